"""What the package's tests share: the repository's root and the binary they compare with."""

import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
BIN = os.environ.get("MARIONETTE_BIN", "marionette")


def binary(*args, check=True):
    """The binary run with `args`: its completed process (its exit status checked unless
    `check` is false)."""
    done = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True)
    if check:
        assert done.returncode == 0, done.stderr
    return done
