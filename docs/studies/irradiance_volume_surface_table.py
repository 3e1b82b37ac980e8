#!/usr/bin/env python3
"""The table of docs/sh-and-irradiance-volumes.md, "Visibility-aware probes", from
docs/results/irradiance_volume_surface.json (docs/studies/irradiance_volume_surface.sh):
per scene and volume, rel_rms (debiased in brackets) of the trilinear lookup at the camera's
G-buffer without and with visibility, over every covered pixel and near walls."""
import json
import sys

path = sys.argv[1] if len(sys.argv) > 1 else "docs/results/irradiance_volume_surface.json"
runs = json.load(open(path))["runs"]
print("| run | probes (inside) | pixels / near walls | all: none | all: chebyshev | near walls: none | near walls: chebyshev | near: chebyshev / none | reference noise |")
print("|---|---|---|---|---|---|---|---|---|")
for r in runs:
    s = r["surface"]
    lk = s["lookups"]
    n, c = lk["trilinear_none"], lk["trilinear_chebyshev"]
    f = lambda e: f'{e["rel_rms"]:.4f} ({e["rel_rms_debiased"]:.4f})'
    ratio = c["near_wall"]["rel_rms"] / n["near_wall"]["rel_rms"]
    print(f'| {r["name"]} | {r["probes"]} ({r["probes_inside"]}) | {s["covered_pixels"]} / {s["near_wall_pixels"]} | '
          f'{f(n["all"])} | {f(c["all"])} | {f(n["near_wall"])} | {f(c["near_wall"])} | {ratio:.2f} | '
          f'{n["near_wall"]["reference_noise_rel_rms"]:.4f} |')
