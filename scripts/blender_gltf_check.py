"""Marionette's glTF export, opened and deformed by Blender's own glTF importer.

For each case, writes `marionette export PATH --out x.glb` (skinned: the skeleton in its
pose, bind mesh, weights, inverse binds) and `--out x.obj` (our own skinned vertices),
imports the .glb with `bpy.ops.import_scene.gltf`, evaluates every mesh object as the
armature deforms it, and compares the vertices (glTF's y-up turned back from Blender's
z-up) with the OBJ's: for each OBJ vertex, the nearest deformed vertex.

    python3.11 scripts/blender_gltf_check.py ../shared/data target/debug/marionette

Then the animation: the wasp's walk exported with `--animation`, played by Blender to
t = 0 and 4 s (key times of every track), against `export --anim ... --time T`; and Khronos samples, the nested
skeleton fixture and its FBX, every clip written key for key, Blender playing the first.

Prints the largest distance per case. Needs `pip install bpy numpy`.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np
from mathutils import kdtree

CASES = {
    "Model1 posed": ("mit6837/Model1.skel", ["--pose", "3=0.3,0.5,-0.2", "--pose", "8=0,0,0.9", "--pose", "14=0.4,0,0.3"]),
    "SMPL body posed": ("smpl", ["--pose", "L_Shoulder=0,0,-0.6", "--pose", "R_Knee=0.8,0,0", "--pose", "Spine1=0.2,0.3,0"]),
    "Homer": ("homer/homer.json", ["--pose", "1=0.2,0.1,0"]),
    "puppet": (None, ["--pose", "l_elbow=0,-1.1,0.2", "--pose", "r_knee=0.9,0,0"]),
    "wasp walking": ("cse169/project3/wasp.skel", ["--anim", "{data}/cse169/project3/wasp_walk.anim", "--time", "1.25"]),
    # A Blender-made file of two characters, one playing its STEP rotation and LINEAR scale
    # animation (re-exported by Marionette with the keyed scale as node scale).
    "Blender pair, waver's clip at 0.5 s": ("{repo}/tests/data/blender_pair.glb", ["--clip", "waver_rig_action", "--time", "0.5"]),
    "Blender pair, walker's clip at 0.3 s": ("{repo}/tests/data/blender_pair.glb", ["--clip", "0", "--time", "0.3"]),
}
REPO = Path(__file__).resolve().parent.parent


def read_obj(path):
    return np.array([list(map(float, l.split()[1:4])) for l in open(path) if l.startswith("v ")])


def deformed_vertices(glb, seconds=None):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=str(glb))
    if seconds is not None:
        render = bpy.context.scene.render
        bpy.context.scene.frame_set(round(seconds * render.fps / render.fps_base))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    points = []
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        evaluated = obj.evaluated_get(depsgraph)
        mesh = evaluated.to_mesh()
        m = evaluated.matrix_world
        points.extend((m @ v.co)[:] for v in mesh.vertices)
        evaluated.to_mesh_clear()
    # Blender is z-up: (x, y, z) in glTF is (x, -z, y) here.
    p = np.array(points)
    return np.stack([p[:, 0], p[:, 2], -p[:, 1]], axis=1)


def largest_distance(ours, theirs):
    tree = kdtree.KDTree(len(theirs))
    for i, p in enumerate(theirs):
        tree.insert(p, i)
    tree.balance()
    return max(tree.find(p)[2] for p in ours)


def check_animation(marionette: str, tmp: str, label: str, source: str, clip: list, times: tuple):
    """`source` posed by `clip` (export arguments) exported with --animation, played by
    Blender at `times`, against `export ... --time T --out x.obj` at each."""
    glb = Path(tmp) / "animated.glb"
    subprocess.run([marionette, "export", source, *clip, "--animation", "--out", str(glb)], check=True, capture_output=True)
    worst = 0.0
    for seconds in times:
        obj = Path(tmp) / "animated.obj"
        args = [*clip, "--time", str(seconds), "--out", str(obj)]
        subprocess.run([marionette, "export", source, *args], check=True, capture_output=True)
        ours = read_obj(obj)
        d = largest_distance(ours, deformed_vertices(glb, seconds))
        print(f"{label} at {seconds} s: largest distance {d:.2e}")
        worst = max(worst, d / float(np.ptp(ours, axis=0).max()))
    return worst


def main(data: Path, marionette: str):
    worst_all = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for name, (path, args) in CASES.items():
            source = (path.replace("{repo}", str(REPO)) if path.startswith("{repo}") else str(data / path)) if path else None
            if source is None:
                # The built-in puppet, from the project's assets.
                source = str(Path(__file__).resolve().parent.parent / "assets" / "puppet.skel")
            args = [a.replace("{data}", str(data)) for a in args]
            glb, obj = Path(tmp) / "x.glb", Path(tmp) / "x.obj"
            for out in (glb, obj):
                subprocess.run([marionette, "export", source, "--out", str(out), *args], check=True, capture_output=True)
            ours = read_obj(obj)
            theirs = deformed_vertices(glb)
            worst = largest_distance(ours, theirs)
            size = float(np.ptp(ours, axis=0).max())
            print(f"{name}: {len(ours)} vertices, Blender {len(theirs)}; largest distance {worst:.2e} ({worst / size:.1e} of the size {size:.3f})")
            worst_all = max(worst_all, worst / size)
        wasp, walk = str(data / "cse169/project3/wasp.skel"), str(data / "cse169/project3/wasp_walk.anim")
        # The walk goes out as CUBICSPLINE keyed at its keys (more where a joint turns fast);
        # Blender drops the tangents, so only where every track has a key: 0 and 4 s.
        worst_all = max(worst_all, check_animation(marionette, tmp, "wasp walk animation", wasp, ["--anim", walk], (0.0, 4.0)))
        # The pair's walker clip (CUBICSPLINE in the file, and so in ours): Blender drops the
        # tangents, so only at key times (frames 10 and 24).
        pair = str(REPO / "tests/data/blender_pair.glb")
        label = "Blender pair, walker's clip as a glTF animation"
        worst_all = max(worst_all, check_animation(marionette, tmp, label, pair, ["--clip", "0"], (10 / 24, 1.0)))
        # Files of others and our nested fixture, every clip written key for key: Blender plays
        # the first, compared at frame times that are key times where keys are sparse
        # (RiggedFigure keys 0 and 1.25 s: between them Blender blends rotations component by
        # component, not as the spec's slerp).
        for model, times in [("CesiumMan", (0.5, 1.0)), ("Fox", (0.5, 2.0)), ("BrainStem", (1.0, 5.0)),
                             ("RiggedFigure", (0.0, 1.25)), ("AnimatedMorphCube", (1.0, 2.0))]:
            source = str(data / "khronos" / f"{model}.glb")
            worst_all = max(worst_all, check_animation(marionette, tmp, f"{model} clip 0", source, ["--clip", "0"], times))
        nested = str(REPO / "tests/data/blender_nested.glb")
        worst_all = max(worst_all, check_animation(marionette, tmp, "nested skeletons", nested, ["--clip", "0"], (0.5, 1.0)))
        nested_fbx = str(REPO / "tests/data/blender_nested.fbx")
        worst_all = max(worst_all, check_animation(marionette, tmp, "nested skeletons from FBX", nested_fbx, ["--clip", "0"], (0.5, 1.0)))
    print(f"worst relative distance {worst_all:.1e}")


if __name__ == "__main__":
    main(Path(sys.argv[1]), sys.argv[2])
