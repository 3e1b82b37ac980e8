#!/usr/bin/env python3
"""The table of docs/radiosity.md section 7, "Grouped shooters", from
docs/results/radiosity_groups.json (docs/studies/radiosity_groups.sh): per scene, one shooter
per block ("blocks") against grouped shooters ("groups"), at 100,000 elements to 90% of the
indirect power: elements, charts, shooters, steps, converged fraction, total and per-step
time, rel_rms and black pixels; and the Sponza scaling runs if present.
Usage: docs/studies/radiosity_groups_table.py [docs/results/radiosity_groups.json]
"""
import json
import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "results", "radiosity_groups.json")
with open(path) as f:
    runs = {r["name"]: r for r in json.load(f)["runs"]}


def row(label, r):
    t = r["timings_ms"]["total"]["median_ms"] if isinstance(r["timings_ms"]["total"], dict) else r["timings_ms"]["total"]
    steps = r["iterations"]
    rel = r.get("error", {}).get("rel_rms")
    conv = 100 * (1 - r["indirect_unshot_fraction"])
    return (f"| {label} | {r['elements']:,} | {r['charts']:,} | {r['shooters']:,} | {steps:,} | {conv:.1f}% "
            f"({r['stopped']}) | {t / 1e3:.0f} | {r['timings_ms']['reconstruction'] / max(steps, 1):.0f} | "
            f"{'-' if rel is None else f'{rel:.4f}'} | {r.get('black_pixels', '-')} |")


print("| scene, shooters | elements | charts | shooters | steps | converged (indirect) | total s | shooting ms per step "
      "| rel_rms | black pixels |")
print("|---|---|---|---|---|---|---|---|---|---|")
for s in ("cornell", "cornell-box", "modern-hall", "sponza", "bunny", "living-room", "conference"):
    for kind in ("blocks", "groups"):
        r = runs.get(f"{kind}-{s}")
        if r:
            print(row(f"{s}, {kind}", r))
scaling = sorted((r for n, r in runs.items() if n.startswith("scaling-")), key=lambda r: (r["name"].split("-")[1], r["elements"]))
if scaling:
    print()
    print("| Sponza, shooters | elements | charts | shooters | steps | converged (indirect) | total s | shooting ms per step "
          "| rel_rms | black pixels |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in scaling:
        print(row(r["name"].split("-")[1], r))
