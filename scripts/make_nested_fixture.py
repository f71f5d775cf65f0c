"""Makes a foreign glTF fixture with Blender itself: a skeleton inside a skeleton, a prop on
a bone and a mesh of two materials (tests/data/blender_nested.glb), and what Blender makes
of the file when it reads it back (tests/data/blender_nested.txt).

- `body`: a tube of two materials (red below, blue above: two glTF primitives) rigged to
  the armature `body_rig` (bones `spine`, `arm`), which turns with linear keys.
- `hand`: a tube rigged to its own armature `hand_rig`, whose object is parented to the
  bone `arm` of `body_rig`: in the file its skeleton hangs under the other skin's animated
  joint. Its bone `finger` bends with linear keys of its own.
- `hat`: a cube without a skin, parented to the bone `spine`: a prop on a bone.

One action per armature, both in the file's one animation (the exporter's
`ACTIVE_ACTIONS` mode merges the assigned actions). The .txt has, per object (`mesh NAME`) and time
(`time T`), its vertices as Blender deforms them after reading the file back, in glTF's
y-up axes; Blender's vertex order is not the file's (the exporter splits vertices by
material), so the test compares the two as point sets.

    python3.11 scripts/make_nested_fixture.py tests/data

Needs `pip install bpy`.
"""
import sys
from math import radians
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blender_kit import armature, bind, fresh_scene, tube, write_deformed  # noqa: E402

out = Path(sys.argv[1])
FPS = 24
scene = fresh_scene(FPS)



def parent_to_bone(obj, rig, bone):
    """Parents `obj` to `bone` of `rig` keeping its place in the world."""
    world = obj.matrix_world.copy()
    obj.parent = rig
    obj.parent_type = "BONE"
    obj.parent_bone = bone
    bpy.context.view_layer.update()
    obj.matrix_world = world


def material(name, colour):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    m.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = colour
    return m


body = tube("body", 9, 2.0, 0.25, segments=10)
body_rig = armature("body_rig", [("spine", (0, 0, 0), (0, 0, 1)), ("arm", (0, 0, 1), (0, 0, 2))])
bind(body, body_rig)
body.data.materials.append(material("red", (0.8, 0.1, 0.1, 1)))
body.data.materials.append(material("blue", (0.1, 0.2, 0.8, 1)))
for face in body.data.polygons:
    face.material_index = 1 if face.center.z > 1.0 else 0

hand_rig = armature("hand_rig", [("palm", (0, 0, 2), (0, 0, 2.5)), ("finger", (0, 0, 2.5), (0, 0, 3))])
hand = tube("hand", 7, 1.0, 0.12, segments=10, location=(0, 0, 2))
bind(hand, hand_rig)
parent_to_bone(hand_rig, body_rig, "arm")

bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.4, 0, 0.8))
hat = bpy.context.active_object
hat.name = "hat"
hat.data.name = "hat"
parent_to_bone(hat, body_rig, "spine")

for rig, keys in [
    (body_rig, [("spine", [(0, (0, 0, 0)), (12, (radians(25), 0, radians(10))), (24, (radians(-10), radians(15), 0))]),
                ("arm", [(0, (0, 0, 0)), (24, (0, radians(50), 0))])]),
    (hand_rig, [("finger", [(0, (0, 0, 0)), (16, (radians(60), 0, 0)), (24, (radians(30), 0, radians(20)))])]),
]:
    rig.animation_data_create()
    rig.animation_data.action = bpy.data.actions.new(rig.name + "_action")
    for bone_name, frames in keys:
        bone = rig.pose.bones[bone_name]
        bone.rotation_mode = "XYZ"
        for frame, value in frames:
            bone.rotation_euler = value
            bone.keyframe_insert("rotation_euler", frame=frame)

glb = out / "blender_nested.glb"
bpy.ops.export_scene.gltf(
    filepath=str(glb),
    export_format="GLB",
    export_animations=True,
    export_animation_mode="ACTIVE_ACTIONS",
    export_force_sampling=True,
    export_rest_position_armature=False,
)

# Read it back with Blender and deform it at a few times.
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.context.scene.render.fps = FPS
bpy.ops.import_scene.gltf(filepath=str(glb))
print("actions:", [a.name for a in bpy.data.actions])
times = [0.0, 0.3, 0.5, 0.75, 1.0]
objects = sorted((o for o in bpy.context.scene.objects if o.name in ("body", "hand", "hat")), key=lambda o: o.name)
with open(out / "blender_nested.txt", "w") as f:
    for obj in objects:
        f.write(f"mesh {obj.name}\n")
        for t in times:
            write_deformed(f, obj, t, FPS)
print("wrote", glb, [o.name for o in objects])
