#!/usr/bin/env bash
# Issue 19's speed-against-error study: per scene, the irradiance cache under each radius
# policy and with fixed or adaptive rays per record over an a sweep, and brute-force Monte
# Carlo's spp sweep, all against one reference per scene (computed in two halves, so every
# error is also given with the reference's own noise taken out). Each run's report goes into
# the study's one results file, docs/results/ic_policies.json; ic_policies_figures.py draws
# docs/figures/ic-policies-<scene>.png from it.
#
# Usage: docs/studies/ic_policies.sh [cornell|sponza|bunny|all|walkthrough] (SIZE=512 by default;
# the walkthrough is not part of all).
# At 512x512 on 2 cores: minutes for the Cornell box and the bunny; Sponza about 15 minutes
# for its reference and 20-40 for its runs (adaptive records at a = 0.2 took over 7 minutes).
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${IC_SPLATTING:-build/bin/ic_splatting}"  # another build of the program may be named
results=docs/results/ic_policies.json
size="${SIZE:-512}"
which="${1:-all}"
mkdir -p build/runs docs/figures

source docs/studies/run.sh  # run NAME ARGS...: one measured run, added to the results file

scene() {  # scene TAG SCENE REFSPP MC_A A...: each configuration over the a values; Monte Carlo's
  # spp sweep with the split sphere's 1024-ray run at MC_A (every run's equal-error time is read
  # off that one sweep by ic_policies_figures.py)
  local tag=$1 name=$2 spp=$3 mc_a=$4; shift 4
  local common=(--scene "$name" --width "$size" --height "$size" --ref-spp "$spp")
  for a in "$@"; do
    local mc=(); [[ $a == "$mc_a" ]] && mc=(--mc-compare)
    run "$tag-split-r1024-a$a" "${common[@]}" --a "$a" --radius split-sphere --no-adaptive-rays --record-samples 1024 "${mc[@]}"
    run "$tag-split-r2048-a$a" "${common[@]}" --a "$a" --radius split-sphere --no-adaptive-rays --record-samples 2048
    run "$tag-hessian-r1024-a$a" "${common[@]}" --a "$a" --radius hessian --no-adaptive-rays --record-samples 1024
    run "$tag-split-adaptive-a$a" "${common[@]}" --a "$a" --radius split-sphere --adaptive-rays --record-samples 2048
  done
}

walkthrough() {  # the 30-frame Sponza walkthrough: one cache grown along the camera path, Monte Carlo at
  # each measured frame's error (every 10th frame; 512-spp references in halves, debiased errors)
  run "sponza-$size-walkthrough30" --scene sponza --width "$size" --height "$size" --a 0.15 --walkthrough 30 \
    --ref-spp 512 --walkthrough-mc-stride 10
}

case "$which" in
  cornell|all) scene "cornell-$size" cornell 2048 0.2 0.4 0.2 ;;&
  sponza|all) scene "sponza-$size" sponza 4096 0.2 0.4 0.2 ;;&
  bunny|all) scene "bunny-$size" bunny 2048 0.2 0.4 0.2 ;;
  walkthrough) walkthrough ;;
  cornell|sponza) ;;
  *) echo "usage: $0 [cornell|sponza|bunny|all|walkthrough]" >&2; exit 2 ;;
esac
/usr/bin/python3 docs/studies/ic_policies_figures.py "$results" docs/figures
