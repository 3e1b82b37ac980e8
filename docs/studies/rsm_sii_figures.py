#!/usr/bin/python3
"""Figures and tables of docs/rsm-sii-interleaved.md from docs/results/rsm_sii.json.

    /usr/bin/python3 docs/studies/rsm_sii_figures.py [docs/results/rsm_sii.json]

Reads the run `cornell-study` (rsm_sii --study: Hahn 2012's grid in one process) and writes
- docs/figures/rsm_sii_timing.png: total frame time against VPL count per pattern, both
  techniques, beside Hahn 2012's timing tables (section 5.1);
- docs/figures/rsm_sii_accuracy.png: the sum of squared intensity differences against the
  same technique without interleaving, per pattern, beside Hahn 2012's accuracy tables
  (section 5.2), plus SII with the thesis's weight 1;
- docs/figures/rsm_sii_time_error.png: time against rel_rms (unoccluded reference) per
  technique, one curve per pattern, the plain runs (16 ... 4096 VPLs) as the baseline;
- docs/studies/rsm_sii_tables.md: the tables behind the figures and the issue's targets,
  including each interleaved run against the plain curve interpolated at its own time, and
  (runs `visibility-edges-<scene>-<count>`, rsm_visibility_study) the headline ratio of issue
  29 for SII 4x4 with the blur, with and without the blur's visibility edges.
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DOCS = os.path.dirname(HERE)
COUNTS = [64, 128, 256, 512, 768, 1024]
PATTERNS = ["1x1", "2x2", "2x4", "4x4", "8x8"]

# Hahn 2012, section 5.1 (seconds; 1280x768, GPU) and 5.2 (sums of squared intensity
# differences against the non-interleaved frame), as published. No 2x2 timing table.
THESIS_TIME = {
    "rsm": {"1x1": [0.125765, 0.25107, 0.50733, 0.9841, 1.4742, 1.958312],
            "2x4": [0.08456, 0.098897, 0.159836, 0.2856, 0.410798, 0.536653],
            "4x4": [0.051923, 0.079898, 0.117043, 0.191274, 0.265996, 0.34402],
            "8x8": [0.055492, 0.061867, 0.073805, 0.099867, 0.125432, 0.151679]},
    "sii": {"1x1": [0.028453, 0.049206, 0.096885, 0.182759, 0.280525, 0.362722],
            "2x4": [0.069322, 0.0427, 0.066594, 0.084725, 0.106727, 0.132191],
            "4x4": [0.045131, 0.046408, 0.071349, 0.08334, 0.097725, 0.125335],
            "8x8": [0.048339, 0.048605, 0.05331, 0.061001, 0.077343, 0.079507]},
}
THESIS_SSD = {
    "rsm": {"2x2": [1587.512573, 1157.870728, 1073.019775, 972.505066, 955.018005, 980.470825],
            "2x4": [986.992493, 1364.303833, 760.413147, 1096.026489, 1118.089722, 1027.150757],
            "4x4": [2513.528564, 1865.905762, 1463.996704, 1320.737671, 1207.255981, 1163.351929],
            "8x8": [8121.203125, 4336.058105, 3264.121338, 2429.007324, 2008.491577, 1650.494141]},
    "sii": {"2x2": [56.348606, 177.745087, 4585.55127, 34976.08594, 5646.042969, 57875.63281],
            "2x4": [1263.057129, 3235.810547, 18706.07031, 75933.85938, 109779.5156, 113257.8828],
            "4x4": [2805.519531, 7069.297363, 37024.79297, 111802.6875, 143026.6875, 147412.0],
            "8x8": [4328.337402, 10934.37305, 57703.60547, 171104.3594, 220956.6719, 235972.6875]},
}
NAMES = {"rsm": "RSM gather", "sii": "SII"}


def load_study(path):
    with open(path) as f:
        results = json.load(f)
    for run in results["runs"]:
        if run["name"] == "cornell-study":
            return run
    sys.exit(f"{path} has no run named cornell-study (run docs/studies/rsm_sii.sh study)")


def lookup(grid, technique, vpls, pattern, energy_correct=True):
    for r in grid:
        if (r["technique"] == technique and r["vpls"] == vpls and r["pattern"] == pattern
                and r["energy_correct"] == energy_correct):
            return r
    return None


def plain_curve(grid, technique):
    """(total_ms, rel_rms) of the plain runs, sorted by time."""
    pts = [(r["timings_ms"]["total"], r["error"]["rel_rms"]) for r in grid
           if r["technique"] == technique and r["pattern"] == "1x1" and r["energy_correct"]]
    return sorted(pts)


def interpolate_log(curve, t):
    """rel_rms of the plain curve at time t, linear in log-log; None outside its range."""
    for (t0, e0), (t1, e1) in zip(curve, curve[1:]):
        if t0 <= t <= t1 and t1 > t0:
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return math.exp(math.log(e0) + a * (math.log(e1) - math.log(e0)))
    return None


def timing_figure(grid, out):
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, technique in zip(axes, ("rsm", "sii")):
        for i, p in enumerate(PATTERNS):
            ys = [lookup(grid, technique, k, p)["timings_ms"]["total"] for k in COUNTS]
            ax.plot(COUNTS, ys, "o-", color=f"C{i}", label=f"bounce {p if p != '1x1' else 'plain'}")
            if p in THESIS_TIME[technique]:
                ax.plot(COUNTS, [1000 * s for s in THESIS_TIME[technique][p]], "x--", color=f"C{i}", alpha=0.6,
                        label=f"Hahn 2012 {p if p != '1x1' else 'plain'}")
        ax.set_yscale("log")
        ax.set_xlabel("VPLs (SII) / disc samples per map (RSM gather)")
        ax.set_ylabel("total frame time, ms")
        ax.set_title(NAMES[technique])
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=6, ncol=2)
    fig.suptitle("Frame time against VPL count (bounce: CPU, 2 shared cores, 512x384; thesis: GPU, 1280x768)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)


def accuracy_figure(grid, out):
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, technique in zip(axes, ("rsm", "sii")):
        for i, p in enumerate(PATTERNS[1:], start=1):
            ys = [lookup(grid, technique, k, p)["error"]["vs_plain"]["rel_rms"] for k in COUNTS]
            ax.plot(COUNTS, ys, "o-", color=f"C{i}", label=f"bounce {p}")
        if technique == "sii":
            pts = [(k, lookup(grid, "sii", k, "4x4", False)) for k in COUNTS]
            pts = [(k, r["error"]["vs_plain"]["rel_rms"]) for k, r in pts if r]
            if pts:
                ax.plot(*zip(*pts), "s:", color="k", label="bounce 4x4, thesis weight 1")
        ax.set_yscale("log")
        ax.set_xlabel("VPLs (SII) / disc samples per map (RSM gather)")
        ax.set_ylabel("rel_rms against the plain image")
        ax.set_title(NAMES[technique])
        ax.grid(True, which="both", alpha=0.3)
        ax2 = ax.twinx()
        for i, p in enumerate(PATTERNS[1:], start=1):
            ax2.plot(COUNTS, THESIS_SSD[technique][p], "x--", color=f"C{i}", alpha=0.5, label=f"Hahn 2012 {p} (SSD)")
        ax2.set_yscale("log")
        ax2.set_ylabel("Hahn 2012: SSD of intensity (dashed)", fontsize=8)
        if technique == "sii":
            h1, l1 = ax.get_legend_handles_labels()
            h2, l2 = ax2.get_legend_handles_labels()
            ax.legend(h1 + h2, l1 + l2, fontsize=6, ncol=2, loc="lower right")
    fig.suptitle("Interleaved against plain: bounce's rel_rms (solid, energy-correct) and the thesis's SSD (dashed)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)


def time_error_figure(grid, out):
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, technique in zip(axes, ("rsm", "sii")):
        curve = plain_curve(grid, technique)
        ax.plot([t for t, _ in curve], [e for _, e in curve], "o-", color="C0", label="plain, 16 ... 4096 VPLs")
        for i, p in enumerate(PATTERNS[1:], start=1):
            pts = [lookup(grid, technique, k, p) for k in COUNTS]
            ax.plot([r["timings_ms"]["total"] for r in pts], [r["error"]["rel_rms"] for r in pts], "o-",
                    color=f"C{i}", label=f"{p}, blurred, 64 ... 1024")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("total frame time, ms")
        ax.set_ylabel("rel_rms against the unoccluded reference")
        ax.set_title(NAMES[technique])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Speed against error on the Cornell box (512x384, CPU, 2 shared cores)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)


def tables(run):
    grid, targets = run["grid"], run["targets"]
    lines = [f"Generated by docs/studies/rsm_sii_figures.py from docs/results/rsm_sii.json, run `cornell-study` "
             f"(commit {run['provenance']['commit'][:10]}, {run['provenance']['date']}, {run['provenance']['cpu']}, "
             f"{run['provenance']['cores']} logical cores, shared with other builds). "
             f"{run['width']}x{run['height']}, {run['parameters']['maps']} maps of "
             f"{run['parameters']['rsm_resolution']}^2 texels, clamp {run['parameters']['clamp']:.4g}, "
             f"Each run's times are medians of --repeat frames (rsm_sii.sh: 3; one for the 4096-VPL runs).", ""]
    for technique in ("rsm", "sii"):
        lines += [f"### {NAMES[technique]}: total frame time, ms (Hahn 2012's seconds x 1000 in brackets)", "",
                  "| VPLs | " + " | ".join(p if p != "1x1" else "plain" for p in PATTERNS) + " |",
                  "|---|" + "---|" * len(PATTERNS)]
        for i, k in enumerate(COUNTS):
            cells = []
            for p in PATTERNS:
                t = lookup(grid, technique, k, p)["timings_ms"]["total"]
                thesis = THESIS_TIME[technique].get(p)
                cells.append(f"{t:.1f}" + (f" [{1000 * thesis[i]:.0f}]" if thesis else ""))
            lines.append(f"| {k} | " + " | ".join(cells) + " |")
        lines.append("")
        lines += [f"### {NAMES[technique]}: rel_rms against the unoccluded reference (plain) and against the plain "
                  f"image (interleaved; SSD of intensity in brackets, Hahn 2012's SSD after the slash)", "",
                  "| VPLs | plain vs reference | " + " | ".join(PATTERNS[1:]) + " |",
                  "|---|---|" + "---|" * (len(PATTERNS) - 1)]
        for i, k in enumerate(COUNTS):
            cells = [f"{lookup(grid, technique, k, '1x1')['error']['rel_rms']:.4f}"]
            for p in PATTERNS[1:]:
                e = lookup(grid, technique, k, p)["error"]["vs_plain"]
                cells.append(f"{e['rel_rms']:.4f} [{e['ssd_intensity']:.3g} / {THESIS_SSD[technique][p][i]:.4g}]")
            lines.append(f"| {k} | " + " | ".join(cells) + " |")
        lines.append("")
    thesis_weight = [(k, lookup(grid, "sii", k, "4x4", False)) for k in COUNTS + [4096]]
    thesis_weight = [(k, r) for k, r in thesis_weight if r]
    if thesis_weight:
        lines += ["### SII at 4x4 with the thesis's weight 1 (energy lost), for comparison", "",
                  "| VPLs | rel_rms vs plain | SSD vs plain | rel_rms vs reference |", "|---|---|---|---|"]
        for k, r in thesis_weight:
            e = r["error"]
            lines.append(f"| {k} | {e['vs_plain']['rel_rms']:.4f} | {e['vs_plain']['ssd_intensity']:.4g} | "
                         f"{e['rel_rms']:.4f} |")
        lines.append("")
    lines += ["### Equal time: each interleaved run against the plain curve at its own time", "",
              "The plain curve (16 ... 4096 VPLs) interpolated in log-log at the interleaved run's total time; "
              "'-' where the run is faster than the plain run with 16 VPLs.", "",
              "| technique | VPLs | pattern | ms | rel_rms | plain rel_rms at that time | plain with K/(NM) VPLs: ms, rel_rms |",
              "|---|---|---|---|---|---|---|"]
    for technique in ("rsm", "sii"):
        curve = plain_curve(grid, technique)
        for p in PATTERNS[1:]:
            for k in (256, 1024):
                r = lookup(grid, technique, k, p)
                t, e = r["timings_ms"]["total"], r["error"]["rel_rms"]
                at = interpolate_log(curve, t)
                n, m = map(int, p.split("x"))
                partner = lookup(grid, technique, k // (n * m), "1x1")
                ps = f"{partner['timings_ms']['total']:.1f}, {partner['error']['rel_rms']:.4f}" if partner else "-"
                lines.append(f"| {NAMES[technique]} | {k} | {p} | {t:.1f} | {e:.4f} | "
                             f"{'-' if at is None else f'{at:.4f}'} | {ps} |")
    lines.append("")
    lines += ["### The issue's targets, from this run", "", "```", json.dumps(
        {k: v for k, v in targets.items() if k != "equal_time"}, indent=1), "```", ""]
    refs = run.get("references", {})
    lines += [f"References: {refs.get('spp')} rays per pixel; measured noise of the unoccluded one "
              f"{refs.get('unoccluded_noise_rel_rms', float('nan')):.4f} rel_rms; the full (occluded) reference differs "
              f"from it by {refs.get('occluded_vs_unoccluded_rel_rms', float('nan')):.4f}.", ""]
    return "\n".join(lines)


def visibility_edges_table(path):
    """Issue 29's headline ratio for SII 4x4 with the blur: rays against the occluded reference
    over none against the unoccluded one (debiased rel_rms), the blur of geometry alone and with
    its visibility edges, from the runs rsm_visibility_study wrote (rsm_sii.sh visibility-edges)."""
    with open(path) as f:
        runs = [r for r in json.load(f)["runs"] if r["name"].startswith("visibility-edges-")]
    if not runs:
        return ""
    rows = {}
    for r in runs:
        for fr in r["frames"]:
            rows.setdefault((fr["scene"], fr["vpls"]), {})[(fr["config"], fr["visibility"])] = fr["rel_rms_debiased"]
    commits = sorted({r["provenance"]["commit"][:10] for r in runs})
    lines = ["### Issue 29: SII 4x4 with the blur, rays / none (debiased rel_rms, each against its reference)", "",
             f"Generated from docs/results/rsm_sii.json, runs `visibility-edges-*` (rsm_visibility_study, commit "
             f"{', '.join(commits)}; 256x256, seed 1, references 1024 / 512 rays a pixel in halves). "
             "The headline asks at most 1.2.", "",
             "| scene | VPLs | none | rays, geometry edges | ratio | rays, visibility edges | ratio |",
             "|---|---|---|---|---|---|---|"]
    for (scene, vpls) in sorted(rows):
        c = rows[(scene, vpls)]
        none = c.get(("4x4-blur", "none"))
        before, after = c.get(("4x4-blur-geometry-edges", "rays")), c.get(("4x4-blur", "rays"))
        if none is None or before is None or after is None:
            continue
        lines.append(f"| {scene} | {vpls} | {none:.4f} | {before:.4f} | {before / none:.2f} | {after:.4f} | "
                     f"{after / none:.2f} |")
    return "\n".join(lines + [""])


def main(argv):
    path = argv[1] if len(argv) > 1 else os.path.join(DOCS, "results", "rsm_sii.json")
    run = load_study(path)
    figures = os.path.join(DOCS, "figures")
    os.makedirs(figures, exist_ok=True)
    timing_figure(run["grid"], os.path.join(figures, "rsm_sii_timing.png"))
    accuracy_figure(run["grid"], os.path.join(figures, "rsm_sii_accuracy.png"))
    time_error_figure(run["grid"], os.path.join(figures, "rsm_sii_time_error.png"))
    with open(os.path.join(HERE, "rsm_sii_tables.md"), "w") as f:
        f.write("# RSM / SII / interleaved sampling: the study's tables\n\n" + tables(run) + "\n" +
                visibility_edges_table(path))
    print("wrote docs/figures/rsm_sii_{timing,accuracy,time_error}.png and docs/studies/rsm_sii_tables.md")


if __name__ == "__main__":
    main(sys.argv)
