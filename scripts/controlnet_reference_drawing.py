#!/usr/bin/env python3
"""ControlNet's own OpenPose drawing (controlnet_aux's draw_bodypose, with OpenCV) of the body
points in a Marionette `shot.openpose.json`, beside Marionette's `shot.openpose.png`, to look
at: writes SHOT.controlnet.png (the reference) and SHOT.compare.png (ours | reference | the
pixels that differ in white), and prints the share of pixels that differ.

usage: controlnet_reference_drawing.py SHOT.openpose.json"""
import json, math, sys
from pathlib import Path

import cv2
import numpy as np

LIMBS = [[2, 3], [2, 6], [3, 4], [4, 5], [6, 7], [7, 8], [2, 9], [9, 10], [10, 11], [2, 12], [12, 13], [13, 14],
         [2, 1], [1, 15], [15, 17], [1, 16], [16, 18]]
COLOURS = [[255, 0, 0], [255, 85, 0], [255, 170, 0], [255, 255, 0], [170, 255, 0], [85, 255, 0], [0, 255, 0],
           [0, 255, 85], [0, 255, 170], [0, 255, 255], [0, 170, 255], [0, 85, 255], [0, 0, 255], [85, 0, 255],
           [170, 0, 255], [255, 0, 255], [255, 0, 170], [255, 0, 85]]
FROM_25 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18]

path = Path(sys.argv[1])
data = json.loads(path.read_text())
w, h = data["canvas_width"], data["canvas_height"]
canvas = np.zeros((h, w, 3), dtype=np.uint8)
for person in data["people"]:
    body = np.array(person["pose_keypoints_2d"]).reshape(-1, 3)
    points = [body[j] if body[j, 2] > 0 else None for j in FROM_25]
    for (a, b), colour in zip(LIMBS, COLOURS):
        pa, pb = points[a - 1], points[b - 1]
        if pa is None or pb is None:
            continue
        x, y = np.array([pa[0], pb[0]]), np.array([pa[1], pb[1]])
        length = math.hypot(x[0] - x[1], y[0] - y[1])
        angle = math.degrees(math.atan2(y[0] - y[1], x[0] - x[1]))
        polygon = cv2.ellipse2Poly((int(np.mean(x)), int(np.mean(y))), (int(length / 2), 4), int(angle), 0, 360, 1)
        cv2.fillConvexPoly(canvas, polygon, [int(float(c) * 0.6) for c in colour])
    for p, colour in zip(points, COLOURS):
        if p is not None:
            cv2.circle(canvas, (int(p[0]), int(p[1])), 4, colour, thickness=-1)
stem = str(path).removesuffix(".openpose.json")
ours = cv2.cvtColor(cv2.imread(stem + ".openpose.png"), cv2.COLOR_BGR2RGB)
cv2.imwrite(stem + ".controlnet.png", cv2.cvtColor(canvas, cv2.COLOR_RGB2BGR))
differ = np.any(ours != canvas, axis=2)
drawn = np.any((ours > 0) | (canvas > 0), axis=2)
print(f"{differ.sum()} of {drawn.sum()} drawn pixels differ ({100 * differ.sum() / max(drawn.sum(), 1):.1f} %)")
side = np.concatenate([ours, canvas, np.repeat(differ[:, :, None] * 255, 3, axis=2).astype(np.uint8)], axis=1)
cv2.imwrite(stem + ".compare.png", cv2.cvtColor(side, cv2.COLOR_RGB2BGR))
