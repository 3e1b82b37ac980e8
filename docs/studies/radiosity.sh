#!/usr/bin/env bash
# The figures of docs/radiosity.md: progressive radiosity (build/bin/radiosity) on the Cornell
# box against the multi-bounce reference (128 x 128, 4096 paths per pixel, cached under
# build/cache after the first run, a few minutes) and on Sponza; every run goes into
# docs/results/radiosity.json, the tables and the plot come from docs/studies/radiosity_figures.py,
# and the pictures are written to docs/figures/radiosity_*.png. About 10 minutes on 2 cores.
# Usage: docs/studies/radiosity.sh   (BOUNCE_BIN: the folder of the programs, default build/bin)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}/radiosity"
out=build/runs/radiosity
results=docs/results/radiosity.json
figures=docs/figures
mkdir -p "$out" "$figures"
ref=(--width 128 --height 128 --reference-paths 4096)
add() { python3 docs/studies/results.py add "$results" "$1" "$out/$1.json"; }
run() {  # run NAME ARGS...: one run, its report added to the results file
  local name=$1; shift
  "$bin" --quiet --json "$out/$name.json" "$@" | tail -2
  add "$name"
}

# 1. The issue's target: about 10,000 elements to 90% on the CPU backend (medians of 5 solves),
#    with each visibility method; the views (EXR) are the baselines of section 2.
run cornell-rays --visibility rays --elements 10000 --converge 0.9 --repeat 5 "${ref[@]}" \
  --out "$out/cornell-rays.exr" --reference-out "$figures/radiosity_reference.png"
run cornell-stereo-128 --visibility stereo --resolution 128 --elements 10000 --converge 0.9 --repeat 5 "${ref[@]}" \
  --versus "$out/cornell-rays.exr"
run cornell-hemicube-128 --visibility hemicube --resolution 128 --elements 10000 --converge 0.9 --repeat 5 "${ref[@]}" \
  --versus "$out/cornell-rays.exr"
# The GL backend (gl::progressive_radiosity; llvmpipe on this machine) on the same run.
run cornell-gl-stereo-128 --backend gl --visibility stereo --resolution 128 --elements 10000 --converge 0.9 --repeat 3 \
  "${ref[@]}" --versus "$out/cornell-rays.exr"

# 2. Item buffers against ray casts (same elements, same convergence): resolution and the
#    stereographic tessellation's tolerance.
for res in 256 512 1024; do
  run "cornell-stereo-$res" --visibility stereo --resolution "$res" --elements 10000 --converge 0.9 "${ref[@]}" \
    --versus "$out/cornell-rays.exr"
done
for tol in 2 1 0.05; do
  run "cornell-stereo-256-tol$tol" --visibility stereo --resolution 256 --tolerance-px "$tol" --elements 10000 \
    --converge 0.9 "${ref[@]}" --versus "$out/cornell-rays.exr"
done
for res in 64 256 512; do
  run "cornell-hemicube-$res" --visibility hemicube --resolution "$res" --elements 10000 --converge 0.9 "${ref[@]}" \
    --versus "$out/cornell-rays.exr"
done

# 3. Adaptive subdivision against uniform elements, both with ray-cast visibility (so only the
#    elements differ) and solved to 99%.
for block in 8 4; do
  for n in 5000 10000 20000 40000; do
    run "cornell-uniform-b$block-$n" --visibility rays --block "$block" --elements "$n" --converge 0.99 "${ref[@]}" --curve-points 0
  done
  run "cornell-adaptive-b$block-2500" --visibility rays --block "$block" --elements 2500 --adaptive on --converge 0.99 \
    "${ref[@]}" --curve-points 0
  run "cornell-adaptive-b$block-2500-l3" --visibility rays --block "$block" --elements 2500 --adaptive on --max-level 3 \
    --converge 0.99 "${ref[@]}" --curve-points 0
done

# 4. The convergence curve: unshot fraction and error against time, to 99.9%.
run cornell-curve --visibility stereo --elements 10000 --converge 0.999 "${ref[@]}" --curve-points 30

# 5. Sponza (66,454 triangles, scene.json's sun and point light) to 95%: time per iteration
#    and memory against the element count. No reference (the error figures are the box's).
for n in 25000 50000 100000 200000 400000; do
  run "sponza-rays-$n" --scene sponza --visibility rays --elements "$n" --converge 0.95 --max-seconds 300 \
    --reference off --curve-points 0
done
run sponza-hemicube-100000 --scene sponza --visibility hemicube --elements 100000 --converge 0.95 --max-seconds 300 \
  --reference off --curve-points 0

# Pictures (PNG, 256 x 256, no reference needed): the converged solution three ways.
"$bin" --quiet --visibility rays --elements 10000 --converge 0.999 --reference off --out "$figures/radiosity_rays.png"
"$bin" --quiet --visibility stereo --elements 10000 --converge 0.9 --reference off --out "$figures/radiosity_stereo_90.png"
"$bin" --quiet --visibility rays --elements 2500 --adaptive on --converge 0.999 --reference off \
  --out "$figures/radiosity_adaptive_view.png"
"$bin" --quiet --scene sponza --visibility rays --elements 100000 --converge 0.95 --reference off \
  --out "$figures/radiosity_sponza.png"
/usr/bin/python3 docs/studies/radiosity_figures.py "$results"
