#!/usr/bin/env python3
"""docs/benchmark.md and docs/figures/benchmark-<scene>.png from the benchmark's results file.

Usage: benchmark_report.py [RESULTS.json] [--md PAGE.md] [--figures DIR]
       (defaults: docs/results/benchmark.json, docs/benchmark.md, docs/figures)

RESULTS.json is what `build/bin/benchmark` writes (adapters/study/include/bounce/study/benchmark.hpp):

    {"provenance": {"commit", "date", "cpu", "cores", "embree", "command", "settings": {...}},
     "scenes": [{"scene", "triangles", "lights", "bounds_diagonal",
                 "references": {quantity: {"spp", "ms", "cached", "noise_rel_rms"}},
                 "techniques": [{"technique", "quantity", "ms", "parameters", "counts",
                                 "error": {"rel_rms", "rel_rms_debiased", "rel_rms_debiased_se", "ssim"},
                                 "error_unoccluded": {...},             # RSM gather and SII
                                 "mc_equal_error": {"rel_rms": {"spp", "ms", "reached", "speedup", "bound"?},
                                                    "ssim": {...}},     # or {"skipped": why}
                                 "mc_equal_error_unoccluded": {...}}    # or {"technique", "failed": message}
                                ],
                 "monte_carlo": {quantity: [{"spp", "ms", "rel_rms", "rel_rms_debiased", "ssim"}]}}]}

The page holds the provenance and settings, an overview of the speed-ups, and per scene its
references, one table of every technique (time, debiased rel_rms +- se, SSIM, Monte Carlo's time at
equal rel_rms and at equal SSIM and the two speed-ups; for the RSM gather and SII the error against
the unoccluded reference beside) and one speed-against-error figure (a panel per quantity: each
technique a point at (time, debiased rel_rms), Monte Carlo's sweep a line, log-log). Then one
paragraph per technique, generated from the speed-ups: where it beats its Monte Carlo baseline at
equal error and where it does not pay.

Every figure on the page is read from the results file; nothing is computed but unit changes and
the comparison of a speed-up with 1. A null (non-finite) or missing value is shown as "—".
"""
import argparse
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TECHNIQUES = ["irradiance_cache", "rsm_gather", "rsm_gather+rays", "sii", "sii+rays", "sii_interleaved",
              "sii_interleaved+rays", "radiosity", "irradiance_volume"]
QUANTITIES = {
    "one_bounce": "one bounce with visibility",
    "unoccluded": "one bounce without visibility",
    "all_bounces": "all bounces",
    "volume_points": "one bounce at points off the surfaces",
}
STYLE = {  # marker and colour per technique, the same on every figure
    "irradiance_cache": ("o", "tab:blue"),
    "rsm_gather": ("s", "tab:orange"),
    "sii": ("^", "tab:green"),
    "sii_interleaved": ("v", "tab:red"),
    "rsm_gather+rays": ("X", "tab:orange"),
    "sii+rays": ("<", "tab:green"),
    "sii_interleaved+rays": (">", "tab:red"),
    "radiosity": ("D", "tab:purple"),
    "irradiance_volume": ("P", "tab:brown"),
}
DASH = "—"


# ---- reading values ------------------------------------------------------------------------------

def num(v):
    """A finite number, else None (null, NaN, a string, a bool)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    return float(v) if math.isfinite(v) else None


def get(d, *keys):
    """d[k0][k1]... or None where a level is missing or not a dict."""
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


def sig(x, digits=3):
    """x to `digits` significant figures, without an exponent for everyday magnitudes."""
    if x == 0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if mag >= digits - 1:
        return f"{x:.0f}"
    if mag < -4:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits - 1 - mag}f}"


def fmt(v, digits=3):
    v = num(v)
    if v is None:
        return DASH
    return str(int(v)) if v == int(v) and abs(v) < 1e15 else sig(v, digits)


def fmt_fixed(v, decimals):
    v = num(v)
    return DASH if v is None else f"{v:.{decimals}f}"


def fmt_ms(ms):
    ms = num(ms)
    if ms is None:
        return DASH
    return f"{sig(ms / 1000)} s" if ms >= 1000 else f"{sig(ms)} ms"


def cell(text):
    """Text safe inside a Markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def bound_prefix(entry):
    """'≥ ' where Monte Carlo's sweep never reached the figure (its time is a lower bound),
    '≤ ' where its first run already beat it (an upper bound), else ''."""
    bound = entry.get("bound")
    if bound is None and entry.get("reached") is False:
        bound = "lower"
    return {"lower": "≥ ", "upper": "≤ "}.get(bound, "")


def times(sp):
    """A speed-up: two significant figures, three near 1 (where the verdict turns on them)."""
    return f"{sig(sp, 3 if 0.9 <= sp < 1.1 else 2)}x"


def fmt_speedup(entry):
    if not isinstance(entry, dict) or num(entry.get("speedup")) is None:
        return DASH
    return f"{bound_prefix(entry)}{times(num(entry['speedup']))}"


def fmt_mc(entry):
    """Monte Carlo's time at equal error and its samples per pixel."""
    if not isinstance(entry, dict):
        return DASH
    if "skipped" in entry:
        return "skipped: " + cell(entry["skipped"])
    ms, spp = num(entry.get("ms")), num(entry.get("spp"))
    if ms is None:
        return DASH
    text = bound_prefix(entry) + fmt_ms(ms)
    return text + (f" ({fmt(spp)} spp)" if spp is not None else "")


def fmt_error(err):
    """'debiased ± se' of an error object."""
    d, se = num(get(err, "rel_rms_debiased")), num(get(err, "rel_rms_debiased_se"))
    if d is None:
        return DASH
    return f"{d:.4f} ± {se:.4f}" if se is not None else f"{d:.4f}"


def fmt_counts(counts):
    if not isinstance(counts, dict) or not counts:
        return DASH
    parts = []
    for k, v in counts.items():
        if isinstance(v, (dict, list)):
            continue
        n = num(v)
        if isinstance(v, bool):
            v = json.dumps(v)
        parts.append(f"{k} {v if isinstance(v, str) or n is None else (int(n) if n == int(n) else sig(n))}")
    return cell("; ".join(parts)) if parts else DASH


def verdict(entry):
    """How a speed-up compares with 1: ('pays' | 'loses' | 'level' | 'open', text) or None
    where there is no speed-up (missing, skipped, null). 'level' when it shows as 1.00x;
    'open' when Monte Carlo's sweep bounds it only on the far side of 1."""
    if not isinstance(entry, dict) or num(entry.get("speedup")) is None:
        return None
    sp, prefix = num(entry["speedup"]), bound_prefix(entry)
    text = f"{prefix}{times(sp)}"
    if prefix == "≥ ":
        return ("pays" if sp > 1 else "open"), text
    if prefix == "≤ ":
        return ("loses" if sp < 1 else "open"), text
    if times(sp) == "1.00x":  # equal to the figures shown
        return "level", text
    return ("pays" if sp > 1 else "loses"), text


def slug(name):
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", str(name)).strip("-") or "scene"


def scene_name(scene, index):
    return str(scene.get("scene") or f"scene-{index + 1}")


def techniques_of(scene):
    """The scene's technique entries, an RSM technique run with visibility named `<technique>+<visibility>`."""
    out = []
    for t in scene.get("techniques") or []:
        if not isinstance(t, dict):
            continue
        if t.get("visibility") not in (None, "none"):
            t = dict(t, technique=f"{t.get('technique')}+{t['visibility']}")
        out.append(t)
    return out


# ---- figures ---------------------------------------------------------------------------------------

def plotted_quantities(scene):
    used = set()
    for q, steps in (scene.get("monte_carlo") or {}).items():
        if steps:
            used.add(q)
    for t in techniques_of(scene):
        if t.get("quantity"):
            used.add(t["quantity"])
        if isinstance(t.get("error_unoccluded"), dict):
            used.add("unoccluded")
    return [q for q in QUANTITIES if q in used] + sorted(used - set(QUANTITIES))


def point(err, ms):
    """(seconds, debiased rel_rms, se) of a technique, or None when it cannot sit on a log axis."""
    s, e = num(ms), num(get(err, "rel_rms_debiased"))
    if s is None or s <= 0 or e is None or e <= 0:
        return None
    return s / 1000, e, num(get(err, "rel_rms_debiased_se")) or 0.0


def figure(scene, index, path):
    """The scene's speed-against-error figure; returns the techniques left off it (and why)."""
    name = scene_name(scene, index)
    quantities = plotted_quantities(scene)
    left_off = []
    if not quantities:
        return None, left_off
    cols = 1 if len(quantities) == 1 else 2
    rows = (len(quantities) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.8 * cols, 3.7 * rows), dpi=80, squeeze=False)
    for ax in axes.flat[len(quantities):]:
        ax.set_visible(False)
    for ax, q in zip(axes.flat, quantities):
        plotted = False
        steps = [s for s in (get(scene, "monte_carlo", q) or []) if isinstance(s, dict)]
        steps.sort(key=lambda s: num(s.get("spp")) or 0)
        mc = [(num(s.get("ms")) / 1000, num(s.get("rel_rms_debiased")), s.get("spp")) for s in steps
              if (num(s.get("ms")) or 0) > 0 and (num(s.get("rel_rms_debiased")) or 0) > 0]
        if mc:
            ax.plot([p[0] for p in mc], [p[1] for p in mc], color="black", linestyle="--", marker="x",
                    markersize=4, linewidth=1, label="Monte Carlo (spp sweep)")
            for x, y, spp in mc:
                ax.annotate(str(spp), (x, y), textcoords="offset points", xytext=(3, -8), fontsize=6, color="0.3")
            plotted = True
        for t in techniques_of(scene):
            tech = str(t.get("technique"))
            marker, colour = STYLE.get(tech, ("*", "tab:gray"))
            own = [s for s in (t.get("monte_carlo") or []) if isinstance(s, dict)] if t.get("quantity") == q else []
            own = sorted(((num(s.get("ms")) or 0) / 1000, num(s.get("rel_rms_debiased")) or 0) for s in own)
            own = [p for p in own if p[0] > 0 and p[1] > 0]
            if own:  # a merged row's own sweep (benchmark_merge.py)
                ax.plot([p[0] for p in own], [p[1] for p in own], color=colour, linestyle=":", linewidth=1,
                        label=f"Monte Carlo ({tech}'s run)")
            for err, hollow, suffix in ((t.get("error"), False, ""), (t.get("error_unoccluded"), True, " (vs unoccluded)")):
                target_q = "unoccluded" if hollow else t.get("quantity")
                if target_q != q or not isinstance(err, dict) or "failed" in t:
                    continue
                p = point(err, t.get("ms"))
                if p is None:
                    left_off.append(f"{tech}{suffix} on {QUANTITIES.get(q, q)} (no positive debiased error or time)")
                    continue
                x, y, se = p
                ax.errorbar([x], [y], yerr=[[min(se, 0.9 * y)], [se]], marker=marker, color=colour, markersize=7,
                            markerfacecolor="none" if hollow else colour, linestyle="none", capsize=2,
                            label=tech + suffix)
                plotted = True
        ax.set_title(QUANTITIES.get(q, q), fontsize=9)
        ax.set_xlabel("time (s)", fontsize=8)
        ax.set_ylabel("rel_rms, reference noise removed", fontsize=8)
        if plotted:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.tick_params(which="both", labelsize=7)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=6)
        else:
            ax.tick_params(labelsize=7)
            ax.text(0.5, 0.5, "nothing to plot\n(no positive errors)", ha="center", va="center",
                    transform=ax.transAxes, fontsize=8)
    fig.suptitle(f"{name}: speed against error", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path, left_off


# ---- the page --------------------------------------------------------------------------------------

MERGED_MARK = "†"


def provenance_lines(results):
    prov = results.get("provenance") or {}
    lines = ["## Provenance and settings", ""]
    for key, label in (("commit", "commit"), ("date", "date"), ("cpu", "CPU"), ("cores", "cores"),
                       ("embree", "Embree ISA")):
        v = prov.get(key)
        lines.append(f"- {label}: {DASH if v is None else v}")
    cmd = prov.get("command")
    lines.append(f"- command: `{cmd}`" if cmd else f"- command: {DASH}")
    settings = prov.get("settings") or {}
    if settings:
        lines.append("- settings:")
        for k, v in settings.items():
            if isinstance(v, dict):
                v = ", ".join(f"{kk} {DASH if vv is None else vv}" for kk, vv in v.items()) or DASH
            elif isinstance(v, list):
                v = ", ".join(str(x) for x in v) or DASH
            elif v is None:
                v = DASH
            elif isinstance(v, bool):
                v = json.dumps(v)
            lines.append(f"  - {k}: {v}")
    for m in prov.get("merged") or []:  # runs of some techniques merged in (benchmark_merge.py)
        if not isinstance(m, dict):
            continue
        techs = sorted({str(e).split("/", 1)[-1] for e in m.get("entries") or []})
        use = m.get("machine_use") or {}
        lines.append(f"- merged run ({', '.join(techs) or DASH}; rows marked {MERGED_MARK}): commit {m.get('commit', DASH)}, "
                     f"date {m.get('date', DASH)}, command `{m.get('command', DASH)}`, wall {fmt(num(use.get('wall_s')))} s, "
                     f"load average {fmt(num(use.get('load_average_start')))} -> {fmt(num(use.get('load_average_end')))}"
                     + (f"; {m['note']}" if m.get("note") else ""))
    return lines + [""]


def overview_lines(results):
    scenes = [scene_name(s, i) for i, s in enumerate(results["scenes"])]
    present = {str(t.get("technique")) for s in results["scenes"] for t in techniques_of(s)}
    techs = [t for t in TECHNIQUES if t in present] + sorted(present - set(TECHNIQUES))
    lines = ["## Overview: speed-up over Monte Carlo at equal error", "",
             "Each cell: at equal debiased rel_rms / at equal SSIM (Monte Carlo's time over the technique's; "
             "above 1 the technique pays).", "",
             "| technique | " + " | ".join(cell(s) for s in scenes) + " |",
             "|---|" + "---|" * len(scenes)]
    for tech in techs:
        row = []
        for s in results["scenes"]:
            t = next((t for t in techniques_of(s) if t.get("technique") == tech), None)
            if t is None:
                row.append("not run")
            elif "failed" in t:
                row.append("failed")
            else:
                row.append(f"{fmt_speedup(get(t, 'mc_equal_error', 'rel_rms'))} / "
                           f"{fmt_speedup(get(t, 'mc_equal_error', 'ssim'))}")
        lines.append(f"| {tech} | " + " | ".join(row) + " |")
    return lines + [""]


def scene_lines(scene, index, figure_path, left_off, md_dir):
    name = scene_name(scene, index)
    lines = [f"## Scene: {name}", ""]
    facts = []
    if num(scene.get("triangles")) is not None:
        facts.append(f"{int(num(scene['triangles']))} triangles")
    if num(scene.get("lights")) is not None:
        n = int(num(scene["lights"]))
        facts.append(f"{n} light" + ("" if n == 1 else "s"))
    if num(scene.get("bounds_diagonal")) is not None:
        facts.append(f"bounding-box diagonal {sig(num(scene['bounds_diagonal']))}")
    if facts:
        lines += [", ".join(facts) + ".", ""]

    refs = scene.get("references") or {}
    if refs:
        lines += ["References (two independent halves each; their noise is taken out of every error):", "",
                  "| quantity | samples per pixel | time | cached | reference noise (rel_rms) |",
                  "|---|---|---|---|---|"]
        for q, r in refs.items():
            r = r if isinstance(r, dict) else {}
            cached = {True: "yes", False: "no"}.get(r.get("cached"), DASH)
            lines.append(f"| {cell(q)} | {fmt(r.get('spp'))} | {fmt_ms(r.get('ms'))} | {cached} | "
                         f"{fmt_fixed(r.get('noise_rel_rms'), 4)} |")
        lines.append("")

    lines += ["| technique | quantity | time | rel_rms (debiased ± se) | SSIM | Monte Carlo at equal rel_rms | speed-up "
              "| Monte Carlo at equal SSIM | speed-up | against the unoccluded reference: rel_rms, SSIM, speed-up | counts |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    merged_rows = False
    for t in techniques_of(scene):
        tech = cell(t.get("technique", DASH))
        if isinstance(t.get("merged_run"), int):
            tech += " " + MERGED_MARK
            merged_rows = True
        if "failed" in t:
            lines.append(f"| {tech} | {cell(t.get('quantity', DASH))} | failed: {cell(t['failed'])} |"
                         + f" {DASH} |" * 8)
            continue
        err, mc = t.get("error"), t.get("mc_equal_error") or {}
        unocc = DASH
        if isinstance(t.get("error_unoccluded"), dict):
            eu = t["error_unoccluded"]
            unocc = (f"{fmt_error(eu)}, {fmt_fixed(eu.get('ssim'), 3)}, "
                     f"{fmt_speedup(get(t, 'mc_equal_error_unoccluded', 'rel_rms'))}")
        lines.append(f"| {tech} | {cell(t.get('quantity', DASH))} | {fmt_ms(t.get('ms'))} | {fmt_error(err)} | "
                     f"{fmt_fixed(get(err, 'ssim'), 3)} | {fmt_mc(mc.get('rel_rms'))} | {fmt_speedup(mc.get('rel_rms'))} | "
                     f"{fmt_mc(mc.get('ssim'))} | {fmt_speedup(mc.get('ssim'))} | {unocc} | {fmt_counts(t.get('counts'))} |")
    lines.append("")
    if merged_rows:
        lines += [f"{MERGED_MARK} from a later run of that technique alone (provenance above), its speed-ups against that "
                  "run's own Monte Carlo sweep (the dotted line in the figure).", ""]
    visibility = [v for v in scene.get("visibility") or [] if isinstance(v, dict)]
    if visibility:
        lines += ["What indirect visibility adds (issue 29's headline, at most 1.2): each RSM technique's debiased "
                  "rel_rms with occlusion rays against the reference with visibility, over its rel_rms without "
                  "visibility against the unoccluded reference.", "",
                  "| technique | with rays, against the occluded reference | without, against the unoccluded one | "
                  "ratio |", "|---|---|---|---|"]
        for v in visibility:
            lines.append(f"| {cell(v.get('technique', DASH))} | {fmt_fixed(v.get('rays_vs_occluded'), 4)} | "
                         f"{fmt_fixed(v.get('none_vs_unoccluded'), 4)} | {fmt_fixed(v.get('ratio'), 2)} |")
        lines.append("")
    if figure_path:
        rel = os.path.relpath(figure_path, md_dir).replace(os.sep, "/")
        lines += [f"![{name}: speed against error]({rel})", ""]
        caption = ("Each technique is a point at (time, debiased rel_rms) with a bar of one standard error; "
                   "hollow markers are the RSM gather's and SII's error against the unoccluded reference; "
                   "the dashed line is Monte Carlo's sweep, its samples per pixel marked.")
        if left_off:
            caption += " Not plotted: " + "; ".join(left_off) + "."
        lines += [caption, ""]
    return lines


def join_scenes(items):
    items = list(items)
    if len(items) <= 1:
        return "".join(items)
    return ", ".join(items[:-1]) + " and " + items[-1]


def technique_paragraph(tech, results):
    """Where `tech` pays against its Monte Carlo baseline, from the speed-ups alone."""
    runs = [(scene_name(s, i), next((t for t in techniques_of(s) if t.get("technique") == tech), None))
            for i, s in enumerate(results["scenes"])]
    ran = [(n, t) for n, t in runs if t is not None]
    quantity = next((t.get("quantity") for _, t in ran if t.get("quantity")), None)
    head = f"**{tech}**" + (f" ({QUANTITIES.get(quantity, quantity)})" if quantity else "") + "."
    sentences = [head]
    failed = [(n, t) for n, t in ran if "failed" in t]
    ok = [(n, t) for n, t in ran if "failed" not in t]

    def comparison(measure, key, what):
        groups = {"pays": [], "loses": [], "level": [], "open": [], None: []}
        for n, t in ok:
            entry = get(t, key, measure)
            v = verdict(entry)
            if v and v[0] == "open":
                run = "largest run" if bound_prefix(entry) == "≥ " else "first run"
                did = "did not reach its error" if run == "largest run" else "already did better"
                most = "at least" if run == "largest run" else "at most"
                groups["open"].append(f"{n} (Monte Carlo's {run}, {fmt_ms(entry.get('ms'))}, {did}: "
                                      f"the speed-up is {most} {v[1].lstrip('≥≤ ')})")
            else:
                groups[v[0] if v else None].append(f"{n} ({v[1]})" if v else n)
        baseline = "its Monte Carlo baseline" if key == "mc_equal_error" else "unoccluded Monte Carlo"
        if ok and len(groups["pays"]) == len(ok):
            return [f"At equal {what} it beats {baseline} on every scene it ran on: {join_scenes(groups['pays'])}."]
        if ok and len(groups["loses"]) == len(ok):
            return [f"At equal {what} it does not pay on any scene it ran on: {join_scenes(groups['loses'])}."]
        clauses = []
        if groups["pays"]:
            clauses.append(f"beats {baseline} on {join_scenes(groups['pays'])}")
        if groups["loses"]:
            clauses.append(f"does not pay on {join_scenes(groups['loses'])}")
        if groups["level"]:
            clauses.append(f"is level with Monte Carlo on {join_scenes(groups['level'])}")
        if groups["open"]:
            clauses.append(f"is not settled by the sweep on {join_scenes(groups['open'])}")
        out = [f"At equal {what} it " + "; it ".join(clauses) + "."] if clauses else []
        if groups[None]:
            out.append(f"No equal-{what} figure on {join_scenes(groups[None])}.")
        return out

    if ok:
        sentences += comparison("rel_rms", "mc_equal_error", "rel_rms")
        sentences += comparison("ssim", "mc_equal_error", "SSIM")
        unocc = [(n, t) for n, t in ok if isinstance(t.get("error_unoccluded"), dict)]
        if unocc:
            pairs = [f"{n} {fmt_fixed(get(t, 'error_unoccluded', 'rel_rms_debiased'), 3)} against "
                     f"{fmt_fixed(get(t, 'error', 'rel_rms_debiased'), 3)}" for n, t in unocc]
            sentences.append("Its debiased rel_rms against the unoccluded reference (the quantity it approximates), "
                             "beside that against the one with visibility: " + join_scenes(pairs) + ".")
            if any(isinstance(t.get("mc_equal_error_unoccluded"), dict) for _, t in unocc):
                sentences += comparison("rel_rms", "mc_equal_error_unoccluded", "unoccluded rel_rms")
    if failed:
        sentences.append("It failed on " + join_scenes(n for n, _ in failed) + " (the messages are in the scenes' tables).")
    missing = [n for n, t in runs if t is None]
    if missing:
        sentences.append(f"Not run on {join_scenes(missing)}.")
    return " ".join(sentences)


def page(results, figures, md_dir, results_label):
    lines = ["# Benchmark: every technique on every scene", "",
             f"Generated by `docs/studies/benchmark_report.py` from `{results_label}` (written by "
             "`build/bin/benchmark`); do not edit by hand. Each technique runs with its defaults and is measured against "
             "the reference of the quantity it computes; its baseline is brute-force Monte Carlo of the same quantity on "
             "the same ray tracer, swept over samples per pixel.", "",
             "How to read the tables: *time* is the technique's wall time; *rel_rms* is the relative RMS error of "
             "luminance over the pixels that see geometry with the reference's own noise taken out, ± one standard "
             "error; *SSIM* is the structural similarity of the tone-mapped luminance "
             "(`bounce::study::tonemapped_ssim`: Monte Carlo's white noise and a cache's smooth error of equal rel_rms "
             "do not look alike); *Monte Carlo at equal ...* is the time (samples per pixel) the baseline takes to "
             "reach the same figure, read off its sweep, and the *speed-up* is that time over the technique's. "
             "≥ marks a lower bound (Monte Carlo's largest run did not reach the figure), ≤ an upper bound (its "
             "first run already did better).", ""]
    lines += provenance_lines(results)
    lines += overview_lines(results)
    for i, scene in enumerate(results["scenes"]):
        path, left_off = figures[i]
        lines += scene_lines(scene, i, path, left_off, md_dir)
    present = {str(t.get("technique")) for s in results["scenes"] for t in techniques_of(s)}
    techs = [t for t in TECHNIQUES if t in present] + sorted(present - set(TECHNIQUES))
    lines += ["## Where each technique pays", ""]
    for tech in techs:
        lines += [technique_paragraph(tech, results), ""]
    lines += ["*These paragraphs are generated from the numbers in the results file by "
              "`docs/studies/benchmark_report.py`: a speed-up above 1 reads \"beats\", below 1 \"does not pay\", one shown "
              "as 1.00x \"level\"; "
              "where Monte Carlo's sweep only bounds the speed-up on the other side of 1, it says the sweep does not "
              "settle it. No sentence is written by hand.*", ""]
    return "\n".join(lines)


def main(argv):
    here = os.path.dirname(os.path.abspath(__file__))
    docs = os.path.dirname(here)
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("results", nargs="?", default=os.path.join(docs, "results", "benchmark.json"))
    parser.add_argument("--md", default=os.path.join(docs, "benchmark.md"), help="the page to write")
    parser.add_argument("--figures", default=os.path.join(docs, "figures"), help="folder of the figures")
    args = parser.parse_args(argv)
    try:
        with open(args.results) as f:
            results = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"benchmark_report: cannot read {args.results}: {e}")
    if not isinstance(results, dict) or not isinstance(results.get("scenes"), list) or not results["scenes"]:
        sys.exit(f"benchmark_report: {args.results} holds no 'scenes' list")
    if not all(isinstance(s, dict) for s in results["scenes"]):
        sys.exit(f"benchmark_report: {args.results}: every entry of 'scenes' must be an object")
    os.makedirs(args.figures, exist_ok=True)
    md_dir = os.path.dirname(os.path.abspath(args.md))
    figures, used = [], set()
    for i, scene in enumerate(results["scenes"]):
        stem = slug(scene_name(scene, i))
        while stem in used:  # two scenes of one name still get a figure each
            stem += f"-{i + 1}"
        used.add(stem)
        path, left_off = figure(scene, i, os.path.join(args.figures, f"benchmark-{stem}.png"))
        figures.append((os.path.abspath(path) if path else None, left_off))
        if path:
            print(path)
    try:
        label = os.path.relpath(os.path.abspath(args.results), os.path.dirname(docs)).replace(os.sep, "/")
    except ValueError:
        label = args.results
    if label.startswith(".."):
        label = os.path.basename(args.results)
    text = page(results, figures, md_dir, label)
    os.makedirs(md_dir, exist_ok=True)
    with open(args.md, "w") as f:
        f.write(text)
    print(args.md)


if __name__ == "__main__":
    main(sys.argv[1:])
