"""Draws the people of a `render --controlnet` picture's `cn-openpose.json` with the OpenPose
annotator's own `draw_bodypose` and `draw_handpose` (lllyasviel's, as `controlnet_aux`
carries them in `open_pose/util.py`, in its `draw_poses` order: each person's body, left
hand, right hand) and holds Marionette's `cn-openpose.png` to that drawing: drawn pixels
agree at IoU >= 0.98, colours within 8 on >= 98 % of the pixels both drew.

The annotator's code is taken from the `controlnet_aux` wheel at run time (`pip download
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
from typing import List, Tuple, Union

import cv2
import numpy as np

WHEEL = "controlnet_aux==0.0.10"


def annotator():
    cache = os.path.expanduser("~/.cache/marionette-controlnet-aux")
    wheels = glob.glob(os.path.join(cache, "controlnet_aux-*.whl"))
    if not wheels:
        os.makedirs(cache, exist_ok=True)
        subprocess.run(
            [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", WHEEL, "-d", cache], check=True
        )
        wheels = glob.glob(os.path.join(cache, "controlnet_aux-*.whl"))
    source = zipfile.ZipFile(wheels[0]).read("controlnet_aux/open_pose/util.py").decode()
    tree = ast.parse(source)
    wanted = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name in ("draw_bodypose", "draw_handpose")]
    module = ast.Module(body=wanted, type_ignores=[])
    space = {"np": np, "cv2": cv2, "math": math, "List": List, "Union": Union, "Tuple": Tuple, "eps": 0.01}
    space["Keypoint"] = namedtuple("Keypoint", "x y")
    exec(compile(module, "util.py", "exec"), space)
    return space


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
    assert ours.shape == canvas.shape, (ours.shape, canvas.shape)
    theirs_drawn, ours_drawn = canvas.any(axis=2), ours.any(axis=2)
    both = theirs_drawn & ours_drawn
    iou = both.sum() / max((theirs_drawn | ours_drawn).sum(), 1)
    close = (np.abs(canvas.astype(int) - ours.astype(int)).max(axis=2) <= 8)[both].mean() if both.any() else 1.0
    hands = sum(bool(p.get(f"hand_{s}_keypoints_2d")) for p in people["people"] for s in ("left", "right"))
    print(f"{len(people['people'])} people ({hands} hands) at {w}x{h}: IoU {iou:.4f}, colours within 8 on {100 * close:.2f} % "
          f"of {both.sum()} pixels drawn by both")
    if not (iou >= 0.98 and close >= 0.98 and both.sum() > 0):
        sys.exit("the drawing is not the annotator's")


main(sys.argv[1])
