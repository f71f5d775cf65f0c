"""Makes a foreign glTF fixture with Blender itself: a cylinder rigged to a two-bone
armature by Blender's automatic weights, the upper bone bent and twisted, exported by
Blender's glTF exporter (tests/data/blender_arm.glb), and the vertices as Blender deforms
them, in glTF's y-up axes (tests/data/blender_arm.txt: one `x y z` per line, in the
exported vertex order). The test loads the .glb with Marionette and compares.

    python3.11 scripts/make_gltf_fixture.py tests/data

Needs `pip install bpy`.
"""
import sys
from math import radians
from pathlib import Path

import bpy

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blender_kit import tube  # noqa: E402

out = Path(sys.argv[1])
bpy.ops.wm.read_factory_settings(use_empty=True)
# A tube of 11 rings of 16 vertices from z = 0 to 2, so it bends where the bones meet.
arm_mesh = tube("arm", 11, 2.0, 0.15, segments=16)

armature = bpy.data.armatures.new("rig")
rig = bpy.data.objects.new("rig", armature)
bpy.context.scene.collection.objects.link(rig)
bpy.context.view_layer.objects.active = rig
bpy.ops.object.mode_set(mode="EDIT")
upper = armature.edit_bones.new("upper")
upper.head, upper.tail = (0, 0, 0), (0, 0.05, 1)
lower = armature.edit_bones.new("lower")
lower.head, lower.tail, lower.parent = (0, 0.05, 1), (0, 0, 2), upper
bpy.ops.object.mode_set(mode="OBJECT")

arm_mesh.select_set(True)
rig.select_set(True)
bpy.context.view_layer.objects.active = rig
bpy.ops.object.parent_set(type="ARMATURE_AUTO")

rig.pose.bones["lower"].rotation_mode = "XYZ"
rig.pose.bones["lower"].rotation_euler = (radians(50), radians(20), radians(35))
rig.pose.bones["upper"].rotation_mode = "XYZ"
rig.pose.bones["upper"].rotation_euler = (radians(-15), 0, radians(10))
bpy.context.view_layer.update()

glb = out / "blender_arm.glb"
bpy.ops.export_scene.gltf(
    filepath=str(glb), export_format="GLB", export_animations=False, export_rest_position_armature=False
)

# Read back what was exported, deformed by Blender, in the exported vertex order.
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=str(glb))
depsgraph = bpy.context.evaluated_depsgraph_get()
mesh_obj = next(o for o in bpy.context.scene.objects if o.type == "MESH" and o.find_armature())
evaluated = mesh_obj.evaluated_get(depsgraph)
mesh = evaluated.to_mesh()
with open(out / "blender_arm.txt", "w") as f:
    for v in mesh.vertices:
        p = evaluated.matrix_world @ v.co
        f.write(f"{p.x:.7f} {p.z:.7f} {-p.y:.7f}\n")
print("wrote", glb, len(mesh.vertices), "vertices")
