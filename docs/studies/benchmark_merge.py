#!/usr/bin/env python3
"""Merge a benchmark run of some techniques into a results file of a fuller run.

    docs/studies/benchmark_merge.py docs/results/benchmark.json /tmp/bench-cache.json \\
        --note "loaded machine: load average 12-17 on 2 shared cores"

`build/bin/benchmark --techniques irradiance_cache --json partial.json` re-runs one family in
minutes where the whole benchmark takes about an hour. Each technique entry of the partial
run (matched by scene name, technique and visibility) replaces the base file's, and keeps
what its speed-ups were read against: its run's Monte Carlo sweep of its quantity (the
entry's `monte_carlo`, the scene's sweep staying the base run's for the other techniques)
and its run (`merged_run`: the index in the base file's provenance `merged`, which lists
each merged run's commit, date, command, settings, machine use, the note and its entries). The sizes and reference sample counts of
the two runs must be the same (the errors are against references of one size and noise).
benchmark_report.py marks merged rows and draws their own sweep.
"""
import argparse
import json
import sys


def key(t):
    return (t.get("technique"), t.get("visibility") or "none")


def same_setup(base, part):
    b, p = base.get("settings") or {}, part.get("settings") or {}
    return all(b.get(k) == p.get(k) for k in ("width", "height", "reference_spp", "mc_max_spp", "quick"))


def merge(base, part, note):
    bprov, pprov = base.get("provenance") or {}, part.get("provenance") or {}
    if not same_setup(bprov, pprov):
        sys.exit("benchmark_merge: the runs differ in size, reference or Monte Carlo samples: not comparable")
    run = {k: pprov.get(k) for k in ("commit", "date", "cpu", "cores", "embree", "command", "settings",
                                     "machine_use")}
    if note:
        run["note"] = note
    scenes = {s.get("scene"): s for s in base.get("scenes") or []}
    merged = bprov.setdefault("merged", [])
    replaced = []
    for ps in part.get("scenes") or []:
        bs = scenes.get(ps.get("scene"))
        if bs is None:
            sys.exit(f"benchmark_merge: scene {ps.get('scene')} is not in the base file")
        for t in ps.get("techniques") or []:
            entry = dict(t)
            entry["merged_run"] = len(merged)
            sweep = (ps.get("monte_carlo") or {}).get(t.get("quantity"))
            if sweep is not None:
                entry["monte_carlo"] = sweep
            old = [i for i, bt in enumerate(bs.get("techniques") or []) if key(bt) == key(t)]
            if old:
                bs["techniques"][old[0]] = entry
            else:
                bs.setdefault("techniques", []).append(entry)
            replaced.append(f"{ps.get('scene')}/{t.get('technique')}")
    merged.append(dict(run, entries=replaced))
    return base


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("base", help="the fuller run's results file (rewritten unless --out)")
    parser.add_argument("partial", help="the run of some techniques")
    parser.add_argument("--out", help="where to write the merged file (default: base)")
    parser.add_argument("--note", default="", help="said of the partial run (e.g. the machine's load)")
    args = parser.parse_args(argv)
    with open(args.base) as f:
        base = json.load(f)
    with open(args.partial) as f:
        part = json.load(f)
    out = merge(base, part, args.note)
    with open(args.out or args.base, "w") as f:
        f.write(json.dumps(out, indent=2, ensure_ascii=False) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
