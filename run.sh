#!/usr/bin/env bash
# Opens the editor (on the embedded default scene, or on the paths given), after installing
# the system packages the machine lacks.
set -euo pipefail
cd "$(dirname "$0")"
./scripts/ensure-tools.sh
exec cargo run -- "$@"
