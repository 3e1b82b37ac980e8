#!/usr/bin/env bash
# Issue 31, fifth session (docs/sh-and-irradiance-volumes.md, "hanging corners computed,
# equal total rays"): per scene, one bake of the depth-4 lattice (512 rays, the rotated
# repeat's measured noise, uncalibrated, no gradients: trilinear lookups and merging use
# none), the depth-4 grid, and the octrees merged from it by bias tolerance in units of the
# probes' median noise (one scale for every scene, derived from the bake), hanging corners
# computed by the lookup (not stored); each measured on the moving sphere and at the
# camera's surface points (128 x 128) twice: with the bake's probes (equal rays per probe)
# and with its stored probes baked again with the grid's total rays spread over them
# (equal total rays). Results: docs/results/irradiance_volume_equal_rays.json; table:
# docs/studies/irradiance_volume_equal_rays.py. A few minutes a scene on 2 shared cores.
# MODE=fixed: tolerances 1, 3, 8 only, each octree also with 512 rays a probe (equal rays
# per probe, nothing pooled), runs "equal-rays-512-SCENE". MODE=floor: the Cornell boxes'
# path only, with 4096-sample references (the path measure's noise floor), runs
# "equal-rays-floor-SCENE". MODE=lookup: the program's adaptive octree on the Cornell box with
# hanging corners stored and computed (probes, error, trilinear lookup time on 1 thread).
# Usage: [MODE=fixed|floor] docs/studies/irradiance_volume_equal_rays.sh [SCENE...]   (BOUNCE_BIN: default build/bin; BOUNCE_RUNS: default build/runs)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}/irradiance_volume"
out="${BOUNCE_RUNS:-build/runs}/irradiance_volume"
results=docs/results/irradiance_volume_equal_rays.json
mkdir -p "$out"
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell cornell-box bunny living-room modern-hall sponza conference)
mode="${MODE:-main}"
if [[ "$mode" == lookup ]]; then  # the program's adaptive octree, hanging corners stored and computed: probes, error, lookup time
  for h in stored computed; do
    "$bin" --scene cornell --gradient-step 0 --hanging-corners "$h" --repeat 15 --threads 1 --json "$out/lookup-$h.json" 2>/dev/null \
      | grep -E "^(trilinear|cornell)"
    python3 docs/studies/results.py add "$results" "equal-rays-lookup-$h-cornell" "$out/lookup-$h.json"
  done
  exit 0
fi
tolerances=(0.1 0.2 0.35 0.5 0.75 1 1.5 2 3 5 8)
extra=(--sweep-surface)
name=equal-rays
case "$mode" in
  fixed) tolerances=(1 3 8); name=equal-rays-512 ;;
  floor) tolerances=(1 3 8); name=equal-rays-floor; extra=(--ref-samples 4096)
         [[ $# -gt 0 ]] || scenes=(cornell cornell-box) ;;
esac
for sc in "${scenes[@]}"; do
  "$bin" --scene "$sc" --mode uniform --max-depth 4 --noise-estimate rotated-repeat --calibrate-noise off \
    --gradient-step 0 --hanging-corners computed --bias-tolerance-unit noise --sweep-depths 4 \
    --sweep-bias-tolerance "${tolerances[@]}" "${extra[@]}" --sweep-equal-rays 4 \
    --json "$out/$name-$sc.json" 2>/dev/null | grep -E "^(grid|sweep|rebaked|$sc)"
  python3 docs/studies/results.py add "$results" "$name-$sc" "$out/$name-$sc.json"
done
