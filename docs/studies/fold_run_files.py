#!/usr/bin/env python3
"""Folds the per-run report files the studies used to write (docs/data/*.json,
docs/data/hemisphere-turn/*.json, docs/hemisphere-sampling-*.json) into one results file per
study (docs/studies/results.py). Run once, from the repository root, before the old files
are removed; each run's commit and date are those of the last commit that wrote its file.
The runs did not record their machine: cpu, cores, gl_renderer and embree_isa are those of
the machine that folds them (the studies ran on 2-core machines without a GPU, OpenGL on
Mesa llvmpipe), and each folded run says so in provenance.source."""
import glob
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results  # noqa: E402


def last_commit(path):
    out = subprocess.run(["git", "log", "-1", "--format=%H %aI", "--", path], capture_output=True, text=True,
                         check=True).stdout.split()
    return (out[0], out[1]) if out else (None, None)


def uses_gl(report):
    p = report.get("parameters", {})
    return "gl" in report.get("backend", "") or p.get("interp") == "splat-gl" or p.get("sampler") == "raster"


def fold(study, files, name_of, target):
    model, cores, flags = results.cpu_model()
    runs = []
    for path in files:
        with open(path) as f:
            report = json.load(f)
        commit, date = last_commit(path)
        config = report.get("parameters", {}).get("embree_config", "")
        provenance = {"commit": commit, "date": date, "cpu": model, "cores": cores,
                      "gl_renderer": "llvmpipe" if uses_gl(report) else None,
                      "embree_isa": results.embree_isa(flags, config),
                      "source": f"{path}: cpu, cores, gl_renderer and embree_isa not recorded by the run; "
                                "those of the machine that folded it"}
        run = {"name": name_of(path), "provenance": provenance}
        run.update(report)
        runs.append(run)
    newest = max(runs, key=lambda r: r["provenance"]["date"] or "")
    results.save(target, {"study": study, "provenance": dict(newest["provenance"]), "runs": runs})
    print(f"{target}: {len(runs)} runs")


def stem(path):
    return os.path.splitext(os.path.basename(path))[0]


def main():
    fold("ic_splatting", sorted(glob.glob("docs/data/*.json")), stem, "docs/results/ic_splatting.json")
    fold("hemisphere_sampling", sorted(glob.glob("docs/hemisphere-sampling-*.json")),
         lambda p: stem(p)[len("hemisphere-sampling-"):], "docs/results/hemisphere_sampling.json")
    fold("hemisphere_turn", sorted(glob.glob("docs/data/hemisphere-turn/*.json")), stem,
         "docs/results/hemisphere_turn.json")


if __name__ == "__main__":
    main()
