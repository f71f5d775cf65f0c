"""Draws the people of a `render --controlnet` picture's `cn-openpose.json` with the OpenPose
annotator's own `draw_bodypose` and `draw_handpose` (lllyasviel's, as `controlnet_aux`
carries them in `open_pose/util.py`, in its `draw_poses` order: each person's body, left
hand, right hand) and holds Marionette's `cn-openpose.png` to that drawing: drawn pixels
agree at IoU >= 0.98, colours within 8 on >= 98 % of the pixels both drew.

It then reads the `cn-openpose.json` back through the annotator's JSON reader
(`decode_json_as_poses`, which sd-webui-controlnet and ComfyUI's controlnet_aux carry, here
from the `dwpose` wheel with its `draw_poses` and the drawing functions beside it) and holds
the PNG to that reader's drawing in the same way: the JSON round-trips to the same picture.

The annotator's code is taken from the `controlnet_aux` and `dwpose` wheels at run time (`pip download
--no-deps`, into ~/.cache; never committed) and its drawing functions read out of util.py
without importing the package (which needs torch). Needs numpy, opencv and matplotlib.

    python3 check_controlnet_openpose.py SHOT.png
"""
import ast
import glob
import json
import math
import os
import subprocess
import sys
import zipfile
from collections import namedtuple
from types import SimpleNamespace
from typing import List, NamedTuple, Optional, Tuple, Union

import cv2
import matplotlib
import numpy as np

ANNOTATOR = "controlnet_aux==0.0.10"
READER = "dwpose==1.0.1"


def wheel(requirement):
    """The wheel of `requirement`, downloaded once into ~/.cache."""
    cache = os.path.expanduser("~/.cache/marionette-controlnet-aux")
    name = requirement.split("==")[0]
    wheels = glob.glob(os.path.join(cache, f"{name}-*.whl"))
    if not wheels:
        os.makedirs(cache, exist_ok=True)
        subprocess.run(
            [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", requirement, "-d", cache], check=True
        )
        wheels = glob.glob(os.path.join(cache, f"{name}-*.whl"))
    return zipfile.ZipFile(wheels[0])


def definitions(space, source, names):
    """Runs the top-level definitions `names` of `source` in `space`, nothing else of it."""
    tree = ast.parse(source)
    wanted = [n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and n.name in names]
    assert {n.name for n in wanted} == set(names), (names, [n.name for n in wanted])
    exec(compile(ast.Module(body=wanted, type_ignores=[]), "annotator", "exec"), space)
    return space


def common_space():
    return {"np": np, "cv2": cv2, "math": math, "json": json, "matplotlib": matplotlib, "eps": 0.01,
            "List": List, "Union": Union, "Tuple": Tuple, "Optional": Optional, "NamedTuple": NamedTuple}


def annotator():
    """controlnet_aux's `draw_bodypose` and `draw_handpose`."""
    space = common_space()
    space["Keypoint"] = namedtuple("Keypoint", "x y")
    source = wheel(ANNOTATOR).read("controlnet_aux/open_pose/util.py").decode()
    return definitions(space, source, ["draw_bodypose", "draw_handpose"])


def reader():
    """The JSON reader `decode_json_as_poses` and `draw_poses` with the drawing they call."""
    archive = wheel(READER)
    space = common_space()
    exec(archive.read("dwpose/types.py").decode(), space)  # NamedTuples, typing only
    util = definitions(
        common_space() | {"Keypoint": space["Keypoint"]},
        archive.read("dwpose/util.py").decode(),
        ["is_normalized", "draw_bodypose", "draw_handpose", "draw_facepose"],
    )
    space["util"] = SimpleNamespace(**util)
    return definitions(space, archive.read("dwpose/__init__.py").decode(), ["draw_poses", "decode_json_as_poses"])


def compare(what, ours, theirs):
    """IoU of drawn pixels and the share of shared pixels within 8 in every channel."""
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    theirs_drawn, ours_drawn = theirs.any(axis=2), ours.any(axis=2)
    both = theirs_drawn & ours_drawn
    iou = both.sum() / max((theirs_drawn | ours_drawn).sum(), 1)
    close = (np.abs(theirs.astype(int) - ours.astype(int)).max(axis=2) <= 8)[both].mean() if both.any() else 1.0
    print(f"  {what}: IoU {iou:.4f}, colours within 8 on {100 * close:.2f} % of {both.sum()} pixels drawn by both")
    return iou >= 0.98 and close >= 0.98 and both.sum() > 0


def main(shot):
    stem = shot[: -len(".png")]
    people = json.load(open(stem + ".cn-openpose.json"))
    w, h = people["canvas_width"], people["canvas_height"]
    space = annotator()
    keypoint = space["Keypoint"]
    canvas = np.zeros((h, w, 3), dtype=np.uint8)
    for person in people["people"]:
        p = person["pose_keypoints_2d"]
        points = [keypoint(p[3 * k] / w, p[3 * k + 1] / h) if p[3 * k + 2] > 0 else None for k in range(18)]
        canvas = space["draw_bodypose"](canvas, points)
        for side in ("left", "right"):
            h21 = person.get(f"hand_{side}_keypoints_2d") or []
            hand = [keypoint(h21[3 * k] / w, h21[3 * k + 1] / h) for k in range(len(h21) // 3)]
            canvas = space["draw_handpose"](canvas, hand or None)
    ours = cv2.cvtColor(cv2.imread(stem + ".cn-openpose.png"), cv2.COLOR_BGR2RGB)
    hands = sum(bool(p.get(f"hand_{s}_keypoints_2d")) for p in people["people"] for s in ("left", "right"))
    print(f"{len(people['people'])} people ({hands} hands) at {w}x{h}:")
    drawn = compare("the annotator's drawing of the points", ours, canvas)

    read = reader()
    poses, canvas_height, canvas_width = read["decode_json_as_poses"](open(stem + ".cn-openpose.json").read())
    assert (canvas_width, canvas_height) == (w, h)
    assert len(poses) == len(people["people"])
    read_back = compare("the JSON read back by the annotator's reader", ours, read["draw_poses"](poses, h, w))
    if not (drawn and read_back):
        sys.exit("the drawing is not the annotator's")


main(sys.argv[1])
