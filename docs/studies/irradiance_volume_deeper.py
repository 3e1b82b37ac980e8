#!/usr/bin/env python3
"""Issue 31, fourth session: the table and the error-against-probes figure of
docs/sh-and-irradiance-volumes.md ("refining deeper than the grid") from
docs/results/irradiance_volume_deeper.json (docs/studies/irradiance_volume_deeper.sh).

For every scene: the uniform grids of depth 3, 4, 5 (one bake of the depth-5 lattice) and the
octrees merged from depth 4 and 5 by bias tolerance (and by bias budget), each on the moving
sphere ("path", rel_rms) and at the camera's surface points ("surface", rel_rms). The share of
the depth-d grid's probes at that grid's error is read off each family's points that no other
point of the family beats in both probes and error: the first crossing of the grid's error,
interpolated linearly ("<= s" where the sparsest point is already within it, "none" where no
point is).

Usage: /usr/bin/python3 docs/studies/irradiance_volume_deeper.py [RESULTS] [--figure PNG]
(matplotlib only for --figure)."""
import json
import sys

SCENES = ["cornell", "cornell-box", "bunny", "living-room", "modern-hall", "sponza", "conference"]


def points(run):
    """The sweep's points, each merged one labelled by the lattice it was merged from: the
    blocks follow --sweep-depths (the first runs labelled a merged octree by its own depth,
    shallower where everything merged)."""
    pts, par = run["sweep"], run["parameters"]
    depths = par["sweep_depths"]
    block = len(par["sweep_bias_budget"]) * max(1, len(par["sweep_noise_sigmas"])) + \
        len(par["sweep_bias_tolerance"]) * max(1, len(par["sweep_noise_sigmas"]))
    merged = [p for p in pts if not p["uniform"]]
    for i, p in enumerate(merged):
        p["max_depth"] = depths[i // block]
    return pts


def grid(run, depth):
    return next(p for p in points(run) if p["uniform"] and p["max_depth"] == depth)


def err(p, measure):
    return p["rel_rms"] if measure == "path" else p["surface"]["all"]["rel_rms"]


def family(run, depth, kind):
    key = "bias_tolerance" if kind == "tolerance" else "bias_budget"
    return [p for p in points(run) if not p["uniform"] and p["max_depth"] == depth and p[key] > 0]


def share_at(pts, n, target, measure, baked_only=False):
    """(text, share or None): the first crossing of `target` along the family's frontier;
    baked_only: the hanging corners (interpolated from the coarser leaf) not counted."""
    pts = sorted((((p["probes"] - (p.get("hanging", 0) if baked_only else 0)) / n, err(p, measure)) for p in pts))
    front, best = [], float("inf")
    for s, e in pts:
        if e < best:
            front.append((s, e))
            best = e
    for i, (s, e) in enumerate(front):
        if e <= target:
            if i == 0:
                return f"<= {100 * s:.0f}%", s
            s0, e0 = front[i - 1]
            x = s0 + (s - s0) * (e0 - target) / (e0 - e)
            return f"{100 * x:.0f}%", x
    s, e = min(front, key=lambda f: f[1])
    return f"none ({100 * s:.0f}% at {e:.4f})", None


def main():
    argv = sys.argv[1:]
    picture = None
    if "--figure" in argv:
        i = argv.index("--figure")
        picture = argv[i + 1]
        del argv[i:i + 2]
    args = argv
    path = args[0] if args else "docs/results/irradiance_volume_deeper.json"
    runs = {r["name"].removeprefix("deeper-"): r for r in json.load(open(path))["runs"]}
    scenes = [s for s in SCENES if s in runs]
    print("| scene | grid 3 / 4 / 5: path rel_rms | grid 3 / 4 / 5: surface rel_rms (debiased) | surface reference noise "
          "| depth 4's share at its error, path: from 4 / from 5 | surface: from 4 / from 5 | budget from 5, surface "
          "| hanging corners not counted: path from 4 / 5, surface from 4 / 5 |")
    print("|---|---|---|---|---|---|---|---|")
    for sc in scenes:
        r = runs[sc]
        g = {d: grid(r, d) for d in (3, 4, 5)}
        path_e = " / ".join(f"{err(g[d], 'path'):.4f}" for d in (3, 4, 5))
        surf_e = " / ".join(f"{err(g[d], 'surface'):.4f} ({g[d]['surface']['all']['rel_rms_debiased']:.4f})" for d in (3, 4, 5))
        noise = g[4]["surface"]["all"]["reference_noise_rel_rms"]
        n4 = g[4]["probes"]
        cells = []
        for measure in ("path", "surface"):
            cells.append(" / ".join(share_at(family(r, d, "tolerance"), n4, err(g[4], measure), measure)[0] for d in (4, 5)))
        cells.append(share_at(family(r, 5, "budget"), n4, err(g[4], "surface"), "surface")[0])
        cells.append(" / ".join(" / ".join(share_at(family(r, d, "tolerance"), n4, err(g[4], m), m, True)[0] for d in (4, 5))
                                for m in ("path", "surface")))
        print(f"| {sc} | {path_e} | {surf_e} | {noise:.4f} | " + " | ".join(cells) + " |")
    print()
    print("Per tolerance, merged from depth 5: share of depth 4's probes, path / surface rel_rms")
    for sc in scenes:
        r = runs[sc]
        n4 = grid(r, 4)["probes"]
        row = ", ".join(f"{p['bias_tolerance']:g}: {100 * p['probes'] / n4:.0f}% {err(p, 'path'):.4f}/{err(p, 'surface'):.4f}"
                        for p in family(r, 5, "tolerance"))
        print(f"- {sc}: {row}")
    print()
    print("One tolerance for every scene: scenes where it is within the depth-4 grid's error with at most 40% of its "
          "probes (path / surface; baked: hanging corners not counted), merged from 4 and from 5")
    for d in (4, 5):
        tols = sorted({p["bias_tolerance"] for sc in scenes for p in family(runs[sc], d, "tolerance")})
        for t in tols:
            hits = {"path": [], "surface": [], "path, baked": [], "surface, baked": []}
            for sc in scenes:
                r = runs[sc]
                g4 = grid(r, 4)
                p = next(p for p in family(r, d, "tolerance") if p["bias_tolerance"] == t)
                for m in hits:
                    n = p["probes"] - (p.get("hanging", 0) if "baked" in m else 0)
                    if n <= 0.4 * g4["probes"] and err(p, m.split(",")[0]) <= err(g4, m.split(",")[0]):
                        hits[m].append(sc)
            print(f"- from {d}, tolerance {t:g}: " + "; ".join(f"{m} {len(v)} ({', '.join(v)})" for m, v in hits.items()))
    if picture:
        figure(runs, scenes, picture)


def figure(runs, scenes, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, len(scenes), figsize=(2.6 * len(scenes), 5.4), squeeze=False)
    for col, sc in enumerate(scenes):
        r = runs[sc]
        n4 = grid(r, 4)["probes"]
        for row, measure in enumerate(("surface", "path")):
            ax = axes[row][col]
            gs = [grid(r, d) for d in (3, 4, 5)]
            ax.plot([p["probes"] / n4 for p in gs], [err(p, measure) for p in gs], "ks-", label="uniform grid 3, 4, 5", ms=4)
            for d, c in ((4, "tab:blue"), (5, "tab:red")):
                f = sorted(family(r, d, "tolerance"), key=lambda p: p["probes"])
                ax.plot([p["probes"] / n4 for p in f], [err(p, measure) for p in f], "o-", color=c, ms=3,
                        label=f"merged from {d}, tolerance")
            f = sorted(family(r, 5, "budget"), key=lambda p: p["probes"])
            ax.plot([p["probes"] / n4 for p in f], [err(p, measure) for p in f], "x:", color="tab:orange", ms=4,
                    label="merged from 5, budget")
            ax.axhline(err(gs[1], measure), color="grey", lw=0.6)
            ax.axvline(0.4, color="green", lw=0.6, ls="--")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.tick_params(labelsize=6)
            if row == 0:
                ax.set_title(sc, fontsize=8)
            if col == 0:
                ax.set_ylabel(f"{measure} rel_rms", fontsize=7)
            if row == 1:
                ax.set_xlabel("probes / depth-4 grid's", fontsize=7)
    axes[0][0].legend(fontsize=5, loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=80)


if __name__ == "__main__":
    main()
