#!/usr/bin/env python3
"""The table of docs/sh-and-irradiance-volumes.md (irradiance volumes) from
docs/results/irradiance_volume.json: one row per run and lookup (probes, bake, error,
popping, popping beyond the reference's, lookup time), and the SH study's rows.
Usage: python3 docs/studies/irradiance_volume_table.py [RESULTS]"""
import json
import sys

path = sys.argv[1] if len(sys.argv) > 1 else "docs/results/irradiance_volume.json"
runs = json.load(open(path))["runs"]
print("| run | probes (inside) | bake s | lookup | rel_rms | popping | popping beyond reference | lookup ns |")
print("|---|---|---|---|---|---|---|---|")
for r in runs:
    if "lookups" not in r:
        continue
    for name, l in r["lookups"].items():
        print(f"| {r['name']} | {r['probes']} ({r['probes_inside']}) | {r['bake_ms'] / 1000:.1f} | {name} | "
              f"{l['rel_rms']:.4f} | {l['popping']:.3f} | {l['popping_excess']:.3f} | {l['lookup_ns']:.0f} |")
for r in runs:
    if "environments" not in r:
        continue
    print(f"\n{r['name']}: SH of environments captured along the path (16384 rays each), worst over "
          f"{len(r['environments'])} points\n")
    print("| order | radiance rel. L2 | irradiance max / peak | irradiance mean / peak |")
    print("|---|---|---|---|")
    orders = r["environments"][0]["orders"]
    for k, o in enumerate(orders):
        worst = [max(e["orders"][k][key] for e in r["environments"])
                 for key in ("radiance_rel_l2", "irradiance_max_rel_peak", "irradiance_mean_rel_peak")]
        print(f"| {o['order']} | {worst[0]:.4f} | {worst[1]:.4f} | {worst[2]:.4f} |")
