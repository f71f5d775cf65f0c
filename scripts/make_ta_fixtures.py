"""Makes the T-pose and A-pose humanoids for the retargeting tests with Blender itself
(tests/data/blender_tpose.glb, tests/data/blender_apose.glb), and what Blender says about
them (tests/data/blender_ta.txt).

- `tpose`: a humanoid armature with Blender's `.L`/`.R` names, arms straight out along
  ±x. Its action: frame 0 its rest, frame 12 both upper arms raised 80° towards the
  head and the left forearm bent 30°, frame 24 its rest again (24 frames a second).
- `blender_tpose.bvh`: the same action as BVH motion capture (Blender's exporter).
- `apose`: another humanoid, longer legs and a shorter spine, its arms resting 45° down.
  No action.

Each is a box per bone (its vertices wholly in that bone's group), so the skin follows
the bones exactly. The .txt has, for `tpose` at frames 0 and 12, each bone's world head
and tail as Blender evaluates the pose (`bone NAME hx hy hz tx ty tz`, glTF's y-up axes),
and for `apose` its rest bones the same way: the directions the tests compare with.

    python3.11 scripts/make_ta_fixtures.py tests/data

Needs `pip install bpy`.
"""
import sys
from math import radians
from pathlib import Path

import bpy
from mathutils import Vector

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blender_kit import fresh_scene  # noqa: E402

out = Path(sys.argv[1])
FPS = 24


def humanoid(name, leg, spine, arm_drop):
    """An armature `name`: legs `leg` long (thigh + shin), the spine `spine` long, the arms
    resting `arm_drop` degrees below the horizontal. Blender's axes: z up, -y forward."""
    from math import cos, sin

    data = bpy.data.armatures.new(name)
    rig = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    hip_z = leg + 0.1
    bones = {}

    def bone(bone_name, head, tail, parent=None, connect=False):
        b = data.edit_bones.new(bone_name)
        b.head, b.tail = Vector(head), Vector(tail)
        if parent:
            b.parent = bones[parent]
            b.use_connect = connect
        bones[bone_name] = b

    bone("hips", (0, 0, hip_z), (0, 0, hip_z + 0.1))
    bone("spine", (0, 0, hip_z + 0.1), (0, 0, hip_z + 0.1 + spine / 2), "hips", True)
    bone("chest", (0, 0, hip_z + 0.1 + spine / 2), (0, 0, hip_z + 0.1 + spine), "spine", True)
    top = hip_z + 0.1 + spine
    bone("neck", (0, 0, top), (0, 0, top + 0.1), "chest", True)
    bone("head", (0, 0, top + 0.1), (0, 0, top + 0.35), "neck", True)
    drop = radians(arm_drop)
    for side, sx in (("L", 1), ("R", -1)):
        # Blender's left is +x for a character facing -y.
        shoulder = (sx * 0.05, 0, top - 0.05)
        arm_root = (sx * 0.2, 0, top - 0.05)
        bone(f"shoulder.{side}", shoulder, arm_root, "chest")
        def along(d):
            return (arm_root[0] + sx * d * cos(drop), 0, arm_root[2] - d * sin(drop))
        bone(f"upper_arm.{side}", arm_root, along(0.3), f"shoulder.{side}", True)
        bone(f"forearm.{side}", along(0.3), along(0.55), f"upper_arm.{side}", True)
        bone(f"hand.{side}", along(0.55), along(0.65), f"forearm.{side}", True)
        hip = (sx * 0.1, 0, hip_z)
        knee = (sx * 0.1, 0, hip_z - leg / 2)
        ankle = (sx * 0.1, 0, 0.1)
        bone(f"thigh.{side}", hip, knee, "hips")
        bone(f"shin.{side}", knee, ankle, f"thigh.{side}", True)
        bone(f"foot.{side}", ankle, (sx * 0.1, -0.12, 0.02), f"shin.{side}", True)
        bone(f"toe.{side}", (sx * 0.1, -0.12, 0.02), (sx * 0.1, -0.2, 0.02), f"foot.{side}", True)
    bpy.ops.object.mode_set(mode="OBJECT")
    return rig


def boxes(rig):
    """A box around each bone, its vertices wholly in that bone's group, deformed by `rig`."""
    verts, faces, groups = [], [], []
    for b in rig.data.bones:
        head, tail = b.head_local, b.tail_local
        axis = (tail - head).normalized()
        side = axis.orthogonal().normalized() * 0.03
        other = axis.cross(side).normalized() * 0.03
        first = len(verts)
        for end in (head, tail):
            for a, c in ((1, 1), (1, -1), (-1, -1), (-1, 1)):
                verts.append(end + side * a + other * c)
        quads = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]
        faces += [tuple(first + i for i in q) for q in quads]
        groups.append((b.name, range(first, first + 8)))
    mesh = bpy.data.meshes.new(rig.name + "_skin")
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    obj = bpy.data.objects.new(rig.name + "_skin", mesh)
    bpy.context.scene.collection.objects.link(obj)
    for name, indices in groups:
        group = obj.vertex_groups.new(name=name)
        group.add(list(indices), 1.0, "REPLACE")
    obj.parent = rig
    obj.modifiers.new("armature", "ARMATURE").object = rig
    return obj


def write_bones(f, rig, label):
    """`pose LABEL`, then each bone's world head and tail as evaluated, in glTF's axes."""
    f.write(f"pose {label}\n")
    for b in rig.pose.bones:
        h, t = rig.matrix_world @ b.head, rig.matrix_world @ b.tail
        f.write(f"bone {b.name} {h.x:.7f} {h.z:.7f} {-h.y:.7f} {t.x:.7f} {t.z:.7f} {-t.y:.7f}\n")


def export(rig, skin, path):
    bpy.ops.object.select_all(action="DESELECT")
    rig.select_set(True)
    skin.select_set(True)
    bpy.ops.export_scene.gltf(
        filepath=str(path), export_format="GLB", use_selection=True, export_animations=True, export_force_sampling=True
    )


scene = fresh_scene(FPS)
t = humanoid("tpose", leg=0.8, spine=0.5, arm_drop=0)
t_skin = boxes(t)
bpy.context.view_layer.objects.active = t
bpy.ops.object.mode_set(mode="POSE")
t.animation_data_create()
t.animation_data.action = bpy.data.actions.new("raise")
for frame, raise_deg, bend_deg in ((0, 0, 0), (12, 80, 30), (24, 0, 0)):
    for side in ("L", "R"):
        arm = t.pose.bones[f"upper_arm.{side}"]
        arm.rotation_mode = "XYZ"
        # Each upper arm's own y runs along it; turning about its x lifts it towards the head.
        arm.rotation_euler = (radians(raise_deg), 0, 0)
        arm.keyframe_insert("rotation_euler", frame=frame)
    fore = t.pose.bones["forearm.L"]
    fore.rotation_mode = "XYZ"
    fore.rotation_euler = (radians(bend_deg), 0, 0)
    fore.keyframe_insert("rotation_euler", frame=frame)
bpy.ops.object.mode_set(mode="OBJECT")

with open(out / "blender_ta.txt", "w") as f:
    for frame in (0, 12):
        scene.frame_set(frame)
        write_bones(f, t, f"tpose {frame}")
    scene.frame_set(0)
    export(t, t_skin, out / "blender_tpose.glb")

    a = humanoid("apose", leg=0.95, spine=0.4, arm_drop=45)
    a_skin = boxes(a)
    write_bones(f, a, "apose rest")
    bpy.ops.object.select_all(action="DESELECT")
    a.select_set(True)
    a_skin.select_set(True)
    bpy.ops.export_scene.gltf(filepath=str(out / "blender_apose.glb"), export_format="GLB", use_selection=True)

# The T-pose action as BVH motion capture (tests/data/blender_tpose.bvh), stood up in y as
# BVH files are: the armature turned -90° about x and the turn applied to its rest.
bpy.ops.object.select_all(action="DESELECT")
t.select_set(True)
bpy.context.view_layer.objects.active = t
t.rotation_euler = (radians(-90), 0, 0)
bpy.ops.object.transform_apply(location=False, rotation=True, scale=False)
bpy.ops.export_anim.bvh(filepath=str(out / "blender_tpose.bvh"), frame_start=0, frame_end=24)
