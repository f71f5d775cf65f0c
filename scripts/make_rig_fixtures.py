"""Makes the humanoid rig fixtures of tests/it/rig_families.rs with Blender 5 (pip install bpy):
one rig per naming family people bring (Mixamo, Unreal, MotionBuilder/HumanIK, Bandai-Namco
`_L`, a Maya rig with IK controls beside its skeleton, Daz Genesis, VRoid, 3ds Max Biped, a
generated Rigify human with every control bone), each with what real rigs carry (an extra
root, zero-length end joints, twist and roll joints, a cape, hair), exported by Blender's own
glTF exporter with a box skinned to every deforming bone; and two BVH clips by Blender's BVH
exporter, in centimetres with a T-pose first frame (CMU-style names, position channels on the
root only; Bandai-Namco-style, a still `joint_Root` above a walking `Hips`, position channels
on every joint).

    python3 scripts/make_rig_fixtures.py tests/data/rigs
"""
import math
import os
import sys

import bpy  # noqa: I001 (bpy first: it makes addon_utils importable)
import addon_utils
from mathutils import Vector

OUT = sys.argv[-1] if len(sys.argv) > 1 and not sys.argv[-1].endswith(".py") else "tests/data/rigs"

# A 1.8 m human in a T-pose, Blender's axes (z up, facing -y, its left at +x): role -> head.
FINGERS = ["thumb", "index", "middle", "ring", "little"]


def body():
    p = {
        "hips": (0, 0, 1.0), "spine": (0, 0, 1.1), "chest": (0, 0, 1.28), "upper_chest": (0, 0, 1.4),
        "neck": (0, 0, 1.55), "head": (0, 0, 1.65), "head_end": (0, 0, 1.85),
    }
    for s, x in (("L", 1), ("R", -1)):
        p[f"clavicle.{s}"] = (0.03 * x, -0.02, 1.48)
        p[f"upper_arm.{s}"] = (0.18 * x, 0, 1.48)
        p[f"lower_arm.{s}"] = (0.45 * x, 0, 1.48)
        p[f"hand.{s}"] = (0.70 * x, 0, 1.48)
        for k, f in enumerate(FINGERS):
            y = [-0.035, -0.02, 0.0, 0.02, 0.038][k]
            base = 0.73 if f == "thumb" else 0.79
            for ph in range(4):
                p[f"{f}{ph + 1}.{s}"] = ((base + 0.03 * ph) * x, y - (0.015 * ph if f == "thumb" else 0), 1.48 - (0.01 * ph if f == "thumb" else 0))
        p[f"upper_leg.{s}"] = (0.1 * x, 0, 0.95)
        p[f"lower_leg.{s}"] = (0.1 * x, -0.01, 0.52)
        p[f"foot.{s}"] = (0.1 * x, 0.02, 0.09)
        p[f"toes.{s}"] = (0.1 * x, -0.1, 0.02)
        p[f"toes_end.{s}"] = (0.1 * x, -0.18, 0.02)
    return p


P = body()


def chain_parent(role):
    """The standard parent of a role (None for the hips)."""
    name, _, side = role.partition(".")
    s = "." + side if side else ""
    order = {
        "hips": None, "spine": "hips", "chest": "spine", "upper_chest": "chest", "neck": "upper_chest", "head": "neck",
        "head_end": "head", "clavicle": "upper_chest", "upper_arm": "clavicle" + s, "lower_arm": "upper_arm" + s,
        "hand": "lower_arm" + s, "upper_leg": "hips", "lower_leg": "upper_leg" + s, "foot": "lower_leg" + s,
        "toes": "foot" + s, "toes_end": "toes" + s,
    }
    if name in order:
        parent = order[name]
        return parent if parent is None or "." in parent or not side else parent
    f, ph = name[:-1], int(name[-1])
    return ("hand" + s) if ph == 1 else f"{f}{ph - 1}{s}"


def family_mixamo():
    n = {"hips": "Hips", "spine": "Spine", "chest": "Spine1", "upper_chest": "Spine2", "neck": "Neck", "head": "Head",
         "head_end": "HeadTop_End"}
    for s, side in (("L", "Left"), ("R", "Right")):
        n.update({f"clavicle.{s}": f"{side}Shoulder", f"upper_arm.{s}": f"{side}Arm", f"lower_arm.{s}": f"{side}ForeArm",
                  f"hand.{s}": f"{side}Hand", f"upper_leg.{s}": f"{side}UpLeg", f"lower_leg.{s}": f"{side}Leg",
                  f"foot.{s}": f"{side}Foot", f"toes.{s}": f"{side}ToeBase", f"toes_end.{s}": f"{side}Toe_End"})
        for f, F in zip(FINGERS, ["Thumb", "Index", "Middle", "Ring", "Pinky"]):
            for ph in range(1, 5):
                n[f"{f}{ph}.{s}"] = f"{side}Hand{F}{ph}"
    return {r: "mixamorig:" + v for r, v in n.items()}, []


def family_unreal():
    n = {"hips": "pelvis", "spine": "spine_01", "chest": "spine_02", "upper_chest": "spine_03", "neck": "neck_01",
         "head": "head"}
    for s, l in (("L", "l"), ("R", "r")):
        n.update({f"clavicle.{s}": f"clavicle_{l}", f"upper_arm.{s}": f"upperarm_{l}", f"lower_arm.{s}": f"lowerarm_{l}",
                  f"hand.{s}": f"hand_{l}", f"upper_leg.{s}": f"thigh_{l}", f"lower_leg.{s}": f"calf_{l}",
                  f"foot.{s}": f"foot_{l}", f"toes.{s}": f"ball_{l}"})
        for f, F in zip(FINGERS, ["thumb", "index", "middle", "ring", "pinky"]):
            for ph in range(1, 4):
                n[f"{f}{ph}.{s}"] = f"{F}_0{ph}_{l}"
    extra = [("root", None, (0, 0, 0), False), ("ik_foot_root", "root", (0, 0, 0), False),
             ("ik_hand_root", "root", (0, 0, 0), False), ("ik_hand_gun", "ik_hand_root", (-0.7, 0, 1.48), False)]
    for s, l, x in (("L", "l", 1), ("R", "r", -1)):
        extra += [(f"ik_foot_{l}", "ik_foot_root", (0.1 * x, 0.02, 0.0), False),
                  (f"ik_hand_{l}", "ik_hand_gun", (0.7 * x, 0, 1.48), False),
                  (f"upperarm_twist_01_{l}", f"upperarm_{l}", (0.3 * x, 0, 1.48), True),
                  (f"lowerarm_twist_01_{l}", f"lowerarm_{l}", (0.6 * x, 0, 1.48), True),
                  (f"thigh_twist_01_{l}", f"thigh_{l}", (0.1 * x, 0, 0.75), True),
                  (f"calf_twist_01_{l}", f"calf_{l}", (0.1 * x, 0, 0.3), True)]
    return n, extra, "root"


def family_humanik():
    n = {"hips": "Hips", "spine": "Spine", "chest": "Spine1", "upper_chest": "Spine2", "neck": "Neck", "head": "Head",
         "head_end": "HeadEnd"}
    for s, side in (("L", "Left"), ("R", "Right")):
        n.update({f"clavicle.{s}": f"{side}Shoulder", f"upper_arm.{s}": f"{side}Arm", f"lower_arm.{s}": f"{side}ForeArm",
                  f"hand.{s}": f"{side}Hand", f"upper_leg.{s}": f"{side}UpLeg", f"lower_leg.{s}": f"{side}Leg",
                  f"foot.{s}": f"{side}Foot", f"toes.{s}": f"{side}ToeBase", f"toes_end.{s}": f"{side}ToesEnd"})
        for f, F in zip(FINGERS, ["Thumb", "Index", "Middle", "Ring", "Pinky"]):
            for ph in range(1, 5):
                n[f"{f}{ph}.{s}"] = f"{side}Hand{F}{ph}"
    extra = [("Reference", None, (0, 0, 0), False)]
    for s, side in (("L", "Left"), ("R", "Right")):
        # Roll joints on the limbs, and zero-length ends where the chain ends.
        extra += [(f"{side}UpLegRoll", f"{side}UpLeg", P[f"upper_leg.{s}"], True),
                  (f"{side}LegRoll", f"{side}Leg", P[f"lower_leg.{s}"], True),
                  (f"{side}ArmRoll", f"{side}Arm", P[f"upper_arm.{s}"], True),
                  (f"{side}ForeArmRoll", f"{side}ForeArm", P[f"lower_arm.{s}"], True),
                  (f"{side}ToesEnd_End", f"{side}ToesEnd", P[f"toes_end.{s}"], False),
                  (f"{side}HandThumb4_End", f"{side}HandThumb4", P[f"thumb4.{s}"], False)]
    extra += [("HeadEnd_End", "HeadEnd", P["head_end"], False)]
    return n, extra, "Reference"


def family_bandai():
    n = {"hips": "Hips", "spine": "Spine", "upper_chest": "Chest", "neck": "Neck", "head": "Head"}
    for s in ("L", "R"):
        n.update({f"clavicle.{s}": f"Shoulder_{s}", f"upper_arm.{s}": f"UpperArm_{s}", f"lower_arm.{s}": f"LowerArm_{s}",
                  f"hand.{s}": f"Hand_{s}", f"upper_leg.{s}": f"UpperLeg_{s}", f"lower_leg.{s}": f"LowerLeg_{s}",
                  f"foot.{s}": f"Foot_{s}", f"toes.{s}": f"Toes_{s}"})
    extra = [("joint_Root", None, (0, 0, 0), False)]
    # A cape from the chest's back down to the floor behind the heels, and a sword on the hip.
    extra += [("Knight_Cape", "Chest", (0, 0.12, 1.45), True), ("Knight_Cape_01", "Knight_Cape", (0, 0.16, 0.9), True),
              ("Knight_Cape_02", "Knight_Cape_01", (0, 0.2, 0.4), True), ("Knight_Cape_03", "Knight_Cape_02", (0, 0.22, 0.0), True),
              ("Sword", "Hips", (0.2, 0, 0.9), True), ("Sword_Tip", "Sword", (0.25, -0.1, 0.05), True)]
    return n, extra, "joint_Root"


def family_maya_controls():
    n = {"hips": "Character1_Hips", "spine": "Character1_Spine", "chest": "Character1_Spine1",
         "upper_chest": "Character1_Spine2", "neck": "Character1_Neck", "head": "Character1_Head"}
    for s, side in (("L", "Left"), ("R", "Right")):
        n.update({f"clavicle.{s}": f"Character1_{side}Shoulder", f"upper_arm.{s}": f"Character1_{side}Arm",
                  f"lower_arm.{s}": f"Character1_{side}ForeArm", f"hand.{s}": f"Character1_{side}Hand",
                  f"upper_leg.{s}": f"Character1_{side}UpLeg", f"lower_leg.{s}": f"Character1_{side}Leg",
                  f"foot.{s}": f"Character1_{side}Foot", f"toes.{s}": f"Character1_{side}ToeBase"})
    extra = [("Character1_Reference", None, (0, 0, 0), False)]
    for s, side, x in (("L", "Left", 1), ("R", "Right", -1)):
        extra += [(f"Character1_{side}FootCtrl", "Character1_Reference", (0.1 * x, 0.02, 0.0), False),
                  (f"Character1_{side}HeelRoll", f"Character1_{side}FootCtrl", (0.1 * x, 0.08, -0.01), False),
                  (f"Character1_{side}ToeRoll", f"Character1_{side}HeelRoll", (0.1 * x, -0.2, -0.01), False),
                  (f"Character1_{side}HandIK", "Character1_Reference", (0.75 * x, 0, 1.48), False),
                  (f"Character1_{side}KneePole", "Character1_Reference", (0.1 * x, -0.6, 0.52), False)]
    return n, extra, "Character1_Reference"


def family_daz():
    n = {"hips": "hip", "spine": "abdomenLower", "chest": "abdomenUpper", "upper_chest": "chestUpper",
         "neck": "neckLower", "head": "head"}
    for s, l in (("L", "l"), ("R", "r")):
        n.update({f"clavicle.{s}": f"{l}Collar", f"upper_arm.{s}": f"{l}ShldrBend", f"lower_arm.{s}": f"{l}ForearmBend",
                  f"hand.{s}": f"{l}Hand", f"upper_leg.{s}": f"{l}ThighBend", f"lower_leg.{s}": f"{l}Shin",
                  f"foot.{s}": f"{l}Foot", f"toes.{s}": f"{l}Toe"})
        for f, F in zip(FINGERS, ["Thumb", "Index", "Mid", "Ring", "Pinky"]):
            for ph in range(1, 4):
                n[f"{f}{ph}.{s}"] = f"{l}{F}{ph}"
    # Daz hangs the thighs from a pelvis beside the spine, and twists between the bends.
    extra = [("pelvis", "hip", (0, 0, 0.98), True)]
    reparent = {}
    for s, l in (("L", "l"), ("R", "r")):
        extra += [(f"{l}ShldrTwist", f"{l}ShldrBend", (0.3 * (1 if s == "L" else -1), 0, 1.48), True),
                  (f"{l}ForearmTwist", f"{l}ForearmBend", (0.58 * (1 if s == "L" else -1), 0, 1.48), True),
                  (f"{l}ThighTwist", f"{l}ThighBend", (0.1 * (1 if s == "L" else -1), 0, 0.75), True)]
        reparent[f"{l}ThighBend"] = "pelvis"
        reparent[f"{l}ForearmBend"] = f"{l}ShldrTwist"
        reparent[f"{l}Shin"] = f"{l}ThighTwist"
        reparent[f"{l}Hand"] = f"{l}ForearmTwist"
    return n, extra, None, reparent


def family_vroid():
    n = {"hips": "J_Bip_C_Hips", "spine": "J_Bip_C_Spine", "chest": "J_Bip_C_Chest", "upper_chest": "J_Bip_C_UpperChest",
         "neck": "J_Bip_C_Neck", "head": "J_Bip_C_Head"}
    for s in ("L", "R"):
        n.update({f"clavicle.{s}": f"J_Bip_{s}_Shoulder", f"upper_arm.{s}": f"J_Bip_{s}_UpperArm",
                  f"lower_arm.{s}": f"J_Bip_{s}_LowerArm", f"hand.{s}": f"J_Bip_{s}_Hand",
                  f"upper_leg.{s}": f"J_Bip_{s}_UpperLeg", f"lower_leg.{s}": f"J_Bip_{s}_LowerLeg",
                  f"foot.{s}": f"J_Bip_{s}_Foot", f"toes.{s}": f"J_Bip_{s}_ToeBase"})
        for f, F in zip(FINGERS, ["Thumb", "Index", "Middle", "Ring", "Little"]):
            for ph in range(1, 4):
                n[f"{f}{ph}.{s}"] = f"J_Bip_{s}_{F}{ph}"
    extra = [("Root", None, (0, 0, 0), False)]
    # Long hair down the back, below the hips.
    extra += [("J_Sec_Hair1_01", "J_Bip_C_Head", (0, 0.1, 1.7), True), ("J_Sec_Hair2_01", "J_Sec_Hair1_01", (0, 0.14, 1.2), True),
              ("J_Sec_Hair3_01", "J_Sec_Hair2_01", (0, 0.15, 0.7), True)]
    return n, extra, "Root"


def family_biped():
    n = {"hips": "Bip01 Pelvis", "spine": "Bip01 Spine", "chest": "Bip01 Spine1", "upper_chest": "Bip01 Spine2",
         "neck": "Bip01 Neck", "head": "Bip01 Head", "head_end": "Bip01 HeadNub"}
    for s in ("L", "R"):
        n.update({f"clavicle.{s}": f"Bip01 {s} Clavicle", f"upper_arm.{s}": f"Bip01 {s} UpperArm",
                  f"lower_arm.{s}": f"Bip01 {s} Forearm", f"hand.{s}": f"Bip01 {s} Hand",
                  f"upper_leg.{s}": f"Bip01 {s} Thigh", f"lower_leg.{s}": f"Bip01 {s} Calf",
                  f"foot.{s}": f"Bip01 {s} Foot", f"toes.{s}": f"Bip01 {s} Toe0", f"toes_end.{s}": f"Bip01 {s} Toe0Nub"})
        for k, f in enumerate(FINGERS):
            for ph in range(1, 4):
                n[f"{f}{ph}.{s}"] = f"Bip01 {s} Finger{k}" + ("" if ph == 1 else str(ph - 1))
    extra = [("Bip01", None, (0, 0, 1.0), False)]
    return n, extra, "Bip01"


FAMILIES = {
    "mixamo": family_mixamo, "unreal": family_unreal, "humanik": family_humanik, "bandai": family_bandai,
    "maya_controls": family_maya_controls, "daz": family_daz, "vroid": family_vroid, "biped": family_biped,
}


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def build(names, extra, root, reparent, yup=False):
    """An armature: the body's roles named by `names` (roles a family lacks are left out,
    their children hung on the nearest role it has), `extra` joints (name, parent, head,
    deforms); each bone's tail at its first child or 5 cm on. A box skinned to each
    deforming bone. With `yup` the rig is laid y up (facing +z) in Blender's own axes, as a
    BVH file is read."""
    turn = (lambda v: Vector((v[0], v[2], -v[1]))) if yup else Vector
    arm = bpy.data.armatures.new("Armature")
    obj = bpy.data.objects.new("Armature", arm)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    heads, parents, deforms = {}, {}, {}
    if root:
        for name, parent, head, d in extra:
            if name == root:
                heads[name], parents[name], deforms[name] = turn(head), None, d
    for role, name in names.items():
        parent = chain_parent(role)
        while parent is not None and parent not in names:
            parent = chain_parent(parent)
        parents[name] = names[parent] if parent else root
        heads[name] = turn(P[role])
        deforms[name] = not role.startswith("head_end") and not role.startswith("toes_end") and not role.endswith(("4.L", "4.R"))
    for name, parent, head, d in extra:
        if name != root:
            heads[name], parents[name], deforms[name] = turn(head), parent, d
    parents.update(reparent)
    bones = {}
    for name in heads:
        b = arm.edit_bones.new(name)
        b.head = heads[name]
        kids = [k for k, p in parents.items() if p == name]
        tail = heads[kids[0]] if kids and (heads[kids[0]] - heads[name]).length > 1e-4 else heads[name] + turn((0, 0, 0.05))
        b.tail = tail
        bones[name] = b
    for name, parent in parents.items():
        if parent:
            bones[name].parent = bones[parent]
        bones[name].use_deform = deforms[name]
    bpy.ops.object.mode_set(mode="OBJECT")
    # A box on each deforming bone, weighted to it.
    verts, faces, groups = [], [], []
    for bone in arm.bones:
        if not bone.use_deform:
            continue
        a, b = bone.head_local, bone.tail_local
        c, half = (a + b) / 2, max((b - a).length / 2, 0.01)
        r = 0.02
        base = len(verts)
        for dx in (-1, 1):
            for dy in (-1, 1):
                for dz in (-1, 1):
                    verts.append(c + Vector((dx * r, dy * r, dz * r)) + (b - a).normalized() * (half * dz if (b - a).length > 1e-6 else 0))
        faces += [(base + i, base + j, base + k, base + m) for i, j, k, m in
                  ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3))]
        groups.append((bone.name, range(base, base + 8)))
    mesh = bpy.data.meshes.new("Body")
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    body = bpy.data.objects.new("Body", mesh)
    bpy.context.scene.collection.objects.link(body)
    for name, vs in groups:
        g = body.vertex_groups.new(name=name)
        g.add(list(vs), 1.0, "REPLACE")
    body.parent = obj
    body.modifiers.new("Armature", "ARMATURE").object = obj
    return obj


def add_face_shapes(armature, head):
    """Two shape keys on the body, moving the head's box (a VRM avatar's expressions are
    made of such): `Joy` widens it, `Blink` flattens it."""
    body = next(c for c in armature.children if c.type == "MESH")
    group = body.vertex_groups[head].index
    body.shape_key_add(name="Basis")
    for name, scale in (("Joy", (1.5, 1.0, 1.0)), ("Blink", (1.0, 1.0, 0.5))):
        key = body.shape_key_add(name=name)
        for v in body.data.vertices:
            if any(g.group == group for g in v.groups):
                c = Vector((0, 0, 1.75))
                key.data[v.index].co = c + Vector([(v.co - c)[i] * scale[i] for i in range(3)])


def export_gltf(path):
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_animations=False, export_def_bones=False,
                              export_skins=True, export_apply=False)


def rigify(path):
    reset()
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    bpy.ops.pose.rigify_generate()
    rig = bpy.context.active_object
    # The metarig stays out of the file, as a user exports the generated rig.
    bpy.data.objects.remove(bpy.data.objects["metarig"], do_unlink=True)
    verts, faces, groups = [], [], []
    for bone in rig.data.bones:
        if not bone.name.startswith("DEF-"):
            continue
        a, b = bone.head_local, bone.tail_local
        base = len(verts)
        for k in range(8):
            d = Vector(((k & 1) * 2 - 1, (k >> 1 & 1) * 2 - 1, (k >> 2 & 1) * 2 - 1)) * 0.01
            verts.append((a if k < 4 else b) + d)
        faces += [(base, base + 1, base + 3, base + 2), (base + 4, base + 6, base + 7, base + 5)]
        groups.append((bone.name, range(base, base + 8)))
    mesh = bpy.data.meshes.new("Body")
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    body = bpy.data.objects.new("Body", mesh)
    bpy.context.scene.collection.objects.link(body)
    for name, vs in groups:
        body.vertex_groups.new(name=name).add(list(vs), 1.0, "REPLACE")
    body.parent = rig
    body.modifiers.new("Armature", "ARMATURE").object = rig
    export_gltf(path)


def walk(obj, names, frames, travel):
    """A T-pose at the first frame, then marching in place while the hips travel `travel`
    metres forward: the standing leg straight (its foot on the floor), the other thigh and
    knee bending, the arms down."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, frames
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="POSE")
    pb = obj.pose.bones
    for pose_bone in pb:
        pose_bone.rotation_mode = "XYZ"
    for f in range(1, frames + 1):
        scene.frame_set(f)
        u = (f - 2) / max(frames - 2, 1)
        for pose_bone in pb:
            pose_bone.rotation_euler = (0, 0, 0)
            pose_bone.location = (0, 0, 0)
        if f > 1:
            phase = 4 * math.pi * u
            for s, sign in (("L", 1), ("R", -1)):
                lift = max(0.0, math.sin(phase) * sign)
                if f"upper_leg.{s}" in names:
                    pb[names[f"upper_leg.{s}"]].rotation_euler = (0.7 * lift, 0, 0)
                if f"lower_leg.{s}" in names:
                    pb[names[f"lower_leg.{s}"]].rotation_euler = (-1.1 * lift, 0, 0)
                if f"upper_arm.{s}" in names:
                    pb[names[f"upper_arm.{s}"]].rotation_euler = (0, 0, 1.1 * sign)
            hips = pb[names["hips"]]
            # Bone space: the hips' bone points up (+y along it), forward is -z of the bone.
            hips.location = (0, 0, travel * u)
        for pose_bone in pb:
            pose_bone.keyframe_insert("rotation_euler", frame=f)
            pose_bone.keyframe_insert("location", frame=f)
    bpy.ops.object.mode_set(mode="OBJECT")


def cmu_names():
    n = {"hips": "Hips", "spine": "LowerBack", "chest": "Spine", "upper_chest": "Spine1", "neck": "Neck",
         "head": "Head"}
    for s, side in (("L", "Left"), ("R", "Right")):
        n.update({f"clavicle.{s}": f"{side}Shoulder", f"upper_arm.{s}": f"{side}Arm", f"lower_arm.{s}": f"{side}ForeArm",
                  f"hand.{s}": f"{side}Hand", f"index1.{s}": f"{side}HandIndex1", f"thumb1.{s}": f"{s}Thumb",
                  f"upper_leg.{s}": f"{side}UpLeg", f"lower_leg.{s}": f"{side}Leg", f"foot.{s}": f"{side}Foot",
                  f"toes.{s}": f"{side}ToeBase"})
    return n


def main():
    os.makedirs(OUT, exist_ok=True)
    for family, make in FAMILIES.items():
        reset()
        made = make()
        names, extra = made[0], made[1]
        root = made[2] if len(made) > 2 else None
        reparent = made[3] if len(made) > 3 else {}
        obj = build(names, extra, root, reparent)
        if family == "vroid":
            add_face_shapes(obj, names["head"])
        export_gltf(os.path.join(OUT, f"{family}.glb"))
    rigify(os.path.join(OUT, "rigify.glb"))
    # BVH clips in centimetres, a T-pose first frame.
    reset()
    names = cmu_names()
    # CMU's pelvis joints between the hips and the thighs, its second neck joint, and the
    # finger base under each hand.
    extra = [("Neck1", "Neck", (0, 0, 1.6), True)]
    reparent = {"Head": "Neck1"}
    for s, side, x in (("L", "Left", 1), ("R", "Right", -1)):
        extra += [(f"{s}HipJoint", "Hips", (0.03 * x, 0, 0.98), True),
                  (f"{side}FingerBase", f"{side}Hand", (0.76 * x, 0, 1.48), True)]
        reparent[f"{side}UpLeg"] = f"{s}HipJoint"
        reparent[f"{side}HandIndex1"] = f"{side}FingerBase"
    obj = build(names, extra, None, reparent, yup=True)
    walk(obj, names, 41, 1.0)
    bpy.ops.export_anim.bvh(filepath=os.path.join(OUT, "cmu_walk.bvh"), global_scale=100.0, frame_start=1,
                            frame_end=41, rotate_mode="ZXY", root_transform_only=True)
    reset()
    names, extra, root = family_bandai()
    obj = build(names, extra, root, {}, yup=True)
    walk(obj, names, 41, 1.0)
    bpy.ops.export_anim.bvh(filepath=os.path.join(OUT, "bandai_walk.bvh"), global_scale=100.0, frame_start=1,
                            frame_end=41, rotate_mode="NATIVE", root_transform_only=False)


main()
