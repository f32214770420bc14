#!/usr/bin/env bash
# The main job on a default scene: set up (installs what is missing), build, then run the
# material-point driver on a drained triaxial test of Mohr-Coulomb sand, print its summary and
# write a plot of q-ea and ev-ea. Outputs go to out/default/.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$repo/scripts/build.sh" release
out="$repo/out/default"
mkdir -p "$out"
"$repo/build/bin/bulkflow-matpoint" "$repo/inputs/matpoint/triaxial_mc.inp" -o "$out/triaxial_mc.csv"
"$repo/.venv/bin/bulkflow-matpoint-plot" "$out/triaxial_mc.csv" -o "$out/triaxial_mc.png"
echo "plot: $out/triaxial_mc.png"
