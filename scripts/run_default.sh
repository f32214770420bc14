#!/usr/bin/env bash
# The main job on the default scene (README "Two commands"):
#   1. set up and build (scripts/build.sh release: installs what is missing, builds build/);
#   2. run bulkflow on inputs/demo/wedge_hopper.inp (plane-strain wedge hopper half model,
#      Mohr-Coulomb fill settling under gravity against frictional rigid walls, outlet closed) on
#      all cores with mpirun; the solver prints its effects, energies, wall forces and the time
#      per effect;
#   3. print a 3-line digest from the history (ALLKE/ALLIE, wall loads against the fill weight,
#      energy balance) and write a picture: out/default/wedge_hopper.png (deformed mesh coloured
#      by vertical stress, walls, energies and wall loads against time);
#   4. the material-point job (the previous default): drained triaxial test of a Mohr-Coulomb sand
#      with bulkflow-matpoint, plot out/default/triaxial_mc.png.
# Outputs go to out/default/. Environment: NP (ranks; default nproc), SCENE (another .inp),
# SKIP_MATPOINT=1 (main job only).
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out="$repo/out/default"
py="$repo/.venv/bin/python"

bash "$repo/scripts/build.sh" release
mkdir -p "$out"

scene=${SCENE:-$repo/inputs/demo/wedge_hopper.inp}
name=$(basename "$scene" .inp)
np=${NP:-$(nproc)}
mpi=()
if [ "$np" -gt 1 ] && command -v mpirun >/dev/null 2>&1; then
  if [ "$(id -u)" -eq 0 ]; then
    export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
  fi
  mpi=(mpirun -np "$np" --oversubscribe)
fi

echo "== main job: bulkflow $scene on $np rank(s)"
start=$(date +%s%N)
"${mpi[@]}" "$repo/build/bin/bulkflow" "$scene" --output "$out/$name" --quiet
end=$(date +%s%N)
ms=$(( (end - start) / 1000000 ))
printf '  wall time %d.%d s\n' $((ms / 1000)) $((ms % 1000 / 100))
echo "== digest ($out/${name}_history.csv)"
"$py" -m bulkflow.post.run_digest "$out/$name" --scene "$scene"
"$py" -m bulkflow.post.hopper_plot "$out/$name.h5" --scene "$scene" -o "$out/$name.png" --field sv
echo "  fields for ParaView: $out/$name.xmf"

if [ "${SKIP_MATPOINT:-0}" != 1 ]; then
  echo "== material-point job: drained triaxial test (inputs/matpoint/triaxial_mc.inp)"
  "$repo/build/bin/bulkflow-matpoint" "$repo/inputs/matpoint/triaxial_mc.inp" -o "$out/triaxial_mc.csv"
  "$repo/.venv/bin/bulkflow-matpoint-plot" "$out/triaxial_mc.csv" -o "$out/triaxial_mc.png"
  echo "  plot: $out/triaxial_mc.png"
fi
