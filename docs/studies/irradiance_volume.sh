#!/usr/bin/env bash
# The figures of docs/sh-and-irradiance-volumes.md, irradiance-volume sections: uniform grids
# and adaptive octrees (build/bin/irradiance_volume) lighting a sphere moving through the
# Cornell box and Sponza, every lookup (trilinear, weighted, weighted with gradients) on
# each bake, error against the reference integrator's one-bounce indirect irradiance on the
# sphere. Every run goes into docs/results/irradiance_volume.json; the strip pictures into
# docs/figures/irradiance_volume_*.png. Sponza needs BOUNCE_SCENES (or ../shared/scenes).
# About 40 minutes on 2 shared cores (the adaptive Sponza bake dominates).
# Usage: docs/studies/irradiance_volume.sh [cornell|sponza|adaptive|sweep|sh]   (BOUNCE_BIN: default build/bin; BOUNCE_RUNS: default build/runs)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}/irradiance_volume"
out="${BOUNCE_RUNS:-build/runs}/irradiance_volume"
results=docs/results/irradiance_volume.json
figures=docs/figures
mkdir -p "$out" "$figures"
common=(--rays 512 --ref-samples 1024 --frames 8 --sphere-points 128 --gradient-step 0.5)
run() {  # run NAME ARGS...: one run, its report added to the results file
  local name=$1; shift
  "$bin" --json "$out/$name.json" "$@" 2>/dev/null | tail -4
  python3 docs/studies/results.py add "$results" "$name" "$out/$name.json"
}
part=${1:-all}

if [[ $part == all || $part == cornell ]]; then
  # The built-in box (0.55 m): uniform grids of depth 3 and 4 against an adaptive octree of
  # depth 4 with the default heuristics.
  run cornell-uniform-3 --scene cornell --mode uniform --max-depth 3 "${common[@]}"
  run cornell-uniform-4 --scene cornell --mode uniform --max-depth 4 "${common[@]}" --out "$figures/irradiance_volume_cornell.png"
  run cornell-adaptive-4 --scene cornell --mode adaptive --max-depth 4 "${common[@]}"
  run cornell-adaptive-4-b1 --scene cornell --mode adaptive --max-depth 4 --b 1 "${common[@]}"
fi

if [[ $part == all || $part == sponza ]]; then
  # Sponza (sphere through the atrium at 20% of the height): uniform grids of depth 3, 4 and
  # 5; adaptive octrees of depth 4 and 5 with the default heuristics, of depth 5 with the
  # harmonic-mean-distance heuristic alone (ratio 0.5), and of depth 5 with the geometry
  # heuristic off, distance ratio 0.5, neighbour change 0.5 and culling at 20%, and of depth
  # 5 on the lighting heuristics alone (neighbour change 0.25, gradient 0.3, culling 5%).
  run sponza-uniform-3 --scene sponza --mode uniform --max-depth 3 "${common[@]}"
  run sponza-uniform-4 --scene sponza --mode uniform --max-depth 4 "${common[@]}"
  run sponza-uniform-5 --scene sponza --mode uniform --max-depth 5 "${common[@]}"
  run sponza-adaptive-4 --scene sponza --mode adaptive --max-depth 4 "${common[@]}"
  run sponza-adaptive-5 --scene sponza --mode adaptive --max-depth 5 "${common[@]}"
  run sponza-adaptive-5-distance --scene sponza --mode adaptive --max-depth 5 --geometry-triangles 0 \
    --neighbour-change 0 --gradient-ratio 0 --distance-ratio 0.5 --cull 0.05 "${common[@]}"
  run sponza-adaptive-5-cull --scene sponza --mode adaptive --max-depth 5 --cull 0.2 --neighbour-change 0.5 \
    --distance-ratio 0.5 --geometry-triangles 0 "${common[@]}"
  run sponza-adaptive-5-loose --scene sponza --mode adaptive --max-depth 5 --distance-ratio 0.25 \
    --neighbour-change 0.6 --gradient-ratio 0.6 --geometry-triangles 0 --cull 0.1 "${common[@]}"
  run sponza-adaptive-5-lighting --scene sponza --mode adaptive --max-depth 5 --distance-ratio 0 \
    --geometry-triangles 0 "${common[@]}" --out "$figures/irradiance_volume_sponza.png"
fi

if [[ $part == all || $part == adaptive ]]; then
  # Issue 31, the headline: every shared scene and the built-in box with the program's
  # defaults (depth 4, 512 rays, trilinear), the uniform grid against the adaptive octree
  # merged from the finest grid (the default) and split from the root (--refine split);
  # then the settings tried on the three scenes where adaptive lost most.
  for sc in cornell cornell-box bunny living-room modern-hall sponza conference; do
    run "issue31-uniform-$sc" --scene "$sc" --mode uniform
    run "issue31-merge-$sc" --scene "$sc"
    run "issue31-split-$sc" --scene "$sc" --refine split
  done
  for sc in cornell modern-hall conference; do
    run "issue31-merge-k3-$sc" --scene "$sc" --noise-sigmas 3
    run "issue31-merge-k2-$sc" --scene "$sc" --noise-sigmas 2
    run "issue31-merge-k0-$sc" --scene "$sc" --noise-sigmas 0
    run "issue31-merge-bias1-$sc" --scene "$sc" --bias-budget 1
    run "issue31-merge-bias1-norefit-$sc" --scene "$sc" --bias-budget 1 --refit off
  done
  for sc in modern-hall conference; do
    run "issue31-merge-k2-norefit-$sc" --scene "$sc" --noise-sigmas 2 --refit off
    run "issue31-merge-k2-noconforming-$sc" --scene "$sc" --noise-sigmas 2 --conforming off
  done
fi

if [[ $part == all || $part == sweep ]]; then
  # Issue 31, third session: per scene, the uniform grid (program defaults otherwise) and
  # merged octrees built from its very probes (--sweep-bias-budget, --sweep-noise-sigmas:
  # every budget at every slack), into docs/results/irradiance_volume_sweep.json, tabulated
  # by `irradiance_volume_table.py --sweep` (the share of the grid's probes at its error).
  # The probes' noise: from the even and odd rays of one Fibonacci set (calibrated, as the
  # second session's bias budget), from two independently turned halves, or from a repeat
  # of the set turned at random (both measured, not calibrated). First budgets 0.25 .. 4 at
  # the default slack (4 standard deviations), "sweep-*" (the first runs spelled
  # --noise-estimate as --halves even-odd|independent); then budgets 0.25, 1, 4 at slacks
  # 0 .. 8, "grid-*". About 2 minutes a run on 2 shared cores.
  for sc in cornell cornell-box bunny living-room modern-hall sponza conference; do
    for noise in even-odd independent; do
      calibrate=off
      [[ $noise == even-odd ]] && calibrate=on
      "$bin" --scene "$sc" --mode uniform --noise-estimate "${noise/#independent/independent-halves}" \
        --calibrate-noise "$calibrate" --sweep-bias-budget 0.25 0.5 1 2 4 --json "$out/sweep-$noise-$sc.json" 2>/dev/null | tail -7
      python3 docs/studies/results.py add docs/results/irradiance_volume_sweep.json "sweep-$noise-$sc" "$out/sweep-$noise-$sc.json"
    done
  done
  for noise in rotated-repeat even-odd; do
    for sc in cornell cornell-box bunny living-room modern-hall sponza conference; do
      calibrate=off
      [[ $noise == even-odd ]] && calibrate=on
      "$bin" --scene "$sc" --mode uniform --noise-estimate "$noise" --calibrate-noise "$calibrate" \
        --sweep-bias-budget 0.25 1 4 --sweep-noise-sigmas 0 1 2 4 8 --json "$out/grid-$noise-$sc.json" 2>/dev/null | tail -18
      python3 docs/studies/results.py add docs/results/irradiance_volume_sweep.json "grid-$noise-$sc" "$out/grid-$noise-$sc.json"
    done
  done
fi

if [[ $part == all || $part == sh ]]; then
  # SH projection and irradiance errors per order of environments captured along the paths.
  "$bin" --scene cornell --sh-study --json "$out/sh-cornell.json"
  python3 docs/studies/results.py add "$results" sh-cornell "$out/sh-cornell.json"
  "$bin" --scene sponza --sh-study --json "$out/sh-sponza.json"
  python3 docs/studies/results.py add "$results" sh-sponza "$out/sh-sponza.json"
fi
