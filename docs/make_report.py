#!/usr/bin/python3
"""Builds docs/report.md and its speed-against-error plots from the irradiance-splatting
study's results file, docs/results/ic_splatting.json (the examples' --json reports, added
by docs/studies/ic_splatting.sh through docs/studies/results.py)."""
import json
import math
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


RESULTS = os.path.join(HERE, "results", "ic_splatting.json")


def load():
    """{run name: report}, ordered by name (as the report has always listed them)."""
    with open(RESULTS) as f:
        runs = json.load(f)["runs"]
    return {r["name"]: r for r in sorted(runs, key=lambda r: r["name"] + ".json")}


def row(name, r):
    t = r["timings_ms"]
    e = r.get("error", {}).get("rel_rms", float("nan"))
    p = r["parameters"]
    return (f"| {name} | {r['backend']} | {p.get('weight', '')} | {'on' if p.get('gradients') else 'off'} | "
            f"{'on' if p.get('neighbour_clamp') else 'off'} | "
            f"{p.get('a', 0):.3g} | {p.get('record_samples', '')} | {r.get('records', '')} | {t.get('interpolate', float('nan')):.1f} | "
            f"{t.get('compute_records', float('nan')):.0f} | {t.get('total', float('nan')):.0f} | {e:.4f} |")


def mc_time_at(sweep, e):
    """Monte Carlo's time to reach error e, by log-log interpolation in its spp sweep:
    (ms, False), or (ms of its last point, True) when it never got down to e (a lower bound)."""
    for a, b in zip(sweep, sweep[1:]):
        if a["rel_rms"] >= e >= b["rel_rms"]:
            f = math.log(a["rel_rms"] / e) / math.log(a["rel_rms"] / b["rel_rms"])
            return a["ms"] * (b["ms"] / a["ms"]) ** f, False
    if e < sweep[-1]["rel_rms"]:
        return sweep[-1]["ms"], True
    return None, False


def sweep_table(sweep, mc):
    """The a sweep's speed against error, each a beside Monte Carlo's time at its error."""
    lines = ["| a | records | total ms | rel_rms | Monte Carlo ms at that error | speed-up |", "|---|---|---|---|---|---|"]
    for r in sweep:
        e, t = r["error"]["rel_rms"], r["timings_ms"]["total"]
        ms, bound = mc_time_at(mc, e) if mc else (None, False)
        mc_cell = "" if ms is None else f"{'> ' if bound else ''}{ms:.0f}"
        up = "" if ms is None else f"{'> ' if bound else ''}{ms / t:.1f}x"
        lines.append(f"| {r['parameters']['a']:.2g} | {r['records']} | {t:.0f} | {e:.4f} | {mc_cell} | {up} |")
    return lines


def headline(scene, mine):
    """The comparisons of the irradiance-splatting issue, from the runs that exist."""
    def err(name):
        r = mine.get(f"{scene}-{name}")
        return r and r.get("error", {}).get("rel_rms")

    out = []
    if err("smooth") is not None:
        out.append(f"- indirect rel_rms with gradients: {err('smooth'):.4f} (target <= 0.06)")
    if err("smooth") and err("nograd"):
        out.append(f"- gradients lower the error by {100 * (1 - err('smooth') / err('nograd')):.0f}% "
                   f"({err('nograd'):.4f} without; target >= 25%)")
    if err("nolimit-nograd") and err("nolimit"):
        nl, nn, sm = mine[f"{scene}-nolimit"], mine[f"{scene}-nolimit-nograd"], mine.get(f"{scene}-smooth")
        line = (f"- without any gradient (Ward 1988, no radius limit either): {err('nolimit-nograd'):.4f} with "
                f"{nn['records']} records; the same records extrapolated: {err('nolimit'):.4f} "
                f"(-{100 * (1 - err('nolimit') / err('nolimit-nograd')):.0f}%)")
        if sm:
            line += (f"; with the radius limit too ({sm['records']} records): "
                     f"-{100 * (1 - err('smooth') / err('nolimit-nograd')):.0f}%")
        out.append(line)
    for rays in (1024, 2048):  # the same pair with the ray count the scene's main runs do not use
        on = err(f"r{rays}") or err(f"r{rays}-a0.15")
        if on and err(f"r{rays}-nograd"):
            out.append(f"- with {rays} rays per record: {on:.4f}, without gradients {err(f'r{rays}-nograd'):.4f}: "
                       f"gradients lower the error by {100 * (1 - on / err(f'r{rays}-nograd')):.0f}%")
    for tag, label in (("256-r16384", "at 256x256 against a 16384-spp reference, 16384 rays per record"),
                       ("r4096", "with 4096 rays per record")):
        if err(tag) and err(f"{tag}-nograd"):
            out.append(f"- {label}: {err(tag):.4f}, without gradients {err(f'{tag}-nograd'):.4f}: "
                       f"gradients lower the error by {100 * (1 - err(tag) / err(f'{tag}-nograd')):.0f}%")
    if err("smooth") and err("front"):
        f, sm = mine[f"{scene}-front"], mine[f"{scene}-smooth"]
        out.append(f"- Ward's in-front test (tolerance {f['parameters']['front_tolerance']:.2g}): {err('front'):.4f} with "
                   f"{f['records']} records, against {err('smooth'):.4f} with {sm['records']} without it")
    if err("smooth") and err("ward"):
        out.append(f"- smoothed weight {err('smooth'):.4f} against Ward's {err('ward'):.4f} (target: not above)")
    for tag, label in (("r4096", "with 4096 rays per record"),
                       ("r16384", "with 16384 rays per record (nearly noise-free records)"),
                       ("256-r1024", "at 256x256 against a 16384-spp reference, 1024 rays per record"),
                       ("256-r16384", "at 256x256 against a 16384-spp reference, 16384 rays per record")):
        if err(tag) and err(f"ward-{tag}"):
            out.append(f"- {label}: smoothed {err(tag):.4f}, Ward's {err(f'ward-{tag}'):.4f}")
    if err("a0.4") and err("ward-a0.4"):
        out.append(f"- at a = 0.4, where Ward's seams show: smoothed {err('a0.4'):.4f}, Ward's {err('ward-a0.4'):.4f}")
    si, oi = mine.get(f"{scene}-interp-splat"), mine.get(f"{scene}-interp-octree")
    if si and oi:
        s_ms, o_ms = si["timings_ms"]["interpolate"], oi["timings_ms"]["interpolate"]
        out.append(f"- interpolation on one saved cache ({si['records']} records, medians of {si['repeat']} renders): "
                   f"splatting {s_ms:.1f} ms, octree lookups {o_ms:.1f} ms: {o_ms / s_ms:.2f}x (target >= 2x)")
        ol = mine.get(f"{scene}-interp-octree-lanes")
        if ol:
            out.append(f"- the octree evaluating four records at a time (same lanes as the splat): "
                       f"{ol['timings_ms']['interpolate']:.1f} ms")
    s, o = mine.get(f"{scene}-smooth"), mine.get(f"{scene}-octree")
    if s and o:
        out.append(f"- whole two-pass frame: splatting {s['timings_ms']['total']:.0f} ms at {err('smooth'):.4f}, "
                   f"octree {o['timings_ms']['total']:.0f} ms at {o['error']['rel_rms']:.4f} (single runs: interpolate "
                   f"{s['timings_ms']['interpolate']:.1f} and {o['timings_ms']['interpolate']:.1f} ms)")
    g = mine.get(f"{scene}-gl")
    if g:
        out.append(f"- GL splatting (llvmpipe, no GPU): interpolate {g['timings_ms']['interpolate']:.1f} ms, "
                   f"rel_rms {g['error']['rel_rms']:.4f}")
    m = mine.get(f"{scene}-mc")
    if m and "mc_equal_error" in m:
        bound = "at least " if m["mc_equal_error"].get("lower_bound") else ""
        out.append(f"- at equal error brute-force Monte Carlo takes {bound}{m['mc_equal_error']['speedup']:.1f}x "
                   f"the cache's time (target >= 20x)")
    return out


WEIGHTS = ("ward", "ward-smooth", "ward-gpu", "ward-gpu-shader", "tabellion")


def weights_table(scene, mine):
    """Every weighting policy on its own cache at a = 0.15 and 0.4 (runs SCENE-w-WEIGHT-aA)."""
    cells = {}
    for w in WEIGHTS:
        for a in ("0.15", "0.4"):
            r = mine.get(f"{scene}-w-{w}-a{a}")
            if r:
                cells[w, a] = f"{r['records']} | {r['timings_ms']['total']:.0f} | {r['error']['rel_rms']:.4f}"
    if not cells:
        return []
    lines = ["Weighting functions, each on the cache it builds (runs back to back on one machine):", "",
             "| weight | a = 0.15: records | ms | rel_rms | a = 0.4: records | ms | rel_rms |", "|---|---|---|---|---|---|---|"]
    for w in WEIGHTS:
        lines.append(f"| {w} | {cells.get((w, '0.15'), ' | | ')} | {cells.get((w, '0.4'), ' | | ')} |")
    on, off = mine.get(f"{scene}-w-tabellion-a0.15"), mine.get(f"{scene}-tabellion-nograd")
    if on and off:
        e_on, e_off = on["error"]["rel_rms"], off["error"]["rel_rms"]
        lines += ["", f"Tabellion's weight at a = 0.15 without gradients (same records): {e_off:.4f}; gradients lower "
                      f"its error by {100 * (1 - e_on / e_off):.0f}%."]
    m = mine.get(f"{scene}-tabellion-mc")
    if m and "mc_equal_error" in m:
        bound = "at least " if m["mc_equal_error"].get("lower_bound") else ""
        lines += ["", f"Tabellion's weight at a = {m['parameters']['a']:.2g} ({m['records']} records, "
                      f"{m['timings_ms']['total']:.0f} ms, rel_rms {m['error']['rel_rms']:.4f}): brute-force Monte Carlo "
                      f"takes {bound}{m['mc_equal_error']['speedup']:.1f}x the cache's time at that error."]
    return lines + [""]


def seams_table(scene, mine):
    """Ward's weight against the smoothed one over the a sweep, both run back to back on one
    machine (runs SCENE-seams-WEIGHT-aA)."""
    rows = []
    for a in ("0.4", "0.3", "0.2", "0.15", "0.1"):
        ward, smooth = mine.get(f"{scene}-seams-ward-a{a}"), mine.get(f"{scene}-seams-ward-smooth-a{a}")
        if ward and smooth:
            e_w, e_s = ward["error"]["rel_rms"], smooth["error"]["rel_rms"]
            rows.append(f"| {a} | {ward['records']} | {e_w:.4f} | {smooth['records']} | {e_s:.4f} | "
                        f"{100 * (e_s / e_w - 1):+.1f}% |")
    if not rows:
        return []
    return ["Ward's weight against the smoothed one, each on the cache it builds (run back to back on one "
            "machine):", "",
            "| a | Ward: records | rel_rms | smoothed: records | rel_rms | smoothed vs Ward |",
            "|---|---|---|---|---|---|"] + rows + [""]


def main():
    runs = load()
    lines = ["# Speed against error", "",
             "Generated by `docs/make_report.py` from `docs/results/ic_splatting.json` (the `--json`",
             "reports of the examples with their provenance; `docs/studies/ic_splatting.sh` re-runs",
             "them). Error is the relative RMS of the indirect image's luminance against the",
             "reference integrator over covered pixels. Runs without one error figure (progressive",
             "mode, which has one per frame) have their own table.",
             "Machine: 2 cores, no GPU (OpenGL on Mesa llvmpipe).", ""]
    for scene in sorted({r["scene"] for r in runs.values()}):
        mine = {k: v for k, v in runs.items() if v["scene"] == scene}
        refs = sorted({(r["width"], r["parameters"]["reference_spp"]) for r in mine.values()
                       if "reference_spp" in r.get("parameters", {})}, reverse=True)
        lines += [f"## {scene}", "",
                  "References: " + ", ".join(f"{spp} spp at {w}x{w}" for w, spp in refs) + ".", "",
                  "| run | backend | weight | gradients | clamp | a | rays | records | interpolate ms | records ms | total ms | rel_rms |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for name, r in mine.items():
            if "rel_rms" in r.get("error", {}):
                lines.append(row(name, r))
        lines.append("")
        head = headline(scene, mine)
        if head:
            lines += ["Figures the irradiance-splatting issue asks for (a = 0.15):", ""] + head + [""]
        lines += weights_table(scene, mine)
        lines += seams_table(scene, mine)
        # The main Monte Carlo run (others, such as SCENE-tabellion-mc, have their own lines).
        mc = [r for r in [mine.get(f"{scene}-mc")] if r and "mc_sweep" in r]
        if mc:
            r = mc[0]
            lines += ["Brute-force Monte Carlo (reference integrator, independent seed) on the same G-buffer:", "",
                      "| spp | ms | rel_rms |", "|---|---|---|"]
            lines += [f"| {m['spp']} | {m['ms']:.0f} | {m['rel_rms']:.4f} |" for m in r["mc_sweep"]]
            if r.get("mc_equal_error", {}).get("lower_bound"):
                m = r["mc_equal_error"]
                lines += ["", f"Monte Carlo stays above the cache's error ({m['rel_rms']:.4f}) up to "
                              f"{m['measured_spp']} spp (half the reference's samples), which take {m['measured_ms']:.0f} ms: "
                              f"at least {m['speedup']:.1f}x the cache's total time."]
            elif "mc_equal_error" in r:
                m = r["mc_equal_error"]
                lines += ["", f"At equal error Monte Carlo needs about {m['spp']:.0f} spp, {m['ms']:.0f} ms "
                              f"(log-log interpolation between the last two points): "
                              f"{m['speedup']:.1f}x the cache's total time."]
            lines.append("")
        prog = [r for r in mine.values() if "frames" in r]
        if prog:
            lines += ["Progressive mode (at most N new records per frame; the camera walks forward and pans from -10 to +10 degrees):", "",
                      "| frame | records | new | ms | fps | rel_rms |", "|---|---|---|---|---|---|"]
            lines += [f"| {f['frame']} | {f['records']} | {f['new_records']} | {f['ms']:.0f} | {f['fps']:.2f} | "
                      f"{f['rel_rms']:.4f} |" for f in prog[0]["frames"]]
            lines.append("")
        # The a sweep against Monte Carlo, as a table and as a plot: one series per number of
        # rays per record (runs named SCENE-aA and SCENE-rN-aA).
        swept = [v for k, v in mine.items() if re.fullmatch(rf"{re.escape(scene)}-(r\d+-)?a[0-9.]+", k)]
        series = {}
        for r in swept:
            series.setdefault(r["parameters"]["record_samples"], []).append(r)
        if series:
            mc_sweep = mc[0]["mc_sweep"] if mc else None
            lines += ["Speed against error over the a sweep (smoothed Ward, gradients on), for each number of",
                      "rays per record; Monte Carlo's time at each run's error comes from its spp sweep above",
                      "(log-log interpolation; '>' where it never got that low):", ""]
            fig, ax = plt.subplots(figsize=(5, 3.4), dpi=100)
            for rays, group in sorted(series.items()):
                group.sort(key=lambda r: r["parameters"]["a"])
                lines += [f"{rays} rays per record:", ""] + sweep_table(group, mc_sweep) + [""]
                ax.plot([r["error"]["rel_rms"] for r in group], [r["timings_ms"]["total"] for r in group], "o-",
                        label=f"irradiance splatting, {rays} rays/record (a sweep)")
                for r in group:
                    ax.annotate(f"a={r['parameters']['a']:.2g}", (r["error"]["rel_rms"], r["timings_ms"]["total"]),
                                fontsize=7)
            if mc_sweep:
                ax.plot([m["rel_rms"] for m in mc_sweep], [m["ms"] for m in mc_sweep], "s--",
                        label="Monte Carlo (spp sweep)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("indirect rel. RMS error")
            ax.set_ylabel("time (ms)")
            ax.set_title(f"{scene}, 512x512")
            ax.legend(fontsize=7)
            fig.tight_layout()
            png = os.path.join(HERE, "figures", f"speed-error-{scene}.png")
            os.makedirs(os.path.dirname(png), exist_ok=True)
            fig.savefig(png)
            plt.close(fig)
            lines += [f"![speed against error, {scene}](figures/speed-error-{scene}.png)", ""]
    with open(os.path.join(HERE, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
