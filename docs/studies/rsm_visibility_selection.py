#!/usr/bin/env python3
"""Issue 29, sixth session: SII's VPLs chosen by the view with and without the near field
(view_selection_params::near_field), from docs/results/rsm_visibility_selection.json (runs of
examples/rsm_visibility_study, seed by seed; `before` runs are the library at fc5fe5d or
`--candidates K` at 5a6ecd1, the near field's at 07957dd) and, for seeds not re-run there,
the `table-*` runs of docs/results/rsm_visibility_table.json (the same frames before).

    docs/studies/rsm_visibility_selection.py [--complete]

Prints, per scene x configuration x VPL count, over the seeds measured both ways: debiased
rel_rms with rays (against the occluded reference) before -> with the near field, the mean
without visibility (against the unoccluded one) and both ratios; `--complete` the 4x4 frames
before and with their isolated pixels completed (discontinuity_params::complete_below 0.5).
"""
import argparse
import collections
import json
import os

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
RESULTS = os.path.join(ROOT, "docs", "results")


def variant(run):
    name, p = run["name"], run["parameters"]
    if name.startswith("NF"):
        return "near"
    if name.startswith("table") or name.startswith("complete") or name.startswith("base"):
        return "before"
    return "before" if p.get("view_candidates", 4) == 4 else "K%d" % p["view_candidates"]


def cells():
    out = collections.defaultdict(lambda: collections.defaultdict(dict))
    for file in ("rsm_visibility_table.json", "rsm_visibility_selection.json"):
        for r in json.load(open(os.path.join(RESULTS, file)))["runs"]:
            if file == "rsm_visibility_table.json" and not r["name"].startswith(("table", "complete")):
                continue
            seed = r["parameters"]["seed"]
            for f in r["frames"]:
                key = (f["scene"], f["config"], f["vpls"])
                v = "none" if f["visibility"] == "none" else variant(r)
                out[key][seed][v] = f["rel_rms_debiased"]
    return out


def mean(xs):
    return sum(xs) / len(xs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--complete", action="store_true")
    args = ap.parse_args()
    c = cells()
    if args.complete:
        print("| scene | VPLs | seeds | none: 4x4 -> completed | rays: 4x4 -> completed |")
        print("|---|---|---|---|---|")
        for (scene, config, vpls) in sorted(c):
            if config != "4x4-blur":
                continue
            a, b = c[(scene, config, vpls)], c.get((scene, "4x4-blur-complete", vpls), {})
            seeds = sorted(s for s in b if s in a and "before" in a[s] and "before" in b[s] and "none" in b[s])
            if not seeds:
                continue
            n0, n1 = mean([a[s]["none"] for s in seeds]), mean([b[s]["none"] for s in seeds])
            r0, r1 = mean([a[s]["before"] for s in seeds]), mean([b[s]["before"] for s in seeds])
            print(f"| {scene} | {vpls} | {','.join(map(str, seeds))} | {n0:.4f} -> {n1:.4f} | {r0:.4f} -> {r1:.4f} |")
        return
    print("| scene | technique | VPLs | seeds | rays: before -> near field | none | ratio before -> near field |")
    print("|---|---|---|---|---|---|---|")
    for (scene, config, vpls) in sorted(c, key=lambda k: (k[0], k[1], k[2])):
        if config not in ("plain-footprint", "4x4-blur"):
            continue
        d = c[(scene, config, vpls)]
        seeds = sorted(s for s in d if all(k in d[s] for k in ("before", "near", "none")))
        if not seeds:
            continue
        b, n, z = (mean([d[s][k] for s in seeds]) for k in ("before", "near", "none"))
        tech = "SII plain" if config == "plain-footprint" else "SII 4x4 blur"
        mark = lambda r: f"**{r:.2f}**" if r > 1.2 else f"{r:.2f}"
        print(f"| {scene} | {tech} | {vpls} | {','.join(map(str, seeds))} | {b:.4f} -> {n:.4f} | {z:.4f} "
              f"| {mark(b / z)} -> {mark(n / z)} |")


if __name__ == "__main__":
    main()
