#!/usr/bin/env bash
# Runs every crate's tests, after installing the system packages the machine lacks, then
# (without arguments) the Python package's, built into a virtual environment. The real-data
# tests run when MARIONETTE_DATA names the course data folder (relative to where the command
# was typed); without it they are reported as ignored (skipped, in pytest).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ -n "${MARIONETTE_DATA:-}" ] && [ "$PWD" != "$here" ]; then
  MARIONETTE_DATA=$(cd "$MARIONETTE_DATA" && pwd)
  export MARIONETTE_DATA
fi
cd "$here"
./scripts/ensure-tools.sh
cargo test "$@"
if [ $# -eq 0 ]; then
  ./scripts/python-tests.sh
fi
