"""The peer for `generate`'s data sets: the same kind of picture made with Blender (bpy),
the engine under BlenderProc. Three SMPL bodies (OBJ, each picture other bodies' shapes put
on the three), a floor, a sun, the camera moved for each picture; depth (Z) and normal
passes written with the picture into a multilayer OpenEXR. Prints the pictures a second
after the first, as `generate` does.

    python blender_peer.py --smpl DIR --engine workbench|cycles [--samples 16]
                           [--count 30] [--width 640] [--height 480] --out DIR

Needs `pip install bpy` (Blender 5, Python 3.11, numpy < 2); benches/blender_peer.sh runs
it beside `marionette generate` and prints the ratios of one run.
"""
import argparse
import glob
import math
import os
import random
import sys
import time

import bpy


def arguments():
    parser = argparse.ArgumentParser()
    parser.add_argument("--smpl", required=True, help="a folder of SMPL bodies as OBJ (smpl_00.obj, ...)")
    parser.add_argument("--engine", choices=["workbench", "cycles"], required=True)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--count", type=int, default=30)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--out", required=True)
    return parser.parse_args()


def empty_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


def body_meshes(folder):
    """Each OBJ of the folder as a mesh datablock (the shapes put on the three bodies)."""
    files = sorted(glob.glob(os.path.join(folder, "smpl_*.obj")))
    if len(files) < 3:
        sys.exit(f"{folder}: expected at least 3 smpl_*.obj bodies")
    meshes = []
    for path in files:
        bpy.ops.wm.obj_import(filepath=path, forward_axis="NEGATIVE_Z", up_axis="Y")
        imported = bpy.context.selected_objects[0]
        meshes.append(imported.data)
        bpy.data.objects.remove(imported)
    return meshes


def stage(scene, engine, samples, width, height):
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    if engine == "workbench":
        scene.render.engine = "BLENDER_WORKBENCH"
        scene.display.shading.light = "STUDIO"
        scene.display.shading.show_shadows = True
    else:
        scene.render.engine = "CYCLES"
        scene.cycles.samples = samples
        scene.cycles.device = "CPU"
        scene.cycles.use_denoising = False
    layer = scene.view_layers[0]
    layer.use_pass_z = True
    layer.use_pass_normal = True
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):  # Blender 5: multilayer is a media type first
        settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    scene.render.image_settings.color_depth = "32"
    bpy.ops.mesh.primitive_plane_add(size=20)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", type="SUN"))
    sun.data.energy = 3.0
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    return sun, camera


def main():
    args = arguments()
    os.makedirs(args.out, exist_ok=True)
    scene = empty_scene()
    meshes = body_meshes(args.smpl)
    sun, camera = stage(scene, args.engine, args.samples, args.width, args.height)
    bodies = []
    for k in range(3):
        body = bpy.data.objects.new(f"body{k}", meshes[k])
        scene.collection.objects.link(body)
        bodies.append(body)
    rng = random.Random(1)
    started = None
    for picture in range(args.count):
        # Other shapes on the three, placed apart, facing about the camera.
        for k, body in enumerate(bodies):
            body.data = meshes[rng.randrange(len(meshes))]
            body.location = ((k - 1) * 1.3 + rng.uniform(-0.2, 0.2), rng.uniform(-0.5, 0.5), 0.0)
            body.rotation_euler = (math.radians(90), 0.0, math.radians(rng.uniform(-60, 60)))
        distance, height, yaw = rng.uniform(4.0, 6.0), rng.uniform(0.8, 2.2), math.radians(rng.uniform(-40, 40))
        camera.location = (distance * math.sin(yaw), -distance * math.cos(yaw), height)
        direction = -camera.location.copy()
        direction.z += 0.6
        camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
        camera.data.angle = math.radians(rng.uniform(35.0, 50.0))
        sun.rotation_euler = (math.radians(rng.uniform(20, 70)), 0.0, math.radians(rng.uniform(0, 360)))
        scene.render.filepath = os.path.join(args.out, f"{picture:06d}.exr")
        bpy.ops.render.render(write_still=True)
        if started is None:
            started = time.perf_counter()
    seconds = time.perf_counter() - started
    rate = (args.count - 1) / seconds if args.count > 1 and seconds > 0 else float("nan")
    print(f"blender {args.engine}: {rate:.2f} pictures a second after the first ({args.count} pictures)")


main()
