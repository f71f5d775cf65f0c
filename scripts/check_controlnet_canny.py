"""Holds a `render --controlnet --canny LOW,HIGH` picture's `cn-canny.png` to OpenCV's own
edges of the picture: `cv2.Canny(rgb, LOW, HIGH)` on its RGB, as ControlNet's canny
preprocessor (controlnet_aux's CannyDetector, sd-webui-controlnet's `canny`) calls it.
Every pixel must agree.

    python3 check_controlnet_canny.py SHOT.png LOW HIGH
"""
import sys

import cv2
import numpy as np


def main(shot, low, high):
    rgb = cv2.cvtColor(cv2.imread(shot, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
    theirs = cv2.Canny(rgb, low, high)
    ours = cv2.imread(shot[: -len(".png")] + ".cn-canny.png", cv2.IMREAD_UNCHANGED)
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    differ = int((ours != theirs).sum())
    print(f"canny {low:g},{high:g}: {int((theirs > 0).sum())} edge pixels by OpenCV, {int((ours > 0).sum())} ours, "
          f"{differ} of {ours.size} pixels differ")
    if differ or not (theirs > 0).any():
        sys.exit("the edges are not OpenCV's")


main(sys.argv[1], float(sys.argv[2]), float(sys.argv[3]))
