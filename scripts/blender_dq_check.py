"""Dual quaternion skinning against Blender's "Preserve Volume" armature deform.

Builds the 6.837 model (skeleton, mesh, weights read from the course files here, not
through Marionette) as a Blender armature and mesh, poses it by the same Euler angles as
`marionette export --pose`, deforms it with Blender's dual quaternion skinning, and
compares every vertex with `marionette export --skinning dq`.

    python3.11 scripts/blender_dq_check.py ../shared/data/mit6837/Model1 target/debug/marionette

Prints the largest vertex distance. Needs `pip install bpy numpy`.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import bpy
import numpy as np
from mathutils import Matrix, Vector

# Moderate pose: joint index -> (rx, ry, rz) radians, x applied first (as `--pose`).
POSE = {3: (0.3, 0.2, -0.4), 6: (0.0, 0.5, 0.6), 7: (-0.4, 0.3, 0.0), 10: (0.5, -0.3, 0.2), 14: (0.2, 0.0, 0.7)}


def read_model(stem: Path):
    joints = [list(map(float, l.split()[:3])) + [int(l.split()[3])] for l in open(f"{stem}.skel") if l.strip()]
    verts, faces = [], []
    for line in open(f"{stem}.obj"):
        p = line.split()
        if p and p[0] == "v":
            verts.append(list(map(float, p[1:4])))
        elif p and p[0] == "f":
            faces.append([int(x.split("/")[0]) - 1 for x in p[1:]])
    weights = [list(map(float, l.split())) for l in open(f"{stem}.attach") if l.strip()]
    return joints, np.array(verts), faces, weights


def euler_xyz(rx, ry, rz):
    return Matrix.Rotation(rz, 4, "Z") @ Matrix.Rotation(ry, 4, "Y") @ Matrix.Rotation(rx, 4, "X")


def palette(joints):
    """Model-space deform matrix of each joint: current world x inverse bind (own FK)."""
    rest, posed = [], []
    for j, (x, y, z, parent) in enumerate(joints):
        local_rest = Matrix.Translation((x, y, z))
        local_pose = local_rest @ euler_xyz(*POSE.get(j, (0.0, 0.0, 0.0)))
        rest.append(local_rest if parent < 0 else rest[parent] @ local_rest)
        posed.append(local_pose if parent < 0 else posed[parent] @ local_pose)
    return [p @ r.inverted() for p, r in zip(posed, rest)], rest


def blender_deform(joints, verts, faces, weights, preserve_volume):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    deform, rest = palette(joints)
    arm_data = bpy.data.armatures.new("rig")
    arm = bpy.data.objects.new("rig", arm_data)
    bpy.context.scene.collection.objects.link(arm)
    bpy.context.view_layer.objects.active = arm
    bpy.ops.object.mode_set(mode="EDIT")
    for j, m in enumerate(rest):
        b = arm_data.edit_bones.new(f"j{j}")
        b.head = m.translation
        b.tail = m.translation + Vector((0.0, 0.02, 0.0))
        b.use_deform = True
    bpy.ops.object.mode_set(mode="POSE")
    for j in range(len(joints)):
        pb = arm.pose.bones[f"j{j}"]
        pb.matrix = deform[j] @ pb.bone.matrix_local
        bpy.context.view_layer.update()
    bpy.ops.object.mode_set(mode="OBJECT")
    mesh = bpy.data.meshes.new("skin")
    mesh.from_pydata(verts.tolist(), [], faces)
    obj = bpy.data.objects.new("skin", mesh)
    bpy.context.scene.collection.objects.link(obj)
    groups = [obj.vertex_groups.new(name=f"j{j}") for j in range(len(joints))]
    for v, row in enumerate(weights):
        for k, w in enumerate(row):  # column k is joint k + 1 (the root has no column)
            if w > 0:
                groups[k + 1].add([v], w, "REPLACE")
    mod = obj.modifiers.new("armature", "ARMATURE")
    mod.object = arm
    mod.use_deform_preserve_volume = preserve_volume
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph).to_mesh()
    return np.array([v.co[:] for v in evaluated.vertices])


def marionette_export(stem: Path, binary: str, skinning: str):
    out = Path(tempfile.mkdtemp()) / f"{skinning}.obj"
    pose = [a for j, r in POSE.items() for a in ("--pose", f"{j}={r[0]},{r[1]},{r[2]}")]
    subprocess.run([binary, "export", f"{stem}.skel", "--skinning", skinning, "--out", str(out), *pose],
                   check=True, capture_output=True)
    return np.array([list(map(float, l.split()[1:4])) for l in open(out) if l.startswith("v ")])


if __name__ == "__main__":
    stem, binary = Path(sys.argv[1]), sys.argv[2]
    joints, verts, faces, weights = read_model(stem)
    report = lambda a, b: f"max {np.linalg.norm(a - b, axis=1).max():.2e}, mean {np.linalg.norm(a - b, axis=1).mean():.2e}"
    dq, lbs = marionette_export(stem, binary, "dq"), marionette_export(stem, binary, "lbs")
    blender_dq = blender_deform(joints, verts, faces, weights, preserve_volume=True)
    blender_lbs = blender_deform(joints, verts, faces, weights, preserve_volume=False)
    print(f"{stem.name}: {len(verts)} vertices")
    print(f"  Blender preserve volume vs marionette --skinning dq:  {report(dq, blender_dq)}")
    print(f"  Blender plain armature  vs marionette --skinning lbs: {report(lbs, blender_lbs)}")
    print(f"  (dq vs lbs, how far apart the two methods are:       {report(dq, lbs)})")
