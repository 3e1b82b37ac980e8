#!/usr/bin/env bash
# The "Visibility-aware probes" figures of docs/sh-and-irradiance-volumes.md (issue 31):
# every shared scene and the built-in Cornell box, the program's default volume (adaptive,
# depth 4, 512 rays per probe) and the uniform grid of depth 4, looked up trilinearly at the
# camera's 128 x 128 G-buffer without and with visibility (DDGI distance moments, 16 x 16
# texels from 1024 rays per probe), against the one-bounce reference (1024 samples per
# pixel in two halves), over every covered pixel and over the pixels within one finest cell
# of another surface. Runs into docs/results/irradiance_volume_surface.json; the pictures
# (reference | no visibility | Chebyshev) into docs/figures/irradiance_volume_surface_*.png.
# About 1-3 minutes a scene on 2 shared cores.
# Usage: docs/studies/irradiance_volume_surface.sh [SCENE ...]   (BOUNCE_BIN: default build/bin)
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${BOUNCE_BIN:-build/bin}/irradiance_volume"
out=build/runs/irradiance_volume_surface
results=docs/results/irradiance_volume_surface.json
figures=docs/figures
mkdir -p "$out" "$figures"
scenes=("$@")
[[ ${#scenes[@]} -gt 0 ]] || scenes=(cornell cornell-box bunny living-room modern-hall sponza conference)
for s in "${scenes[@]}"; do
  for mode in adaptive uniform; do
    name=$s-$mode-4
    pic=()
    [[ $mode == adaptive ]] && pic=(--out "$figures/irradiance_volume_surface_$s.png")
    "$bin" --scene "$s" --mode "$mode" --max-depth 4 --surface --json "$out/$name.json" "${pic[@]}" 2>/dev/null | tail -3
    python3 docs/studies/results.py add "$results" "$name" "$out/$name.json"
  done
done
