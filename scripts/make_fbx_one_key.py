"""Makes tests/data/one_key.fbx and tests/data/unweighted.fbx with Blender 5 (pip install bpy): an arm of
two bones skinned by a box each, whose action keeps `lower` turned 30° about x the whole
clip (a constant curve, which Blender's FBX exporter writes as one key) while `upper` swings.
A reader that takes a one-key curve as no curve leaves `lower` at rest.

    python3 scripts/make_fbx_one_key.py tests/data
"""
import math
import os
import sys

import bpy
from mathutils import Vector

OUT = sys.argv[-1] if len(sys.argv) > 1 and not sys.argv[-1].endswith(".py") else "tests/data"
bpy.ops.wm.read_factory_settings(use_empty=True)
arm = bpy.data.armatures.new("Arm")
obj = bpy.data.objects.new("Arm", arm)
bpy.context.scene.collection.objects.link(obj)
bpy.context.view_layer.objects.active = obj
bpy.ops.object.mode_set(mode="EDIT")
upper = arm.edit_bones.new("upper")
upper.head, upper.tail = (0, 0, 0), (0, 0, 1)
lower = arm.edit_bones.new("lower")
lower.head, lower.tail = (0, 0, 1), (0, 0, 2)
lower.parent = upper
lower.use_connect = True
bpy.ops.object.mode_set(mode="OBJECT")
verts, faces = [], []
for k, (z0, z1) in enumerate(((0.0, 1.0), (1.0, 2.0))):
    base = len(verts)
    for z in (z0, z1):
        for x, y in ((-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1)):
            verts.append((x, y, z))
    faces += [(base, base + 1, base + 2, base + 3), (base + 4, base + 7, base + 6, base + 5)]
    faces += [(base + i, base + (i + 1) % 4, base + 4 + (i + 1) % 4, base + 4 + i) for i in range(4)]
mesh = bpy.data.meshes.new("Box")
mesh.from_pydata(verts, [], faces)
box = bpy.data.objects.new("Box", mesh)
bpy.context.scene.collection.objects.link(box)
box.vertex_groups.new(name="upper").add(list(range(8)), 1.0, "REPLACE")
box.vertex_groups.new(name="lower").add(list(range(8, 16)), 1.0, "REPLACE")
box.parent = obj
box.modifiers.new("Armature", "ARMATURE").object = obj
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 25
bpy.ops.object.mode_set(mode="POSE")
for f in (1, 13, 25):
    scene.frame_set(f)
    for b in obj.pose.bones:
        b.rotation_mode = "XYZ"
    obj.pose.bones["upper"].rotation_euler = (0, 0, math.sin(f / 25 * math.pi) * 0.8)
    obj.pose.bones["lower"].rotation_euler = (math.radians(30), 0, 0)
    for b in obj.pose.bones:
        b.keyframe_insert("rotation_euler", frame=f)
bpy.ops.object.mode_set(mode="OBJECT")
bpy.ops.export_scene.fbx(filepath=os.path.join(OUT, "one_key.fbx"), add_leaf_bones=False, bake_anim=True,
                         bake_anim_simplify_factor=1.0, bake_anim_use_all_actions=False, bake_anim_use_nla_strips=False)

# unweighted.fbx: the same arm with a hair mesh whose last two vertices no bone weighs
# (Blender and three.js leave them where the mesh's node puts them).
hair = bpy.data.meshes.new("Hair")
hair.from_pydata([(0.2, 0, 1.8), (0.3, 0, 1.8), (0.3, 0, 1.5), (0.2, 0, 1.5)], [], [(0, 1, 2, 3)])
strand = bpy.data.objects.new("Hair", hair)
bpy.context.scene.collection.objects.link(strand)
strand.vertex_groups.new(name="lower").add([0, 1], 1.0, "REPLACE")
strand.parent = obj
strand.modifiers.new("Armature", "ARMATURE").object = obj
bpy.ops.export_scene.fbx(filepath=os.path.join(OUT, "unweighted.fbx"), add_leaf_bones=False, bake_anim=True)
