#!/usr/bin/env bash
# The plane's turn about the record's normal (plane_camera::turn_deg, hashed_turn): how the
# four weightings' errors move with it, on the first 2000 points of the study (ray-cast,
# 64^2, 126 degrees), for Sponza and the Cornell box. Each run goes into the study's results
# file, docs/results/hemisphere_turn.json, tabulated by hemisphere_turn_table.py. A few
# minutes on 2 cores.
# Usage: docs/studies/hemisphere_turn.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
bin=build/bin/hemisphere_study
scenes="${BOUNCE_SCENES:-../shared/scenes}"
out=build/runs/hemisphere-turn
results=docs/results/hemisphere_turn.json
mkdir -p "$out"
for scene in sponza cornell; do
  arg=$scene
  if [[ $scene == sponza ]]; then arg="$scenes/sponza/scene.json"; fi
  for turn in 0 7.5 15 22.5 30 37.5 45 52.5 60 67.5 75 82.5; do
    "$bin" --scene "$arg" --points 2000 --no-raster --plane-turn "$turn" --json "$out/$scene-turn$turn.json" | tail -1
    python3 docs/studies/results.py add "$results" "$scene-turn$turn" "$out/$scene-turn$turn.json"
  done
  "$bin" --scene "$arg" --points 2000 --no-raster --hashed-turn --json "$out/$scene-hashed.json" | tail -1
  python3 docs/studies/results.py add "$results" "$scene-hashed" "$out/$scene-hashed.json"
done
/usr/bin/python3 docs/studies/hemisphere_turn_table.py "$results"
