#!/usr/bin/env python3
"""Speed against error per scene from docs/results/ic_policies.json (docs/studies/ic_policies.sh):
one curve per cache configuration over its a sweep, and brute-force Monte Carlo's spp sweep,
time on x and indirect error on y (both logarithmic). The error is the one with the
reference's own noise taken out where the run reports it (error.rel_rms_debiased), else the
raw rel_rms; the figure says which.

Usage: ic_policies_figures.py RESULTS.json OUTDIR  -> OUTDIR/ic-policies-<scene>-<size>.png

It also prints, per scene, a Markdown table of every run with Monte Carlo's time at the run's
error read off the same sweep (log-log interpolation between the two runs around it; beyond
the sweep, error ~ spp^-1/2 from its last run, marked "~") and the speed-up.
"""
import math
import collections
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def error_of(entry):
    """(error, debiased?) of a run's or a Monte Carlo step's error object."""
    err = entry.get("error", entry)
    if err.get("rel_rms_debiased") is not None:
        return err["rel_rms_debiased"], True
    return err["rel_rms"], False


def monte_carlo_ms(steps, target):
    """Monte Carlo's time at error `target` from its sweep: (ms, extrapolated?)."""
    pts = [(error_of(st)[0], st["ms"]) for st in steps if error_of(st)[0] and error_of(st)[0] > 0]
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if e0 >= target >= e1:
            f = math.log(target / e0) / math.log(e1 / e0)
            return math.exp(math.log(t0) + f * math.log(t1 / t0)), False
    e1, t1 = pts[-1]
    return t1 * (e1 / target) ** 2, True


def table(scene, s):
    mc = s["mc"]
    steps = mc.get("mc_sweep") if mc else None
    print(f"\n{scene}\n")
    print("| run | a | records | rays per record | total (s) | rel_rms (debiased) | Monte Carlo at equal error (s) | speed-up |")
    print("|---|---|---|---|---|---|---|---|")
    rows = [(name, p) for name, points in s["series"].items() for p in points]
    if mc and mc["name"].endswith("default-mc"):
        e, _ = error_of(mc)
        rows.append(("default", (mc["timings_ms"]["total"] / 1000, e, mc["parameters"]["a"], True, mc)))
    for name, (t, e, a, _, run) in sorted(rows, key=lambda r: (r[0], -r[1][2])):
        rays = run.get("rays_per_record", {}).get("mean")
        mc_cell, speed = "", ""
        if steps:
            ms, extrapolated = monte_carlo_ms(steps, e)
            mc_cell = ("~" if extrapolated else "") + f"{ms / 1000:.1f}"
            speed = f"{ms / 1000 / t:.1f}x"
        print(f"| {name} | {a:g} | {run['records']} | {rays:.0f} | {t:.1f} | {e:.4f} | {mc_cell} | {speed} |"
              if rays else f"| {name} | {a:g} | {run['records']} | | {t:.1f} | {e:.4f} | {mc_cell} | {speed} |")


def main(results_path, outdir):
    with open(results_path) as f:
        runs = json.load(f)["runs"]
    scenes = collections.defaultdict(lambda: {"series": collections.defaultdict(list), "mc": None})
    for run in runs:
        m = re.match(r"^(?P<scene>[a-z]+-\d+)-(?P<series>.+?)(-a(?P<a>[0-9.]+))?$", run["name"])
        if not m:
            continue
        s = scenes[m["scene"]]
        if run.get("mc_sweep") and (s["mc"] is None or m["series"] == "default-mc"):
            s["mc"] = run  # Monte Carlo's sweep: the defaults' run, else any run that has one
        if m["a"] is None:
            continue
        e, debiased = error_of(run)
        s["series"][m["series"]].append((run["timings_ms"]["total"] / 1000, e, float(m["a"]), debiased, run))

    os.makedirs(outdir, exist_ok=True)
    for scene, s in sorted(scenes.items()):
        if not s["series"]:
            continue  # a walkthrough's run alone: no curve to draw
        fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=100)
        any_debiased = False
        for name, points in sorted(s["series"].items()):
            points.sort(key=lambda p: p[0])
            xs, ys = [p[0] for p in points], [p[1] for p in points]
            any_debiased |= any(p[3] for p in points)
            ax.plot(xs, ys, marker="o", label=name)
            for x, y, a, _, _ in points:
                ax.annotate(f"{a:g}", (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7)
        if s["mc"] is not None and s["mc"].get("mc_sweep"):
            steps = [st for st in s["mc"]["mc_sweep"] if st["spp"] >= 4]
            xs = [st["ms"] / 1000 for st in steps]
            ys = [error_of(st)[0] for st in steps]
            ax.plot(xs, ys, color="black", linestyle="--", marker="x", label="Monte Carlo (spp sweep)")
            for st, x, y in zip(steps, xs, ys):
                ax.annotate(str(st["spp"]), (x, y), textcoords="offset points", xytext=(3, -9), fontsize=7)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("time (s, 2 cores)")
        ax.set_ylabel("indirect rel_rms" + (" (reference noise removed)" if any_debiased else ""))
        ax.set_title(f"{scene}: irradiance cache against Monte Carlo")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        out = os.path.join(outdir, f"ic-policies-{scene}.png")
        fig.savefig(out)
        plt.close(fig)
        print(out)
        table(scene, s)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
