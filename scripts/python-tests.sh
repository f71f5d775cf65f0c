#!/usr/bin/env bash
# The Python package's tests: its wheel built by maturin (with the tests' Cargo profile and
# target folder, so a warm build builds nothing twice) into a virtual environment beside
# the build, then its pytest tests run against the binary the Rust tests built.
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-$PWD/target}
venv=$target/python-venv
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import maturin, numpy, pytest" 2> /dev/null; then
  "$venv/bin/pip" install --quiet "maturin>=1.9,<2" numpy pytest
fi
wheels=$target/python-wheels
rm -rf "$wheels"
(cd crates/marionette-python && CARGO_TARGET_DIR=$target "$venv/bin/maturin" build --quiet --out "$wheels")
"$venv/bin/pip" install --quiet --force-reinstall --no-deps "$wheels"/marionette-*.whl
cargo build --quiet --bin marionette
MARIONETTE_BIN=$target/debug/marionette "$venv/bin/python" -m pytest -q crates/marionette-python/tests
