"""Makes FBX fixtures with Blender itself, each with a glTF twin from the same Blender
scene: the project's own Blender-made glTF fixtures read into Blender and written back out
as binary FBX (tests/data/NAME.fbx) and as glTF (tests/data/NAME_twin.glb). The test loads
both with Marionette and poses them at the frames Blender keyed.

    python3.11 scripts/make_fbx_fixtures.py tests/data [tests/data/blender_pair.glb ...]

Without glTF files named, it converts blender_arm, blender_pair and blender_nested. Needs
`pip install bpy`. (The Khronos samples convert the same way into a folder of your own;
they are not copied into the project.)
"""
import sys
from pathlib import Path

import bpy

out = Path(sys.argv[1])
sources = [Path(p) for p in sys.argv[2:]] or [out / f"{n}.glb" for n in ("blender_arm", "blender_pair", "blender_nested")]

for source in sources:
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    bpy.ops.import_scene.gltf(filepath=str(source))
    # The importer's bone shapes (collection `glTF_not_exported`) are not part of the file.
    for o in [o for o in scene.objects if any(c.name == "glTF_not_exported" for c in o.users_collection)]:
        bpy.data.objects.remove(o)
    # Each armature plays the action the file's first animation gave it (one clip).
    actions = [o.animation_data.action for o in scene.objects if o.animation_data and o.animation_data.action]
    if actions:
        scene.frame_start = int(min(a.frame_range[0] for a in actions))
        scene.frame_end = int(max(a.frame_range[1] for a in actions))
    stem = source.stem
    bpy.ops.export_scene.fbx(
        filepath=str(out / f"{stem}.fbx"),
        add_leaf_bones=False,
        bake_anim=bool(actions),
        bake_anim_use_all_actions=False,
        bake_anim_use_nla_strips=False,
        bake_anim_force_startend_keying=True,
        bake_anim_simplify_factor=0.0,
        axis_forward="-Z",
        axis_up="Y",
        mesh_smooth_type="OFF",
        path_mode="COPY",
        embed_textures=True,
    )
    bpy.ops.export_scene.gltf(
        filepath=str(out / f"{stem}_twin.glb"),
        export_format="GLB",
        export_animations=bool(actions),
        export_animation_mode="ACTIVE_ACTIONS",
        export_force_sampling=True,
        export_rest_position_armature=False,
    )
    print("wrote", stem, "frames", scene.frame_start, scene.frame_end, [a.name for a in actions])
