#!/usr/bin/env bash
# Charts that follow surfaces and the element budget (issue 30; docs/radiosity.md section 2,
# "Measured: charts, clusters and the element budget"): on the built-in Cornell box and every shared scene, the lightmap atlas at 10,000 and
# 100,000 elements asked (charts, elements per chart, packing efficiency, stretch, elements
# made against asked: build/bin/lightmap_atlas), then the radiosity program at 100,000
# elements, ray casts, to 90% of the indirect power against the 64-path multi-bounce
# reference (rel_rms, black pixels, steps). Results into docs/results/radiosity_charts.json;
# the atlas pictures (Sponza and the conference room, 10,000 elements) into
# docs/figures/radiosity_atlas_sponza.png and radiosity_atlas_conference.png. The atlas
# reports its clusters of tiny charts (chart_clusters.hpp; issue 30, seventh session); with
# CLUSTER_RUNS=1 the conference room's solves are also run at 10,000 and 100,000 with the
# default (--clusters when-needed), at 10,000 with --clusters never
# and at 100,000 with --clusters always (the clusters' effect at one budget), 256 shooter
# groups as the headline runs (radiosity_groups.sh).
# Heavy scenes get --max-seconds 240 (a loaded machine). Minutes per scene on 2 shared cores.
# Usage: docs/studies/radiosity_charts.sh [SCENE ...]   (BOUNCE_BIN: default build/bin;
# ATLAS_ONLY=1 skips the solves)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}"
out=build/runs/radiosity_charts
results=docs/results/radiosity_charts.json
mkdir -p "$out" docs/figures
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell cornell-box modern-hall sponza bunny living-room conference)
for s in "${scenes[@]}"; do
  for n in 10000 100000; do
    "$bin/lightmap_atlas" --scene "$s" --elements $n --json "$out/atlas-$s-$n.json" > /dev/null
    python3 docs/studies/results.py add "$results" "atlas-$s-$n" "$out/atlas-$s-$n.json"
  done
  [[ -n "${ATLAS_ONLY:-}" ]] && continue
  limit=()
  case $s in living-room|conference|bunny|sponza|modern-hall) limit=(--max-seconds 240) ;; esac
  "$bin/radiosity" --scene "$s" --elements 100000 --visibility rays --converge 0.9 --reference-paths 64 \
    --curve-points 0 "${limit[@]}" --quiet --json "$out/radiosity-$s.json" --out "$out/radiosity-$s.png"
  python3 docs/studies/results.py add "$results" "radiosity-$s" "$out/radiosity-$s.json"
done
if [[ -n "${CLUSTER_RUNS:-}" ]]; then
  for run in "10000 when-needed" "10000 never" "100000 when-needed" "100000 always"; do
    set -- $run
    "$bin/radiosity" --scene conference --elements "$1" --clusters "$2" --shooter-groups 256 --visibility rays \
      --converge 0.9 --reference-paths 64 --curve-points 0 --max-seconds 240 --quiet --json "$out/radiosity-conference-$1-$2.json"
    python3 docs/studies/results.py add "$results" "radiosity-conference-$1-clusters-$2" "$out/radiosity-conference-$1-$2.json"
  done
fi
# The picture: Sponza's atlas at 10,000 elements, 2 pixels a texel.
if [[ -d "${BOUNCE_SCENES:-../shared/scenes}/sponza" ]]; then
  "$bin/lightmap_atlas" --scene sponza --elements 10000 --zoom 2 --png docs/figures/radiosity_atlas_sponza.png > /dev/null
fi
if [[ -d "${BOUNCE_SCENES:-../shared/scenes}/conference" ]]; then
  "$bin/lightmap_atlas" --scene conference --elements 10000 --zoom 2 --png docs/figures/radiosity_atlas_conference.png > /dev/null
fi
