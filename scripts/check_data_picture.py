#!/usr/bin/env python3
"""Checks `marionette render --data` against independent arithmetic (numpy) and pycocotools.

usage: check_data_picture.py SHOT.json FOCUS_X FOCUS_Y FOCUS_Z YAW PITCH DISTANCE FOV_DEGREES

From the scene's camera alone (a pinhole: yaw about y, then pitch about x; the camera looks
along its -z from focus + R (0, 0, distance); fov vertical over the picture's height), it
projects each annotation's 3D joints and compares them with the COCO keypoints that are
v > 0; it does the same with the file's own K and world_to_camera. pycocotools loads the file;
each annotation's mask (annToMask) equals the mask picture's pixels of its instance and its
bbox that mask's box. The OpenPose JSON's body points equal the COCO points they share.
Prints the largest errors; exits 1 when a check fails."""
import json, math, sys
from pathlib import Path

import numpy as np
from PIL import Image
from pycocotools.coco import COCO

COCO_OF_BONE = {"left_shoulder": "LeftUpperArm", "right_shoulder": "RightUpperArm", "left_elbow": "LeftLowerArm",
                "right_elbow": "RightLowerArm", "left_wrist": "LeftHand", "right_wrist": "RightHand",
                "left_hip": "LeftUpperLeg", "right_hip": "RightUpperLeg", "left_knee": "LeftLowerLeg",
                "right_knee": "RightLowerLeg", "left_ankle": "LeftFoot", "right_ankle": "RightFoot"}
BODY_25 = ["nose", "neck", "right_shoulder", "right_elbow", "right_wrist", "left_shoulder", "left_elbow", "left_wrist",
           "mid_hip", "right_hip", "right_knee", "right_ankle", "left_hip", "left_knee", "left_ankle", "right_eye",
           "left_eye", "right_ear", "left_ear", "left_big_toe", "left_small_toe", "left_heel", "right_big_toe",
           "right_small_toe", "right_heel"]


def scene_camera(focus, yaw, pitch, distance, fov, width, height):
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rx = np.array([[1, 0, 0], [0, cp, -sp], [0, sp, cp]])
    r = ry @ rx
    eye = np.array(focus) + r @ np.array([0, 0, distance])
    f = height / 2 / math.tan(math.radians(fov) / 2)
    k = np.array([[f, 0, width / 2], [0, f, height / 2], [0, 0, 1]])
    flip = np.diag([1.0, -1.0, -1.0])
    rot = flip @ r.T
    return k, rot, -rot @ eye


def project(k, rot, t, p):
    c = rot @ np.asarray(p, dtype=float) + t
    uvw = k @ c
    return uvw[:2] / uvw[2]


def main():
    shot = Path(sys.argv[1])
    focus = [float(x) for x in sys.argv[2:5]]
    yaw, pitch, distance, fov = (float(x) for x in sys.argv[5:9])
    data = json.loads(shot.read_text())
    failures = []
    ours_err, file_err = 0.0, 0.0
    names = data["categories"][0]["keypoints"]
    coco = COCO(str(shot))
    mask_picture = np.array(Image.open(shot.with_suffix(".mask.png")))
    openpose = json.loads(shot.with_suffix(".openpose.json").read_text())
    people = {p["person_id"][0]: p for p in openpose["people"]}
    for image in data["images"]:
        w, h = image["width"], image["height"]
        k, rot, t = scene_camera(focus, yaw, pitch, distance, fov, w, h)
        cam = image["camera"]
        fk = np.array(cam["K"], dtype=float)
        m = np.array(cam["world_to_camera"], dtype=float)
        for ann in coco.loadAnns(coco.getAnnIds(imgIds=[image["id"]])):
            kp = np.array(ann["keypoints"], dtype=float).reshape(-1, 3)
            for name, bone in COCO_OF_BONE.items():
                i = names.index(name)
                if kp[i, 2] == 0 or bone not in ann["joints_3d"]:
                    continue
                p = ann["joints_3d"][bone]
                ours_err = max(ours_err, float(np.abs(project(k, rot, t, p) - kp[i, :2]).max()))
                file_err = max(file_err, float(np.abs(project(fk, m[:3, :3], m[:3, 3], p) - kp[i, :2]).max()))
            mask = coco.annToMask(ann)
            mine = (mask_picture == ann["instance_id"]).astype(np.uint8)
            if not np.array_equal(mask, mine):
                failures.append(f"{ann['character']}: annToMask differs from the mask picture in {int((mask != mine).sum())} pixels")
            ys, xs = np.nonzero(mine)
            box = [xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1]
            if max(abs(a - b) for a, b in zip(box, ann["bbox"])) > 1:
                failures.append(f"{ann['character']}: bbox {ann['bbox']} against the mask's {box}")
            person = people.get(ann["instance_id"])
            if person is not None:
                body = np.array(person["pose_keypoints_2d"]).reshape(-1, 3)
                for i, name in enumerate(names):
                    if kp[i, 2] > 0 and name in BODY_25:
                        j = BODY_25.index(name)
                        if np.abs(body[j, :2] - kp[i, :2]).max() > 1e-4:
                            failures.append(f"{ann['character']}: OpenPose {name} {body[j]} against COCO {kp[i]}")
    print(f"largest keypoint error: scene camera {ours_err:.2e} px, file's K and world_to_camera {file_err:.2e} px")
    if ours_err > 0.01 or file_err > 0.01:
        failures.append("a keypoint is more than 0.01 px from its projection")
    for f in failures:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)


main()
