#!/usr/bin/env bash
# What `./run.sh` and `./test.sh` need before cargo: the Debian packages (installed only when
# one is missing) and a Rust toolchain (named when missing; rustup installs it).
set -euo pipefail
cd "$(dirname "$0")/.."
if command -v dpkg-query > /dev/null; then
  ./scripts/install-deps.sh
else
  echo "ensure-tools: not a Debian machine; install the packages scripts/install-deps.sh names yourself" >&2
fi
if ! command -v cargo > /dev/null; then
  echo "ensure-tools: cargo not found: install Rust 1.95 or later (https://rustup.rs), then run this again" >&2
  exit 1
fi
# The tests' independent references (numpy, pycocotools, pillow, webdataset, opencv,
# matplotlib), installed when missing.
if ! python3 -c "import numpy, pycocotools, PIL, webdataset, cv2, matplotlib" 2> /dev/null; then
  packages=(numpy pycocotools pillow webdataset "opencv-python-headless<4.11" matplotlib)
  python3 -m pip install --quiet "${packages[@]}" \
    || python3 -m pip install --quiet --break-system-packages "${packages[@]}" \
    || echo "ensure-tools: could not install ${packages[*]} for python3; the data-picture and data-set tests need them" >&2
fi
