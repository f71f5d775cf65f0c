"""100 renders of 320x240 of the default scene's three puppets, drawn as plain skins (as a
data set's are), in one Python process (`marionette` built by
scripts/python-tests.sh into its venv): the first call's time, the later calls' median, the
drawn frame of the binary's render of the same scene as a frame sequence, and the process's
resident memory after the 10th and the 100th call.

    $CARGO_TARGET_DIR/python-venv/bin/python benches/python_render.py $CARGO_TARGET_DIR/debug/marionette
"""

import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import marionette as mt

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "assets/default_scene.ron"


def resident_mib():
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "marionette"
    plain = Path(tempfile.mkdtemp(prefix="marionette-bench-")) / "scene.ron"
    plain.write_text(SCENE.read_text().replace("display: Both", "display: Mesh").replace("weight_colors: true", "weight_colors: false"))
    scene = mt.Scene.load(plain)
    times, memory = [], {}
    for k in range(100):
        started = time.perf_counter()
        mt.render(scene, width=320, height=240)
        times.append(time.perf_counter() - started)
        if k + 1 in (10, 100):
            memory[k + 1] = resident_mib()
    later = statistics.median(times[1:])
    frames = Path(tempfile.mkdtemp(prefix="marionette-bench-"))
    said = subprocess.run(
        [binary, "render", plain, "--width", "320", "--height", "240", "--from", "0", "--to", "1", "--fps", "20",
         "--out", frames / "f%04d.png"],
        capture_output=True, text=True, check=True,
    ).stderr
    frame = re.search(r"a drawn frame (\d+) ms", said)
    frame_ms = float(frame.group(1)) if frame else float("nan")
    print(f"first render {times[0]:.2f} s; later renders median {later * 1e3:.0f} ms "
          f"(min {min(times[1:]) * 1e3:.0f}, max {max(times[1:]) * 1e3:.0f})")
    print(f"the binary's drawn frame {frame_ms:.0f} ms: a later render is {later * 1e3 / frame_ms:.2f} drawn frames")
    slow = [k + 2 for k, t in enumerate(times[1:]) if t * 1e3 > 2 * frame_ms]
    print(f"later renders over 2 drawn frames: {len(slow)} of {len(times) - 1} (calls {slow})")
    print(f"resident memory after render 10: {memory[10]:.0f} MiB, after 100: {memory[100]:.0f} MiB "
          f"({(memory[100] / memory[10] - 1) * 100:+.1f} %)")


if __name__ == "__main__":
    main()
