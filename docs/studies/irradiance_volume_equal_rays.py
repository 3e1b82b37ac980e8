#!/usr/bin/env python3
"""Issue 31, fifth session: the tables of docs/sh-and-irradiance-volumes.md ("hanging
corners computed, equal total rays") from docs/results/irradiance_volume_equal_rays.json
(docs/studies/irradiance_volume_equal_rays.sh).

Per scene: the depth-4 grid (512 rays a probe) and the octrees merged from its lattice by bias
tolerance in units of the probes' median noise, hanging corners computed (not among the
probes), in three families of the same layouts:
- "pooled": the bake's probes refit by least squares to every probe of the lattice (all the
  grid's rays spent; the program's merged octree);
- "total": the stored probes baked again with the grid's total rays spread over them, no refit;
- "512": the stored probes baked again with 512 rays each, no refit (fewer rays in all).
The share of the grid's probes at its error (path: moving sphere; surface: the camera's points,
rel_rms) is read off each family's points that no other beats in probes and error, the first
crossing interpolated ("<= s": already at the sparsest; "none": never, with its best point).

Usage: python3 docs/studies/irradiance_volume_equal_rays.py [RESULTS]"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from irradiance_volume_deeper import SCENES, err, share_at  # noqa: E402  (the same frontier and crossing)
FAMILIES = ("pooled", "total", "512")


def grid(run):
    return next(p for p in run["sweep"] if p["uniform"])


def family(run, kind):
    merged = [p for p in run["sweep"] if not p["uniform"]]
    if kind == "pooled":
        return [p for p in merged if p["rays_per_probe"] == 0]
    if kind == "512":
        return [p for p in merged if p["rays_per_probe"] == run["parameters"]["rays"]]
    # the total-rays point follows its pooled point; 512 follows it where the totals differ
    out, last = [], None
    for p in merged:
        if p["rays_per_probe"] == 0:
            last = p
        elif last is not None:
            out.append(p)
            last = None
    return out


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "docs/results/irradiance_volume_equal_rays.json"
    every = json.load(open(path))["runs"]
    kinds = {"512": {}, "floor": {}, "main": {}}
    for r in every:
        rest = r["name"].removeprefix("equal-rays-")
        if rest.startswith("lookup-"):
            continue  # MODE=lookup: two program runs, read by hand
        kind = next((k for k in ("512", "floor") if rest.startswith(k + "-")), "main")
        kinds[kind][rest.removeprefix(kind + "-") if kind != "main" else rest] = r
    runs = kinds["main"]
    scenes = [s for s in SCENES if s in runs]
    print("| scene | sigma / L | grid path / surface rel_rms | share at the grid's path error: pooled / total / 512 "
          "| surface: pooled / total / 512 |")
    print("|---|---|---|---|---|")
    for sc in scenes:
        r = runs[sc]
        g = grid(r)
        m = family(r, "pooled")[0]
        cells = [" / ".join(share_at(family(r, f), g["probes"], err(g, ms), ms)[0] for f in FAMILIES if family(r, f))
                 for ms in ("path", "surface")]
        print(f"| {sc} | {m['median_noise'] / m['scene_light']:.3f} | {err(g, 'path'):.4f} / {err(g, 'surface'):.4f} | "
              + " | ".join(cells) + " |")
    print()
    print("Per tolerance k (units of the median noise): share of the grid's probes, path / surface rel_rms, "
          "pooled; total; 512")
    for sc in scenes:
        r = runs[sc]
        n = grid(r)["probes"]
        fams = {f: family(r, f) for f in FAMILIES}
        rows = []
        for i, p in enumerate(fams["pooled"]):
            txt = f"{p['bias_tolerance']:g}: {100 * p['probes'] / n:.0f}% {err(p, 'path'):.4f}/{err(p, 'surface'):.4f}"
            for f in ("total", "512"):
                if i < len(fams[f]):
                    q = fams[f][i]
                    txt += f"; {q['rays_per_probe']} rays {err(q, 'path'):.4f}/{err(q, 'surface'):.4f}"
            rows.append(txt)
        print(f"- {sc}: " + " | ".join(rows))
    print()
    print("One k for every scene: scenes within the grid's error with at most 40% of its probes (path, surface, both)")
    for f in FAMILIES:
        ks = sorted({p["bias_tolerance"] for sc in scenes for p in family(runs[sc], f)})
        for k in ks:
            hits = {"path": [], "surface": [], "both": []}
            for sc in scenes:
                r = runs[sc]
                g = grid(r)
                p = next((p for p in family(r, f) if p["bias_tolerance"] == k), None)
                if p is None or p["probes"] > 0.4 * g["probes"]:
                    continue
                ok = {ms: err(p, ms) <= err(g, ms) for ms in ("path", "surface")}
                for ms in ("path", "surface"):
                    if ok[ms]:
                        hits[ms].append(sc)
                if ok["path"] and ok["surface"]:
                    hits["both"].append(sc)
            print(f"- {f}, k {k:g}: " + "; ".join(f"{m} {len(v)} ({', '.join(v)})" for m, v in hits.items()))
    for kind, title in (("512", "Equal rays per probe (MODE=fixed)"), ("floor", "4096-sample references, path (MODE=floor)")):
        if not kinds[kind]:
            continue
        print()
        print(f"{title}: grid path / surface; per k: share, pooled; total rays; 512 rays (path / surface)")
        for sc in [s for s in SCENES if s in kinds[kind]]:
            r = kinds[kind][sc]
            g = grid(r)
            has_surface = "surface" in g
            fmt = (lambda p: f"{err(p, 'path'):.4f}/{err(p, 'surface'):.4f}") if has_surface else (lambda p: f"{err(p, 'path'):.4f}")
            merged = [p for p in r["sweep"] if not p["uniform"]]
            cells = []
            for p in merged:
                if p["rays_per_probe"] == 0:
                    cells.append(f"k {p['bias_tolerance']:g}: {100 * p['probes'] / g['probes']:.0f}% {fmt(p)}")
                else:
                    cells[-1] += f"; {p['rays_per_probe']} rays {fmt(p)}"
            print(f"- {sc}: grid {fmt(g)} | " + " | ".join(cells))


if __name__ == "__main__":
    main()
