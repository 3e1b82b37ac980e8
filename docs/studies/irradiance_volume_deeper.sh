#!/usr/bin/env bash
# Issue 31, fourth session (docs/sh-and-irradiance-volumes.md, "refining deeper than the
# grid"): per scene, one bake of the depth-5 lattice (program defaults otherwise: 512 rays,
# 1024-sample references, trilinear; the rotated repeat measures each probe's noise,
# uncalibrated; no gradients, which neither trilinear lookups nor merging use), then from
# those same probes the uniform grids of depth 3, 4 and 5 and the octrees merged from each
# of these depths, by bias budget (noise-relative bound) and by bias tolerance (a bound in
# units of the scene's light), each measured on the moving sphere and at the camera's
# surface points (128 x 128, reference in two halves so its noise can be taken out).
# Results: docs/results/irradiance_volume_deeper.json; table and figure:
# docs/studies/irradiance_volume_deeper.py. About 1-5 minutes a scene on 2 shared cores.
# Usage: docs/studies/irradiance_volume_deeper.sh [SCENE...]   (BOUNCE_BIN: default build/bin; BOUNCE_RUNS: default build/runs)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}/irradiance_volume"
out="${BOUNCE_RUNS:-build/runs}/irradiance_volume"
results=docs/results/irradiance_volume_deeper.json
mkdir -p "$out"
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell cornell-box bunny living-room modern-hall sponza conference)
for sc in "${scenes[@]}"; do
  "$bin" --scene "$sc" --mode uniform --max-depth 5 --noise-estimate rotated-repeat --calibrate-noise off \
    --gradient-step 0 --sweep-depths 3 4 5 --sweep-bias-budget 1 16 64 256 \
    --sweep-bias-tolerance 0.01 0.02 0.04 0.06 0.08 0.1 0.12 0.16 0.24 0.32 0.48 0.64 1 1.5 2 3 --sweep-surface \
    --json "$out/deeper-$sc.json" 2>/dev/null | grep -E "^(grid|sweep|$sc)"
  python3 docs/studies/results.py add "$results" "deeper-$sc" "$out/deeper-$sc.json"
done
