#!/usr/bin/env bash
# Runs the measurements behind docs/rsm-sii-interleaved.md (sections 11-13): Hahn 2012's grid
# on the Cornell box in one process (so every ratio comes from one run), the pictures of each
# technique on the Cornell box and Sponza, and adds each run's report (with its commit and
# machine) to the study's one results file, docs/results/rsm_sii.json; then redraws the
# figures and tables (docs/studies/rsm_sii_figures.py).
# Usage: docs/studies/rsm_sii.sh [study|pictures|visibility|visibility-edges|all]  (BIN=DIR/bin, RUNS=DIR for another build folder)
# Takes about 30 minutes on 2 shared cores; the references (4096 rays per pixel, with and
# without indirect visibility) are computed once and cached in build/cache.
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BIN:-build/bin}/rsm_sii"
which="${1:-all}"
results=docs/results/rsm_sii.json
runs="${RUNS:-build/runs}"
mkdir -p "$runs" docs/figures

add() {  # add NAME: the report build/runs/NAME.json into the results file
  python3 docs/studies/results.py add "$results" "$1" "$runs/$1.json"
}

if [[ "$which" == study || "$which" == all ]]; then
  "$bin" --study --scene cornell --width 512 --height 384 --ref-spp 4096 --repeat 3 --json "$runs/cornell-study.json"
  add cornell-study
fi

if [[ "$which" == pictures || "$which" == all ]]; then
  # Each technique's indirect light beside the unoccluded reference (one exposure), 1024
  # VPLs (disc samples per map for the gather) at 4x4, energy-correct, blurred.
  # Sponza's references cross ten surfaces a ray: smaller and at 512 rays per pixel.
  for spec in "cornell 320 240 1024" "sponza 256 192 512"; do
    read -r scene width height spp <<< "$spec"
    for technique in rsm sii; do
      name="$scene-$technique-1024-4x4"
      "$bin" --scene "$scene" --technique "$technique" --vpls 1024 --pattern 4x4 --width "$width" --height "$height" \
        --ref-spp "$spp" --json "$runs/$name.json" --indirect-out "docs/figures/rsm_sii_${scene}_${technique}.png"
      add "$name"
    done
  done
fi

if [[ "$which" == visibility || "$which" == all ]]; then
  # The leak and its fix (issue 29): SII 1024 VPLs at 4x4 without visibility, with occlusion
  # rays, and the one-bounce reference with visibility, one exposure, on the Cornell box and
  # on the conference room (its chairs and tables hide most of the lit floor from each other).
  for spec in "cornell 320 240 1024" "conference 256 192 1024"; do
    read -r scene width height spp <<< "$spec"
    name="$scene-sii-1024-4x4-rays"
    "$bin" --scene "$scene" --technique sii --vpls 1024 --pattern 4x4 --visibility rays --width "$width" \
      --height "$height" --ref-spp "$spp" --json "$runs/$name.json" --indirect-out "docs/figures/rsm_sii_${scene}_visibility.png"
    add "$name"
  done
fi

if [[ "$which" == visibility-edges || "$which" == all ]]; then
  # Issue 29, fourth session: SII 4x4 with the blur at 256, 1024 and 4096 VPLs, without visibility
  # and with rays, the blur stopped by geometry alone and by its visibility edges too, on every
  # scene, against the benchmark's references in halves (rsm_visibility_study; about 10 minutes
  # a scene on 2 shared cores once the references are cached).
  study_bin="${BIN:-build/bin}/rsm_visibility_study"
  for scene in cornell cornell-box bunny conference living-room modern-hall sponza; do
    for vpls in 256 1024 4096; do
      name="visibility-edges-$scene-$vpls"
      "$study_bin" --scenes "$scene" --vpls "$vpls" --configs 4x4-blur,4x4-blur-geometry-edges --json "$runs/$name.json"
      add "$name"
    done
  done
fi

/usr/bin/python3 docs/studies/rsm_sii_figures.py "$results"
