#!/usr/bin/env python3
"""Issue 29's headline table: every scene x {RSM gather, SII plain, SII 4x4 with the blur} x
{256, 1024, 4096} VPLs (disc samples per map for the gather), each frame without visibility
against the unoccluded one-bounce reference and with occlusion rays against the occluded one,
both debiased (rsm_visibility_study: the benchmark's references in halves and its error
measure, rsm_sii's defaults, 256x256), and their ratio (the headline asks at most 1.2).

    docs/studies/rsm_visibility_table.py run [--seeds 1,2] [--counts 256,1024,4096] [--scenes ...] [--configs ...]
    docs/studies/rsm_visibility_table.py table

`complete` prints the 4x4 frames before and with their isolated pixels completed (runs made
with `run --prefix complete --configs 4x4-blur,4x4-blur-complete`). `run` runs the study once
per count and seed (all scenes and the three configurations in one
process) and adds each report to docs/results/rsm_visibility_table.json (docs/studies/results.py,
with its commit and machine); `table` prints the markdown table from that file: seed 1's
cells, as the earlier sections report them, and over the seeds measured the mean of each
error and the ratio of the means (a single seed's error is one draw of a heavy-tailed
estimate at few VPLs, docs/rsm-sii-interleaved.md section 15.4). BIN=DIR/bin for another build folder,
RUNS=DIR for the raw reports (default build/runs). Needs BOUNCE_CACHE and BOUNCE_SCENES as
the benchmark does; the references are computed once and cached.
"""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
RESULTS = os.path.join(ROOT, "docs", "results", "rsm_visibility_table.json")
SCENES = ["cornell", "cornell-box", "bunny", "sponza", "conference", "living-room", "modern-hall"]
CONFIGS = [("gather", "RSM gather"), ("plain-footprint", "SII plain"), ("4x4-blur", "SII 4x4 blur")]
LIMIT = 1.2


def run(args):
    binary = os.path.join(os.environ.get("BIN", os.path.join(ROOT, "build", "bin")), "rsm_visibility_study")
    runs = os.environ.get("RUNS", os.path.join(ROOT, "build", "runs"))
    os.makedirs(runs, exist_ok=True)
    for count in args.counts.split(","):
        for seed in args.seeds.split(","):
            name = f"{args.prefix}-{count}-seed{seed}" + ("" if args.scenes == ",".join(SCENES) else "-" + args.scenes)
            configs = args.configs
            out = os.path.join(runs, name + ".json")
            load = open("/proc/loadavg").read().split()[0]
            subprocess.run([binary, "--scenes", args.scenes, "--vpls", count, "--seed", seed, "--configs",
                            configs, "--json", out], check=True)
            with open(out) as f:
                report = json.load(f)
            report["load_average_before"] = float(load)
            with open(out, "w") as f:
                json.dump(report, f, indent=2)
            subprocess.run([sys.executable, os.path.join(HERE, "results.py"), "add", RESULTS, name, out], check=True)


def cells():
    """{(scene, config, vpls): {seed: {"rays": err, "none": err}}} from the results file."""
    with open(RESULTS) as f:
        study = json.load(f)
    out = {}
    for r in study["runs"]:
        seed = r["parameters"]["seed"]
        for fr in r["frames"]:
            key = (fr["scene"], fr["config"], fr["vpls"])
            out.setdefault(key, {}).setdefault(seed, {})[fr["visibility"]] = fr["rel_rms_debiased"]
    return out


def cell_text(seeds):
    def fmt(rays, none):
        ratio = rays / none if none > 0 else float("inf")
        mark = "**" if ratio > LIMIT else ""
        return f"{rays:.3f} / {none:.3f} = {mark}{ratio:.2f}{mark}"
    first = seeds.get(1)
    text = fmt(first["rays"], first["none"]) if first and "rays" in first and "none" in first else "-"
    both = [s for s in seeds.values() if "rays" in s and "none" in s]
    if len(both) > 1:
        rays = sum(s["rays"] for s in both) / len(both)
        none = sum(s["none"] for s in both) / len(both)
        text += f"; mean of {len(both)}: {fmt(rays, none)}"
    return text


def table(_args):
    c = cells()
    counts = sorted({k[2] for k in c})
    print("| scene | technique | " + " | ".join(str(n) for n in counts) + " |")
    print("|---|---|" + "---|" * len(counts))
    for scene in SCENES:
        for config, label in CONFIGS:
            row = []
            for n in counts:
                seeds = c.get((scene, config, n), {})
                row.append(cell_text(seeds) if seeds else "-")
            print(f"| {scene} | {label} | " + " | ".join(row) + " |")


def complete_table(_args):
    """Interleaved SII 4x4 with the blur, before -> with the isolated pixels completed
    (rsm_visibility_study's 4x4-blur-complete, runs named complete-*), seed 1."""
    c = cells()
    print("| scene | VPLs | none | rays | ratio | ms none, rays (loaded machine) |")
    print("|---|---|---|---|---|---|")
    with open(RESULTS) as f:
        times = {(fr["scene"], fr["config"], fr["vpls"], fr["visibility"]): fr["ms_loaded_machine"]
                 for r in json.load(f)["runs"] if r["name"].startswith("complete-") for fr in r["frames"]}
    for scene in SCENES:
        for n in sorted({k[2] for k in c if k[1] == "4x4-blur-complete"}):
            a, b = c.get((scene, "4x4-blur", n), {}).get(1), c.get((scene, "4x4-blur-complete", n), {}).get(1)
            if not a or not b:
                continue
            t = {(k, v): times.get((scene, k, n, v), float("nan")) for k in ("4x4-blur", "4x4-blur-complete")
                 for v in ("none", "rays")}
            print(f"| {scene} | {n} | {a['none']:.3f} -> {b['none']:.3f} | {a['rays']:.3f} -> {b['rays']:.3f} | "
                  f"{a['rays'] / a['none']:.2f} -> {b['rays'] / b['none']:.2f} | "
                  f"{t['4x4-blur', 'none']:.0f} -> {t['4x4-blur-complete', 'none']:.0f}, "
                  f"{t['4x4-blur', 'rays']:.0f} -> {t['4x4-blur-complete', 'rays']:.0f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("--seeds", default="1")
    r.add_argument("--counts", default="256,1024,4096")
    r.add_argument("--scenes", default=",".join(SCENES))
    r.add_argument("--configs", default=",".join(c for c, _ in CONFIGS))
    r.add_argument("--prefix", default="table", help="run names PREFIX-COUNT-seedS (complete: the completion's runs)")
    r.set_defaults(func=run)
    t = sub.add_parser("table")
    t.set_defaults(func=table)
    sub.add_parser("complete").set_defaults(func=complete_table)
    args = p.parse_args()
    args.func(args)


if __name__ == "__main__":
    main()
