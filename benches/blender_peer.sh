#!/usr/bin/env bash
# Marionette's data sets beside Blender's in one run: three SMPL bodies a picture at
# 640x480 with depth and normals, made by Blender's Workbench and Cycles (16 samples)
# (benches/blender_peer.py) and by `marionette generate` (the example spec with
# `Smpl(folder: ..)` bodies, `per_picture: (3, 3)`, `data: true`; its FXAA, then
# multisampled, then FXAA with four scenes a frame); prints each one's pictures a second
# after the first and Marionette's ratios to both.
#
#   benches/blender_peer.sh SMPL_DIR [COUNT]      (MARIONETTE: the binary, PYTHON: one with bpy)
set -euo pipefail
smpl=$(cd "${1:?a folder of SMPL bodies: smpl_00.obj, ... (the course data smpl folder)}" && pwd)
count=${2:-30}
here=$(cd "$(dirname "$0")" && pwd)
marionette=${MARIONETTE:-${CARGO_TARGET_DIR:-$here/../target}/debug/marionette}
python=${PYTHON:-python3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

rate() { sed -n 's/.*: \([0-9.]*\) pictures a second after the first.*/\1/p' | tail -1; }

workbench=$("$python" "$here/blender_peer.py" --smpl "$smpl" --engine workbench --count "$count" --out "$work/workbench" 2>&1 | rate)
cycles=$("$python" "$here/blender_peer.py" --smpl "$smpl" --engine cycles --samples 16 --count "$count" --out "$work/cycles" 2>&1 | rate)

"$marionette" generate --example 2>/dev/null \
  | sed -e "s/count: 16/count: $count/" -e 's/width: 320/width: 640/' -e 's/height: 240/height: 480/' \
        -e "s|(what: Puppet, weight: 1.0),|(what: Smpl(folder: \"$smpl\", betas: Normal(mean: 0.0, sd: 1.0)), weight: 1.0),|" \
        -e 's/per_picture: (1, 3)/per_picture: (3, 3)/' -e 's/data: false/data: true/' > "$work/spec.ron"
ours=$("$marionette" generate "$work/spec.ron" --out "$work/marionette" 2>&1 | rate)
sed 's/antialias: Fxaa/antialias: Multisample/' "$work/spec.ron" > "$work/multisample.ron"
multisampled=$("$marionette" generate "$work/multisample.ron" --out "$work/multisampled" 2>&1 | rate)
four=$("$marionette" generate "$work/spec.ron" --out "$work/four" --scenes-a-frame 4 2>&1 | rate)

echo "pictures a second after the first, $count pictures of three SMPL bodies at 640x480:"
echo "  Blender Workbench           $workbench"
echo "  Blender Cycles 16           $cycles"
echo "  Marionette (FXAA)           $ours"
echo "  Marionette (multisampled)   $multisampled"
echo "  Marionette (FXAA, 4 a frame) $four"
for m in "FXAA $ours" "multisampled $multisampled" "FXAA-4-a-frame $four"; do
  awk -v name="${m% *}" -v m="${m#* }" -v w="$workbench" -v c="$cycles" \
    'BEGIN { printf "  Marionette %s / Workbench %.2fx, / Cycles %.1fx\n", name, m / w, m / c }'
done
