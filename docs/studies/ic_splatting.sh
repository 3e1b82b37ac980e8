#!/usr/bin/env bash
# Runs the irradiance-splatting measurements behind docs/irradiance-splatting.md and
# docs/report.md, adding each run's report (with its commit and machine) to the study's one
# results file, docs/results/ic_splatting.json (committed), then regenerates the report. Usage: docs/studies/ic_splatting.sh [cornell|sponza|all]
# Takes minutes on 2 cores (Sponza's reference is computed once and cached).
set -euo pipefail
cd "$(dirname "$0")/../.."
bin=build/bin/ic_splatting
scenes="${BOUNCE_SCENES:-../shared/scenes}"
which="${1:-all}"
results=docs/results/ic_splatting.json
mkdir -p build/runs docs/figures

source docs/studies/run.sh  # run NAME ARGS...: one measured run, added to the results file

rays() {  # rays TAG ARGS...: gradients on/off and Ward's weight with 4096 rays per record (less record noise)
  local tag=$1; shift
  run "$tag-r4096" "$@" --a 0.15 --weight ward-smooth --record-samples 4096
  run "$tag-r4096-nograd" "$@" --a 0.15 --weight ward-smooth --record-samples 4096 --gradients off
  run "$tag-ward-r4096" "$@" --a 0.15 --weight ward --record-samples 4096  # Ward's weight, less record noise
}

interp() {  # interp TAG ARGS...: splat against octree (scalar, four-lane) on one saved cache, medians of 15 renders
  local tag=$1; shift
  local cache="build/$tag-a0.15.cache"
  "$bin" "$@" --a 0.15 --weight ward-smooth --cache-out "$cache" > /dev/null
  run "$tag-interp-splat" "$@" --a 0.15 --weight ward-smooth --cache-in "$cache" --repeat 15
  run "$tag-interp-octree" "$@" --a 0.15 --weight ward-smooth --cache-in "$cache" --repeat 15 --interp octree
  run "$tag-interp-octree-lanes" "$@" --a 0.15 --weight ward-smooth --cache-in "$cache" --repeat 15 --interp octree-lanes
}

weights() {  # weights TAG ARGS...: every weighting policy at a = 0.15 and 0.4, run back to back (one machine's times)
  local tag=$1; shift
  for a in 0.15 0.4; do
    for w in ward ward-smooth ward-gpu ward-gpu-shader tabellion; do
      run "$tag-w-$w-a$a" "$@" --a "$a" --weight "$w"
    done
  done
  for a in 0.3 0.2 0.1; do run "$tag-w-tabellion-a$a" "$@" --a "$a" --weight tabellion; done  # its whole sweep
  run "$tag-tabellion-mc" "$@" --a 0.4 --weight tabellion --mc-compare  # its best error per record, against Monte Carlo
  run "$tag-tabellion-nograd" "$@" --a 0.15 --weight tabellion --gradients off  # beside $tag-w-tabellion-a0.15
}

seams() {  # seams TAG ARGS...: Ward's and the smoothed weight over the whole a sweep, back to back on one machine
  local tag=$1; shift
  for a in 0.4 0.3 0.2 0.15 0.1; do
    for w in ward ward-smooth; do run "$tag-seams-$w-a$a" "$@" --a "$a" --weight "$w"; done
  done
}

study() {  # study TAG SCENE REFSPP CLAMP(on|off) FILL(progressive hole filling's a factor) RAYS(per record)
  local tag=$1 scene=$2 spp=$3 clamp=$4 fill=$5 rays=$6
  # ic_splatting clamps by default; the study says which setting each run has.
  local flags=(--no-neighbour-clamp) other=clamp  # other: the cross-check run with the other clamping setting
  if [[ $clamp == on ]]; then flags=(--neighbour-clamp); other=noclamp; fi
  local base=(--scene "$scene" --width 512 --height 512 --ref-spp "$spp" "${flags[@]}")
  local common=("${base[@]}" --record-samples "$rays")
  for a in 0.4 0.3 0.2 0.15 0.1; do
    run "$tag-a$a" "${common[@]}" --a "$a" --weight ward-smooth
    # The same sweep with half the rays, where the study takes more: the cheaper records
    # win at large a (interpolation dominates the error), the better ones at small a.
    if [[ $rays != 1024 ]]; then run "$tag-r1024-a$a" "${base[@]}" --record-samples 1024 --a "$a" --weight ward-smooth; fi
  done
  run "$tag-nograd" "${common[@]}" --a 0.15 --weight ward-smooth --gradients off
  # The gradients' gain on the same records with the other number of rays per record.
  if [[ $rays == 1024 ]]; then
    run "$tag-r2048" "${base[@]}" --record-samples 2048 --a 0.15 --weight ward-smooth
    run "$tag-r2048-nograd" "${base[@]}" --record-samples 2048 --a 0.15 --weight ward-smooth --gradients off
  else
    run "$tag-r1024-nograd" "${base[@]}" --record-samples 1024 --a 0.15 --weight ward-smooth --gradients off
  fi
  # No gradient anywhere (Ward 1988: nor the radius limit), and the same records extrapolated.
  run "$tag-nolimit-nograd" "${common[@]}" --a 0.15 --weight ward-smooth --gradients off --no-gradient-limit
  run "$tag-nolimit" "${common[@]}" --a 0.15 --weight ward-smooth --no-gradient-limit
  run "$tag-front" "${common[@]}" --a 0.15 --weight ward-smooth --front-tolerance 0.1  # Ward's in-front test
  run "$tag-ward" "${common[@]}" --a 0.15 --weight ward
  run "$tag-smooth" "${common[@]}" --a 0.15 --weight ward-smooth
  run "$tag-ward-a0.4" "${common[@]}" --a 0.4 --weight ward  # beside $tag-a0.4: where seams show
  rays "$tag" "${base[@]}"
  weights "$tag" "${common[@]}"
  seams "$tag" "${common[@]}"
  # Nearly noise-free records: does the smoothed weight's excess over Ward's at a = 0.15 come
  # from record noise? Sponza's at 256x256 (at 512x512 a run would take half an hour), against
  # a 16384-spp reference of that size, with 1024 rays beside them.
  if [[ $tag == cornell ]]; then
    run "$tag-r16384" "${base[@]}" --a 0.15 --weight ward-smooth --record-samples 16384
    run "$tag-ward-r16384" "${base[@]}" --a 0.15 --weight ward --record-samples 16384
  else
    local small=(--scene "$scene" --width 256 --height 256 --ref-spp 16384 "${flags[@]}" --a 0.15)
    for r in 1024 16384; do
      run "$tag-256-r$r" "${small[@]}" --weight ward-smooth --record-samples "$r"
      run "$tag-ward-256-r$r" "${small[@]}" --weight ward --record-samples "$r"
    done
    # and the gradients' gain on those accurate records
    run "$tag-256-r16384-nograd" "${small[@]}" --weight ward-smooth --record-samples 16384 --gradients off
  fi
  if [[ $clamp == on ]]; then
    run "$tag-$other" --scene "$scene" --width 512 --height 512 --ref-spp "$spp" --record-samples "$rays" --a 0.15 \
        --weight ward-smooth --no-neighbour-clamp
  else
    run "$tag-$other" "${common[@]}" --a 0.15 --weight ward-smooth --neighbour-clamp
  fi
  # Pictures (small, to stay under 300 KB): indirect light beside the reference's, at a
  # large a where Ward's circular seams show, and the final image.
  for w in ward ward-smooth; do
    "$bin" --scene "$scene" --width 256 --height 256 --ref-spp 1024 --a 0.4 --weight "$w" "${flags[@]}" --record-samples "$rays" \
        --indirect-out "docs/figures/$tag-$w-a0.4.png" --out "docs/figures/$tag-$w-final.png"
  done
  run "$tag-octree" "${common[@]}" --a 0.15 --weight ward-smooth --interp octree
  interp "$tag" "${common[@]}"
  [[ $tag == cornell ]] && run "$tag-raster" "${common[@]}" --a 0.15 --weight ward-smooth --sampler raster
  # Fall-off stretching with the kappa hemisphere_study measures for the box (0.881).
  [[ $tag == cornell ]] && run "$tag-raster-falloff" "${common[@]}" --a 0.15 --weight ward-smooth --sampler raster \
      --falloff-kappa 0.881
  # The planes turned about their normals (docs/hemisphere-sampling.md, "The plane's turn").
  [[ $tag == cornell ]] && run "$tag-raster-hashed" "${common[@]}" --a 0.15 --weight ward-smooth --sampler raster --hashed-turn
  [[ $tag == cornell ]] && run "$tag-raster-turn30" "${common[@]}" --a 0.15 --weight ward-smooth --sampler raster --plane-turn 30
  # Sponza's raster records at 256x256 and a = 0.3 (ten minutes a run on llvmpipe).
  if [[ $tag == sponza ]]; then
    local small_raster=(--scene "$scene" --width 256 --height 256 --ref-spp 16384 "${flags[@]}" --a 0.3 --weight ward-smooth --sampler raster)
    run "$tag-256-embree-a0.3" --scene "$scene" --width 256 --height 256 --ref-spp 16384 "${flags[@]}" --a 0.3 --weight ward-smooth
    run "$tag-256-raster" "${small_raster[@]}"
    run "$tag-256-raster-turn30" "${small_raster[@]}" --plane-turn 30
    # Where the raster records' error sits (128x128, against the same cached reference).
    local tiny=(--scene "$scene" --width 128 --height 128 --ref-spp 1024 "${flags[@]}" --a 0.3 --weight ward-smooth)
    run "$tag-128-embree-a0.3" "${tiny[@]}" --indirect-exr build/sponza-128-embree.exr
    run "$tag-128-raster-a0.3" "${tiny[@]}" --sampler raster --indirect-exr build/sponza-128-raster.exr
    for r in 4096 8192; do  # the renderer's shadow maps are 2048^2 unless told
      run "$tag-128-raster-shadow$r-a0.3" "${tiny[@]}" --sampler raster --shadow-resolution "$r"
    done
    run "$tag-128-raster-shadow8192-turn30-a0.3" "${tiny[@]}" --sampler raster --shadow-resolution 8192 --plane-turn 30
    build/bin/reference --scene "$scene" --width 128 --height 128 --spp 1024 --out build/sponza-128-reference.exr --quiet
    /usr/bin/python3 docs/studies/error_concentration.py build/sponza-128-reference.indirect.exr \
        build/sponza-128-raster.exr build/sponza-128-embree.exr
  fi
  run "$tag-gl" "${common[@]}" --a 0.15 --weight ward-smooth --interp splat-gl
  run "$tag-mc" "${common[@]}" --a 0.15 --weight ward-smooth --mc-compare
  # Every frame of the camera path needs its own reference: smaller images, fewer samples.
  run "$tag-progressive" --scene "$scene" --width 256 --height 256 --ref-spp 256 --a 0.15 --weight ward-smooth \
      "${flags[@]}" --record-samples "$rays" --progressive 400 --frames 20 --fill-holes "$fill"
}

# Neighbour clamping: off in the Cornell box, where it doubles the records for no gain; on
# in Sponza, where records with R ~ 1 otherwise hide one-pixel strips of bright indirect
# light found by a record with R ~ 0.03 (docs/irradiance-splatting.md). Progressive hole
# filling: Sponza's zones are a few pixels wide, so its fallback splat needs wider ones.
# References: 16384 spp for the Cornell box and 8192 for Sponza, so that their own noise
# (about 0.0035 and 0.013) stays below the cache's error and Monte Carlo can be swept to
# half of them. Rays per record: with 1024 the Cornell box's error stops falling below
# a = 0.2 (record noise), so it takes 2048 (and shows the 1024 sweep beside it); in Sponza
# 2048 rays change the gradients' gain little (-5% against -2%) for twice the time, so it
# keeps 1024.
[[ $which == cornell || $which == all ]] && study cornell cornell 16384 off 4 2048
[[ $which == sponza || $which == all ]] && study sponza "$scenes/sponza/scene.json" 8192 on 16 1024
/usr/bin/python3 docs/make_report.py  # Debian python3 with python3-matplotlib
