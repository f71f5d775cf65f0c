"""Where bone heat disagrees with a 6.837 model's own weights: binds ModelN with
`marionette bind --method heat`, compares the heaviest joint of every vertex with
ModelN.attach's, and draws the mesh's vertices from the front and the side (nearest on
top): grey where they agree, red where they do not.

    python3.11 scripts/heat_disagreement.py ../shared/data/mit6837 3 target/debug/marionette docs/heat_model3.png

Needs numpy and pillow.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

data, model, marionette, out = Path(sys.argv[1]), sys.argv[2], sys.argv[3], Path(sys.argv[4])
mesh, skel = data / f"Model{model}.obj", data / f"Model{model}.skel"
with tempfile.TemporaryDirectory() as tmp:
    ours_path = Path(tmp) / "heat.attach"
    report = subprocess.run(
        [marionette, "bind", str(mesh), str(skel), "--method", "heat", "--out", str(ours_path), "--against", str(data / f"Model{model}.attach")],
        check=True, capture_output=True, text=True,
    ).stdout
    ours = np.loadtxt(ours_path)
theirs = np.loadtxt(data / f"Model{model}.attach")
points = np.array([list(map(float, l.split()[1:4])) for l in open(mesh) if l.startswith("v ")])
disagree = ours.argmax(1) != theirs.argmax(1)
print(report.strip().splitlines()[-1], f"({disagree.sum()} vertices differ)")

SIZE, MARGIN = 600, 30
lo, hi = points.min(0), points.max(0)
scale = (SIZE - 2 * MARGIN) / (hi - lo).max()
image = Image.new("RGB", (2 * SIZE, SIZE + 40), "white")
draw = ImageDraw.Draw(image)
for panel, (across, depth, title) in enumerate([(0, 2, "front"), (2, 0, "side")]):
    # Far points first, so the near ones are drawn over them.
    order = np.argsort(points[:, depth] * (1 if panel == 0 else -1))
    for i in order:
        x = panel * SIZE + MARGIN + (points[i, across] - lo[across]) * scale
        y = SIZE - MARGIN - (points[i, 1] - lo[1]) * scale
        r = 2.5 if disagree[i] else 1.5
        draw.ellipse([x - r, y - r, x + r, y + r], fill=(220, 30, 30) if disagree[i] else (150, 150, 150))
    draw.text((panel * SIZE + MARGIN, SIZE), f"Model{model}, {title}: red = heaviest joint differs from Model{model}.attach", fill="black")
draw.text((MARGIN, SIZE + 18), report.strip().splitlines()[-1].split(": ", 1)[-1], fill="black")
image.save(out)
print("wrote", out)
