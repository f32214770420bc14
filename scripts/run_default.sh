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
#      with bulkflow-matpoint, plot out/default/triaxial_mc.png;
#   5. the MPM job: the same hopper (thesis Table 4.2 material) as a material-point scene,
#      inputs/demo/wedge_hopper_mpm_discharge.inp (cell 0.05 m, 4756 particles): 1 s fill with the
#      outlet closed, then 2 s of discharge; the solver's wall time and the load average are printed.
#      Then out/default/wedge_hopper_mpm_discharge.gif (particles coloured by speed, walls, outlet;
#      bulkflow-mpm-movie), ..._mdr.png (discharge rate against time beside Beverloo and
#      Rose-Tanaka; bulkflow-mpm-digest, figures also in ..._digest.json) and, last, a two-line
#      digest: the steady discharge rate with the theories' values and ratios, and the flow mode.
# Outputs go to out/default/. Environment: NP (ranks; default nproc), SCENE (another element .inp),
# SKIP_MATPOINT=1 (no material-point job), SKIP_MPM=1 (no MPM job), MPM_SCENE (another MPM
# hopper .inp for step 5).
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

if [ "${SKIP_MPM:-0}" != 1 ]; then
  mpm_scene=${MPM_SCENE:-$repo/inputs/demo/wedge_hopper_mpm_discharge.inp}
  mpm_name=$(basename "$mpm_scene" .inp)
  echo "== MPM job: fill and discharge of the hopper, $mpm_scene on $np rank(s) (about a minute on 2 idle cores)"
  load_before=$(cut -d' ' -f1-3 /proc/loadavg)
  start=$(date +%s%N)
  "${mpi[@]}" "$repo/build/bin/bulkflow" "$mpm_scene" --output "$out/$mpm_name" --quiet
  end=$(date +%s%N)
  ms=$(( (end - start) / 1000000 ))
  printf '  solver wall time %d.%d s (load average before %s, after %s)\n' $((ms / 1000)) $((ms % 1000 / 100)) \
    "$load_before" "$(cut -d' ' -f1-3 /proc/loadavg)"
  "$py" -m bulkflow.post.mpm_movie "$out/$mpm_name" --scene "$mpm_scene" -o "$out/$mpm_name.gif"
  echo "  particles for ParaView: $out/$mpm_name.xmf"
  echo "== MPM digest ($out/${mpm_name}_mdr.png, $out/${mpm_name}_digest.json)"
  "$py" -m bulkflow.post.mpm_digest "$out/$mpm_name" --scene "$mpm_scene" -o "$out/${mpm_name}_mdr.png" \
    --json "$out/${mpm_name}_digest.json"
fi
