"""What the Blender fixture scripts build with: a tube mesh, an armature of chained bones,
automatic weights. Imported by `make_gltf_pair_fixture.py` and `make_nested_fixture.py`
(run them from anywhere: they put this folder on the path); and writing a mesh as
Blender deforms it."""
from math import cos, pi, sin

import bpy


def fresh_scene(fps=24, frames=(0, 24)):
    """Blender's empty factory scene at `fps` frames per second over `frames`."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = fps
    scene.frame_start, scene.frame_end = frames
    return scene


def tube(name, rings, height, radius, segments=12, location=(0, 0, 0)):
    """A tube of `rings` rings of `segments` vertices, from `location` up `height` along z."""
    x0, y0, z0 = location
    verts = [
        (x0 + radius * cos(2 * pi * s / segments), y0 + radius * sin(2 * pi * s / segments), z0 + height * r / (rings - 1))
        for r in range(rings)
        for s in range(segments)
    ]
    faces = [
        (r * segments + s, r * segments + (s + 1) % segments, (r + 1) * segments + (s + 1) % segments, (r + 1) * segments + s)
        for r in range(rings - 1)
        for s in range(segments)
    ]
    data = bpy.data.meshes.new(name)
    data.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def armature(name, bones):
    """An armature object `name` of `bones` (name, head, tail), each connected to the one
    before."""
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    made = []
    for bone_name, head, tail in bones:
        b = data.edit_bones.new(bone_name)
        b.head, b.tail = head, tail
        if made:
            b.parent = made[-1]
            b.use_connect = True
        made.append(b)
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def bind(mesh, rig):
    """Parents `mesh` to `rig` with Blender's automatic weights."""
    bpy.ops.object.select_all(action="DESELECT")
    mesh.select_set(True)
    rig.select_set(True)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")


def write_deformed(f, obj, t, fps):
    """`time T`, then `obj`'s vertices as Blender deforms them at `t` seconds, one `x y z`
    per line in glTF's y-up axes."""
    frame = int(t * fps)
    bpy.context.scene.frame_set(frame, subframe=t * fps - frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    f.write(f"time {t}\n")
    for v in mesh.vertices:
        p = evaluated.matrix_world @ v.co
        f.write(f"{p.x:.7f} {p.z:.7f} {-p.y:.7f}\n")
    evaluated.to_mesh_clear()
