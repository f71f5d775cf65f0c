#!/usr/bin/env bash
# Runs every crate's tests, after installing the system packages the machine lacks. The
# real-data tests run when MARIONETTE_DATA names the course data folder (relative to where
# the command was typed); without it they are reported as ignored.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ -n "${MARIONETTE_DATA:-}" ] && [ "$PWD" != "$here" ]; then
  MARIONETTE_DATA=$(cd "$MARIONETTE_DATA" && pwd)
  export MARIONETTE_DATA
fi
cd "$here"
./scripts/ensure-tools.sh
exec cargo test "$@"
