#!/usr/bin/env python3
"""The table of docs/sh-and-irradiance-volumes.md (irradiance volumes) from
docs/results/irradiance_volume.json: one row per run and lookup (probes, bake, error,
popping, popping beyond the reference's, lookup time), and the SH study's rows.
With --sweep, the issue 31 third-session table from docs/results/irradiance_volume_sweep.json
instead: per scene and noise estimate, the uniform grid and the merged octrees of its
probes at each bias budget, and the share of the grid's probes at the grid's error.
Usage: python3 docs/studies/irradiance_volume_table.py [RESULTS]
       python3 docs/studies/irradiance_volume_table.py --sweep [SWEEP_RESULTS]"""
import json
import sys


def share_at_error(points, target):
    """The smallest share of the grid's probes at which the piecewise-linear curve through
    (share, rel_rms) points, the grid (1, its error) among them, reaches `target`:
    '<= s' when the sparsest point already does, else the crossing interpolated between
    the last point above the target and the next one at or below it."""
    points = sorted(points)
    if points[0][1] <= target:
        return f"<= {100 * points[0][0]:.0f}%"
    for (s0, e0), (s1, e1) in zip(points, points[1:]):
        if e0 > target >= e1:
            return f"{100 * (s0 + (s1 - s0) * (e0 - target) / (e0 - e1)):.0f}%"
    return "none"


if sys.argv[1:2] == ["--sweep"]:
    path = sys.argv[2] if len(sys.argv) > 2 else "docs/results/irradiance_volume_sweep.json"
    runs = json.load(open(path))["runs"]
    print("| scene | noise | rel_rms grid | bias budget: probes share, rel_rms | share at the grid's error "
          "| at the even-odd grid's | popping grid / budget 1 (reference) |")
    print("|---|---|---|---|---|---|---|")
    def noise(r):  # the first runs spelled --noise-estimate as --halves even-odd|independent
        p = r["parameters"]
        return p.get("noise_estimate", {"independent": "independent-halves"}.get(p.get("halves"), p.get("halves")))

    even_odd = {r["scene"]: r["error"]["rel_rms"] for r in runs if noise(r) == "even-odd"}
    grids = [r for r in runs if r["name"].startswith("grid-")]
    runs = [r for r in runs if not r["name"].startswith("grid-")]
    for r in runs:
        n, err = r["probes"], r["error"]["rel_rms"]
        pts = [(p["probes"] / n, p["rel_rms"]) for p in r["sweep"]]
        cells = ", ".join(f"{p['bias_budget']:g}: {100 * p['probes'] / n:.0f}% {p['rel_rms']:.4f}" for p in r["sweep"])
        one = next((p for p in r["sweep"] if p["bias_budget"] == 1), r["sweep"][0])
        print(f"| {r['scene']} | {noise(r)} | {err:.4f} | {cells} | {share_at_error(pts + [(1, err)], err)} "
              f"| {share_at_error(pts + [(1, err)], even_odd.get(r['scene'], err))} "
              f"| {r['popping']:.3f} / {one['popping']:.3f} ({r['popping_reference']:.3f}) |")
    # Budgets x slacks: the front of (share, rel_rms) points no other point beats in both,
    # and the grid's own point, give the share at equal error.
    print("\n| scene | noise | rel_rms grid | share at the grid's error | at the even-odd grid's "
          "| sparsest within the grid's error: share, rel_rms (budget, slack) | popping grid / that octree (reference) "
          "| slack 4, budget 1: share, rel_rms |")
    print("|---|---|---|---|---|---|---|---|")
    for r in grids:
        n, err = r["probes"], r["error"]["rel_rms"]
        pts = sorted((p["probes"] / n, p["rel_rms"]) for p in r["sweep"])
        front = [q for q in pts if not any(o[0] <= q[0] and o[1] < q[1] for o in pts)]
        within = [p for p in r["sweep"] if p["rel_rms"] <= err]
        best = min(within, key=lambda p: p["probes"]) if within else None
        cell = (f"{100 * best['probes'] / n:.0f}%, {best['rel_rms']:.4f} ({best['bias_budget']:g}, {best['noise_sigmas']:g})"
                if best else "none")
        pop = f"{r['popping']:.3f} / {best['popping']:.3f}" if best else f"{r['popping']:.3f} / -"
        d = next((p for p in r["sweep"] if p["bias_budget"] == 1 and p["noise_sigmas"] == 4), None)
        dcell = f"{100 * d['probes'] / n:.0f}%, {d['rel_rms']:.4f}" if d else "-"
        print(f"| {r['scene']} | {noise(r)} | {err:.4f} | {share_at_error(front + [(1, err)], err)} "
              f"| {share_at_error(front + [(1, err)], even_odd.get(r['scene'], err))} | {cell} "
              f"| {pop} ({r['popping_reference']:.3f}) | {dcell} |")
    sys.exit(0)

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
