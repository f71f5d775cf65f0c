"""Makes a foreign glTF fixture with Blender itself: two characters in one file, each a
tube rigged to its own armature by Blender's automatic weights and animated by its own
action (tests/data/blender_pair.glb), and what Blender makes of the file when it reads it
back (tests/data/blender_pair.txt).

- `walker`: three bones; the root bone moves (translation keys) and the middle one bends
  (rotation keys) with Bezier curves, exported without resampling, so the file holds
  CUBICSPLINE samplers; its mesh has a shape key `bulge` (a glTF morph target, at weight
  0.25 in the file, which Blender's deformation includes) and a base
  colour texture (an 8 x 8 red and blue checker, a PNG inside the .glb).
- `waver`: two bones under an armature object that is moved, turned and scaled (nodes
  above the skeleton); its upper bone turns with constant keys (STEP) and its lower bone
  scales with linear keys (LINEAR).

The .txt has, for each character (`mesh NAME`), the `bulge` deltas (`morph NAME`) and the
vertices as Blender deforms them at a few times (`time T`, seconds), one `x y z` per line
in the exported vertex order, in glTF's y-up axes. Blender's importer ignores CUBICSPLINE
tangents, so for those channels the .txt also has the spec's own formula evaluated here
(`spline NODE PATH`, then `t x y z [w]` lines), and Blender is compared only at key times.
The test loads the .glb with Marionette, samples its clips at those times and compares.

    python3.11 scripts/make_gltf_pair_fixture.py tests/data

Needs `pip install bpy`.
"""
import json
import struct
import sys
from math import atan2, pi, radians
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blender_kit import armature, bind, fresh_scene, tube, write_deformed  # noqa: E402

out = Path(sys.argv[1])
FPS = 24
scene = fresh_scene(FPS)



# walker: three bones up z, a bulge in the middle.
walker = tube("walker", 13, 3.0, 0.2)
walker_rig = armature("walker_rig", [("hip", (0, 0, 0), (0, 0, 1)), ("knee", (0, 0, 1), (0, 0.1, 2)), ("foot", (0, 0.1, 2), (0, 0, 3))])
bind(walker, walker_rig)
walker.shape_key_add(name="Basis")
bulge = walker.shape_key_add(name="bulge")
for i, v in enumerate(walker.data.vertices):
    if 1.2 < v.co.z < 1.8:
        bulge.data[i].co = (v.co.x * 1.5, v.co.y * 1.5, v.co.z)
bulge.value = 0.25  # the mesh's weight in the file (glTF mesh.weights)

# The walker wears a base colour texture: an 8 x 8 checker of red and blue (written into
# the .glb as a PNG), on texture coordinates around the tube.
checker = bpy.data.images.new("checker", 8, 8)
checker.pixels = [c for i in range(64) for c in ((1, 0, 0, 1) if (i % 8 + i // 8) % 2 else (0, 0, 1, 1))]
material = bpy.data.materials.new("walker_skin")
material.use_nodes = True
image_node = material.node_tree.nodes.new("ShaderNodeTexImage")
image_node.image = checker
bsdf = material.node_tree.nodes["Principled BSDF"]
material.node_tree.links.new(image_node.outputs["Color"], bsdf.inputs["Base Color"])
walker.data.materials.append(material)
uv = walker.data.uv_layers.new(name="UVMap")
for loop in walker.data.loops:
    co = walker.data.vertices[loop.vertex_index].co
    uv.data[loop.index].uv = ((atan2(co.y, co.x) / (2 * pi)) % 1.0, co.z / 3.0)

# waver: two bones, its armature object moved, turned and scaled.
waver = tube("waver", 9, 2.0, 0.25)
waver_rig = armature("waver_rig", [("upper", (0, 0, 0), (0, 0, 1)), ("lower", (0, 0, 1), (0, 0, 2))])
bind(waver, waver_rig)
waver_rig.location = (3.0, 0.5, 0.0)
waver_rig.rotation_euler = (0, 0, radians(30))
waver_rig.scale = (1.5, 1.5, 1.5)

for rig, keys in [
    (
        walker_rig,
        [
            ("hip", "location", [(0, (0, 0, 0)), (12, (0.3, 0.2, 0.1)), (24, (0, 0.4, 0))], "BEZIER"),
            ("knee", "rotation_euler", [(0, (0, 0, 0)), (10, (radians(40), 0, radians(15))), (24, (radians(-20), radians(10), 0))], "BEZIER"),
        ],
    ),
    (
        waver_rig,
        [
            ("upper", "rotation_euler", [(0, (0, 0, 0)), (8, (radians(30), 0, 0)), (16, (0, radians(25), radians(-20)))], "CONSTANT"),
            ("lower", "scale", [(0, (1, 1, 1)), (24, (1.3, 0.8, 1.1))], "LINEAR"),
        ],
    ),
]:
    rig.animation_data_create()
    rig.animation_data.action = bpy.data.actions.new(rig.name + "_action")
    for bone_name, prop, frames, interpolation in keys:
        bone = rig.pose.bones[bone_name]
        bone.rotation_mode = "XYZ"
        for frame, value in frames:
            setattr(bone, prop, value)
            bone.keyframe_insert(prop, frame=frame)
    # Every key of the action gets the interpolation of its bone's keys.
    for bone_name, prop, frames, interpolation in keys:
        path = f'pose.bones["{bone_name}"].{prop}'
        action = rig.animation_data.action
        curves = []
        if hasattr(action, "fcurves"):
            curves = [c for c in action.fcurves if c.data_path == path]
        else:  # Blender 5: layered actions
            for layer in action.layers:
                for strip in layer.strips:
                    for bag in strip.channelbags:
                        curves += [c for c in bag.fcurves if c.data_path == path]
        assert curves, path
        for c in curves:
            for point in c.keyframe_points:
                point.interpolation = interpolation

glb = out / "blender_pair.glb"
bpy.ops.export_scene.gltf(
    filepath=str(glb),
    export_format="GLB",
    export_animations=True,
    export_force_sampling=False,
    export_rest_position_armature=False,
    export_morph=True,
)

# What the file holds: each sampler's interpolation (so the test knows it has all three).
raw = glb.read_bytes()
length = struct.unpack_from("<I", raw, 12)[0]
doc = json.loads(raw[20 : 20 + length])
blob = raw[20 + length + 8 :]
kinds = sorted({s["interpolation"] for a in doc.get("animations", []) for s in a["samplers"]})
print("samplers:", kinds, "animations:", [a["name"] for a in doc.get("animations", [])])


def accessor(i):
    a = doc["accessors"][i]
    view = doc["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a["type"]]
    at = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    return [struct.unpack_from(f"<{width}f", blob, at + 4 * width * k) for k in range(a["count"])]


def cubic_spline(times, values, t):
    """glTF 2.0 Appendix C, written out from the spec: values are (in-tangent, value,
    out-tangent) per key; clamped outside the keys."""
    key = lambda k: values[3 * k + 1]
    if t <= times[0]:
        return key(0)
    if t >= times[-1]:
        return key(len(times) - 1)
    k = max(i for i in range(len(times)) if times[i] <= t)
    td = times[k + 1] - times[k]
    s = (t - times[k]) / td
    b, a = values[3 * k + 2], values[3 * (k + 1)]
    v = [
        (2 * s**3 - 3 * s**2 + 1) * p0 + td * (s**3 - 2 * s**2 + s) * m0 + (-2 * s**3 + 3 * s**2) * p1 + td * (s**3 - s**2) * m1
        for p0, m0, p1, m1 in zip(key(k), b, key(k + 1), a)
    ]
    if len(v) == 4:  # a rotation: back to unit length
        n = sum(x * x for x in v) ** 0.5
        v = [x / n for x in v]
    return v


# Blender's importer drops CUBICSPLINE tangents ("TODO manage tangent?" in its
# animation_node.py), so between keys the spec itself is the reference: each CUBICSPLINE
# channel sampled by the formula above (node space, x y z [w]).
spline_times = [0.1, 0.25, 0.4, 0.6, 0.8, 0.95]
splines = []
for a in doc["animations"]:
    for channel in a["channels"]:
        sampler = a["samplers"][channel["sampler"]]
        if sampler["interpolation"] != "CUBICSPLINE":
            continue
        times = [k[0] for k in accessor(sampler["input"])]
        values = accessor(sampler["output"])
        node = doc["nodes"][channel["target"]["node"]]["name"]
        splines.append((node, channel["target"]["path"], [(t, cubic_spline(times, values, t)) for t in spline_times]))

# Read it back with Blender and deform it at a few times.
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.context.scene.render.fps = FPS
bpy.ops.import_scene.gltf(filepath=str(glb))
# Blender makes the file's first animation the active action and stashes the others in NLA
# tracks: give each armature the action of its own track so both play.
for rig in (o for o in bpy.context.scene.objects if o.type == "ARMATURE"):
    track = rig.animation_data.nla_tracks[0]
    rig.animation_data.action = track.strips[0].action
    rig.animation_data.action_slot = rig.animation_data.action.slots[0]
    track.mute = True
meshes = sorted((o for o in bpy.context.scene.objects if o.type == "MESH" and o.find_armature()), key=lambda o: o.name)
# Times where Blender and the file agree: any for STEP and LINEAR (waver), only key times
# for the CUBICSPLINE walker (10 / 24 s is a key of its knee).
times = {"walker": [0.0, 10 / FPS, 1.0], "waver": [0.0, 0.25, 0.4, 0.5, 0.8, 1.0]}
with open(out / "blender_pair.txt", "w") as f:
    f.write(f"# {kinds}\n")
    for node, path, samples in splines:
        f.write(f"spline {node} {path}\n")
        for t, v in samples:
            f.write(f"{t} " + " ".join(f"{x:.8f}" for x in v) + "\n")
    for obj in meshes:
        rig = obj.find_armature()
        f.write(f"mesh {obj.name}\n")
        if obj.data.shape_keys:
            basis = obj.data.shape_keys.key_blocks[0]
            for block in obj.data.shape_keys.key_blocks[1:]:
                f.write(f"morph {block.name}\n")
                for b, k in zip(basis.data, block.data):
                    d = k.co - b.co
                    f.write(f"{d.x:.7f} {d.z:.7f} {-d.y:.7f}\n")
        for t in times[obj.name]:
            # The importer keys frame = time * fps (the actions' frame ranges, written last,
            # show it: 0 to 24 for 0 to 1 s).
            write_deformed(f, obj, t, FPS)
    for a in bpy.data.actions:
        f.write(f"# action {a.name} frames {tuple(a.frame_range)}\n")
print("wrote", glb, [o.name for o in meshes])
