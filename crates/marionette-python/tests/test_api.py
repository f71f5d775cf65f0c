"""The Python package against the binary it shares its code with: the same files read, the
same poses (vertices equal to `marionette export … --out x.obj`), the same messages.

Run by `./test.sh` (scripts/python-tests.sh), which builds the wheel into a virtual
environment and names the binary in MARIONETTE_BIN; the SMPL body needs MARIONETTE_DATA.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import marionette as mt
from conftest import ROOT, binary

MIXAMO = ROOT / "tests/data/rigs/mixamo.glb"
DATA = os.environ.get("MARIONETTE_DATA")
needs_data = pytest.mark.skipif(not DATA, reason="MARIONETTE_DATA names no data folder")


def obj_vertices(path):
    """An OBJ file's `v` lines as float32 (V, 3)."""
    rows = [line.split()[1:4] for line in Path(path).read_text().splitlines() if line.startswith("v ")]
    return np.array(rows, dtype=np.float32)


def test_a_character_reads_as_arrays():
    c = mt.load(MIXAMO)
    assert c.name == "mixamo"
    names, parents = c.joint_names, c.parents
    assert parents.dtype == np.int32 and parents.shape == (len(names),)
    assert parents[0] == -1 and all(0 <= p < j for j, p in enumerate(parents) if j > 0)
    assert c.faces.dtype == np.uint32 and c.faces.shape[1] == 3
    assert c.rest_vertices.dtype == np.float32 and c.rest_vertices.shape[1] == 3
    assert c.faces.max() < len(c.rest_vertices)
    assert c.humanoid["Hips"] == "mixamorig:Hips"
    assert c.humanoid["LeftUpperArm"] == "mixamorig:LeftArm"
    assert isinstance(c.clips, list)


POSES = [
    (dict(preset="sit-chair"), ["--preset", "sit-chair"]),
    (dict(preset="wave", mirrored=True, hands={"left": "fist"}), ["--preset", "wave:mirrored", "--hand", "left=fist"]),
    (dict(rotations={"mixamorig:Head": (0.0, 0.3, 0.0)}), ["--pose", "mixamorig:Head=0,0.3,0"]),
    (
        dict(two_bone={"mixamorig:LeftHand": ((0.3, 1.2, 0.3), (0.3, 1.0, -0.5))}),
        ["--two-bone", "mixamorig:LeftHand=0.3,1.2,0.3@0.3,1,-0.5"],
    ),
    (dict(look_at={"mixamorig:Head": (1.0, 1.6, 2.0)}), ["--look-at", "mixamorig:Head=1,1.6,2"]),
    (dict(preset="kneel", skinning="dq"), ["--preset", "kneel", "--skinning", "dq"]),
]


@pytest.mark.parametrize("kwargs,flags", POSES)
def test_a_pose_is_the_one_export_writes(tmp_path, kwargs, flags):
    p = mt.load(MIXAMO).pose(**kwargs)
    out = tmp_path / "x.obj"
    binary("export", MIXAMO, *flags, "--out", out)
    want = obj_vertices(out)
    assert p.vertices.dtype == np.float32 and p.vertices.shape == want.shape
    assert np.abs(p.vertices - want).max() <= 1e-6


def test_joint_matrices_place_the_skin():
    c = mt.load(MIXAMO)
    p = c.pose(preset="t-pose")
    m = p.joint_matrices
    assert m.shape == (len(c.joint_names), 4, 4) and m.dtype == np.float32
    assert np.allclose(m[:, 3], [0, 0, 0, 1])
    # The hips' row of translation is where the skin's hips are: inside the skin's bounds.
    hips = c.joint_names.index(c.humanoid["Hips"])
    lo, hi = p.vertices.min(axis=0), p.vertices.max(axis=0)
    assert np.all(lo <= m[hips, :3, 3]) and np.all(m[hips, :3, 3] <= hi)
    # A child is its parent's matrix times its own: the rows stay rotations (unit columns).
    assert np.allclose(np.linalg.norm(m[:, :3, :3], axis=1), 1.0, atol=1e-4)


def test_notes_say_what_the_command_line_says(tmp_path):
    p = mt.load(MIXAMO).pose(preset="sit-chair", hands={"left": "fist"})
    said = binary("export", MIXAMO, "--preset", "sit-chair", "--hand", "left=fist", "--out", tmp_path / "x.obj")
    for note in p.notes:
        assert note in said.stderr + said.stdout


@needs_data
def test_an_smpl_body_poses_and_reshapes_as_export_does(tmp_path):
    folder = Path(DATA) / "smpl"
    c = mt.load(folder)
    assert len(c.betas) == 10
    p = c.pose(preset="sit-chair")
    binary("export", folder, "--preset", "sit-chair", "--out", tmp_path / "x.obj")
    assert np.abs(p.vertices - obj_vertices(tmp_path / "x.obj")).max() <= 1e-6
    before = c.rest_vertices
    c.betas = np.array([2.0] + [0.0] * 9)
    assert np.abs(c.rest_vertices - before).max() > 1e-3
    assert c.pose(preset="sit-chair").vertices.shape == p.vertices.shape
    # Its folder's clips play by name's end, at a time in seconds, as a still.
    assert c.clips and all(name.endswith(".txt") for name in c.clips)
    walk = c.pose(clip=c.clips[0][:-4][-4:], time=0.5).vertices
    assert walk.shape == p.vertices.shape and np.abs(walk - c.pose(clip=c.clips[0], time=1.0).vertices).max() > 1e-3
    with pytest.raises(mt.PoseError):
        c.pose(clip="no-such-clip")


def test_a_missing_file_is_a_file_error_with_the_binarys_message(tmp_path):
    missing = tmp_path / "missing.glb"
    with pytest.raises(mt.FileError) as raised:
        mt.load(missing)
    said = binary("export", missing, "--out", tmp_path / "x.obj", check=False)
    assert said.returncode != 0 and str(raised.value) in said.stderr


@pytest.mark.parametrize(
    "kwargs,flags",
    [
        (dict(rotations={"mixamorig:Head": (float("nan"), 0.0, 0.0)}), ["--pose", "mixamorig:Head=NaN,0,0"]),
        (dict(preset="no-such-pose"), ["--preset", "no-such-pose"]),
        (dict(hands={"left": "no-such-hand"}), ["--hand", "left=no-such-hand"]),
        (dict(rotations={"no_such_joint": (0.0, 0.1, 0.0)}), ["--pose", "no_such_joint=0,0.1,0"]),
        (dict(clip="no-such-clip"), ["--clip", "no-such-clip"]),
    ],
)
def test_a_pose_that_cannot_be_made_is_a_pose_error_with_the_binarys_message(tmp_path, kwargs, flags):
    with pytest.raises(mt.PoseError) as raised:
        mt.load(MIXAMO).pose(**kwargs)
    said = binary("export", MIXAMO, *flags, "--out", tmp_path / "x.obj", check=False)
    assert said.returncode != 0 and str(raised.value) in said.stderr
    assert isinstance(raised.value, mt.Error)


def test_bad_arguments_are_value_and_type_errors():
    c = mt.load(MIXAMO)
    with pytest.raises(ValueError):
        c.pose(skinning="cubic")
    with pytest.raises(ValueError):
        c.pose(hands={"middle": "fist"})
    with pytest.raises(TypeError):
        c.pose(rotations={"mixamorig:Head": "up"})
    with pytest.raises(TypeError):
        c.pose(time="soon")
    with pytest.raises(mt.PoseError):
        c.betas = [0.0] * 10


def test_the_module_imports_without_a_display_or_a_gpu():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    done = subprocess.run([sys.executable, "-c", "import marionette"], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
