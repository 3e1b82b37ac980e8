#!/usr/bin/env bash
# Grouped shooters (issue 30, "shooting that scales"; docs/radiosity.md section 7, "Grouped
# shooters"): on the built-in Cornell box and every shared scene, the radiosity program at
# 100,000 elements, ray casts, to 90% of the indirect power against the 64-path multi-bounce
# reference (the shared cache), one shooter per block (--shooter-groups 0, "blocks") and
# grouped (--shooter-groups G, "groups"); then Sponza from 10,000 to 400,000 elements, both
# ways, for the scaling plot (docs/studies/radiosity_groups_figures.py). Results into
# docs/results/radiosity_groups.json. Every solve is cut at --max-seconds 240.
# Usage: docs/studies/radiosity_groups.sh [main|scaling] [SCENE ...]
#   (BOUNCE_BIN: default build/bin; SHOOTER_GROUPS: default 256; ONLY=groups or ONLY=blocks: one of the two;
#   SCALING: the element counts of the scaling runs)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}"
out=build/runs/radiosity_groups
results=docs/results/radiosity_groups.json
groups="${SHOOTER_GROUPS:-256}"
mkdir -p "$out"
what=${1:-main}; shift || true
run() {  # run NAME ARGS...
  local name=$1; shift
  "$bin/radiosity" --visibility rays --converge 0.9 --reference-paths 64 --curve-points 0 --max-seconds 240 \
    --quiet --json "$out/$name.json" "$@" | tail -1
  python3 docs/studies/results.py add "$results" "$name" "$out/$name.json"
}
if [[ $what == main ]]; then
  scenes=("$@")
  [[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell cornell-box modern-hall sponza bunny living-room conference)
  for s in "${scenes[@]}"; do
    [[ ${ONLY:-groups} == blocks ]] || run "groups-$s" --scene "$s" --elements 100000 --shooter-groups "$groups"
    [[ ${ONLY:-blocks} == groups ]] || run "blocks-$s" --scene "$s" --elements 100000 --shooter-groups 0
  done
else
  for n in ${SCALING:-10000 30000 100000 200000 400000}; do
    [[ ${ONLY:-groups} == blocks ]] || run "scaling-groups-sponza-$n" --scene sponza --elements $n --shooter-groups "$groups" --reference off
    [[ ${ONLY:-blocks} == groups ]] || run "scaling-blocks-sponza-$n" --scene sponza --elements $n --shooter-groups 0 --reference off
  done
fi
