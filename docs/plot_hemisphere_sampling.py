#!/usr/bin/env python3
"""Plots a sweep run of the hemisphere study (examples/hemisphere_study --sweep), read from
the study's results file by run name:

    python3 docs/plot_hemisphere_sampling.py docs/results/hemisphere_sampling.json sweep \
        docs/hemisphere-sampling.png

Left: RMS error of the four weightings against the plane resolution at the aperture of the
main run (126 degrees by default), ray-cast sampler solid, raster sampler dashed.
Right: border stretching's error against resolution, one line per aperture (ray-cast).
The title names the planes' turn when the study ran with --plane-turn or --hashed-turn.
Needs matplotlib (Debian: python3-matplotlib; run with /usr/bin/python3).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METHODS = [("rms_plane", "plane only"), ("rms_coverage", "coverage ratio [LC04]"),
           ("rms_stretch", "border stretching"), ("rms_falloff", "fall-off stretching")]
COLOURS = ["#777777", "#1f77b4", "#d62728", "#2ca02c"]


def main(argv):
    if len(argv) != 4:
        sys.exit(__doc__)
    with open(argv[1]) as f:
        runs = {r["name"]: r for r in json.load(f)["runs"]}
    if argv[2] not in runs:
        sys.exit(f"{argv[1]} has no run {argv[2]!r} (runs: {', '.join(runs)})")
    study = runs[argv[2]]
    rows = study["sweep"]
    aperture = study["parameters"]["aperture_deg"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 5), dpi=90)
    for sampler, style in (("ray_cast", "-"), ("raster", "--")):
        sel = sorted((r for r in rows if r["sampler"] == sampler and r["aperture"] == aperture),
                     key=lambda r: r["resolution"])
        if not sel:
            continue
        for (key, label), colour in zip(METHODS, COLOURS):
            left.plot([r["resolution"] for r in sel], [100 * r[key] for r in sel], style, color=colour,
                      marker="o", markersize=3,
                      label=f"{label} ({sampler.replace('_', '-')})")
    left.set_xscale("log", base=2)
    left.set_xlabel("plane resolution N (N x N pixels)")
    left.set_ylabel("RMS error of irradiance (%)")
    params = study["parameters"]
    turn = params.get("plane_turn_deg", 0) or 0
    turned = (f", turned {turn:g} deg" if turn else "") + (", hashed turn" if params.get("hashed_turn") else "")
    left.set_title(f"{study['scene']}, aperture {aperture:g} deg{turned}, {study.get('sweep_points', '?')} points")
    left.grid(True, alpha=0.3)
    left.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.16))

    apertures = sorted({r["aperture"] for r in rows})
    cmap = plt.get_cmap("viridis")
    for i, ap in enumerate(apertures):
        sel = sorted((r for r in rows if r["sampler"] == "ray_cast" and r["aperture"] == ap),
                     key=lambda r: r["resolution"])
        if sel:
            right.plot([r["resolution"] for r in sel], [100 * r["rms_stretch"] for r in sel], "-",
                       color=cmap(i / max(1, len(apertures) - 1)), marker="o", markersize=3,
                       label=f"{ap:g} deg")
    right.set_xscale("log", base=2)
    right.set_xlabel("plane resolution N")
    right.set_ylabel("RMS error, border stretching (%)")
    right.set_title("aperture choice (ray-cast sampler)")
    right.grid(True, alpha=0.3)
    right.legend(fontsize=7, title="aperture", ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    fig.tight_layout()
    fig.savefig(argv[3])


if __name__ == "__main__":
    main(sys.argv)
