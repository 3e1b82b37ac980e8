#!/usr/bin/env python3
"""One results file per study: docs/results/<study>.json holds

    {"study": "ic_splatting",
     "provenance": {"commit", "date", "cpu", "cores", "gl_renderer", "embree_isa"},
     "runs": [{"name": "cornell-a0.4", "provenance": {...the same keys}, ...the run's report}]}

Each run keeps the provenance of the commit and machine that wrote it, since a study's runs
are often re-measured one at a time; the study's provenance is that of its newest run. The
study scripts add each run with

    python3 docs/studies/results.py add docs/results/ic_splatting.json NAME RUN.json

which replaces a run of the same name (keeping the order of the others) and records the
machine it ran on: CPU model and logical cores from /proc/cpuinfo, the GL renderer
(`--gl-renderer`, else the report's own `gl_renderer`, which programs that ran GL write,
else $BOUNCE_GL_RENDERER, else the renderer `eglinfo -B` names, else null), and the Embree ISA (the run's pinned `embree_config`, else the widest of AVX-512,
AVX2, SSE4.2 the CPU has: Embree's own choice). Scripts that read the file
(docs/make_report.py, docs/plot_hemisphere_sampling.py, docs/studies/hemisphere_turn_table.py)
use `load(path)` or read the JSON directly.
"""
import argparse
import datetime
import json
import os
import re
import shutil
import subprocess
import sys


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            text = f.read()
    except OSError:
        return None, None, ""
    model = re.search(r"^model name\s*:\s*(.+)$", text, re.M)
    cores = len(re.findall(r"^processor\s*:", text, re.M)) or None
    flags = re.search(r"^flags\s*:\s*(.+)$", text, re.M)
    return (model.group(1).strip() if model else None), cores, (flags.group(1) if flags else "")


def embree_isa(flags, config):
    """The kernels Embree runs: those a pinned configuration names, else the CPU's widest."""
    pinned = re.search(r"max_isa\s*=\s*([A-Za-z0-9_.]+)", config or "")
    if pinned:
        return pinned.group(1) + " (pinned)"
    have = set(flags.split())
    for flag, isa in (("avx512f", "avx512"), ("avx2", "avx2"), ("sse4_2", "sse4.2")):
        if flag in have:
            return isa
    return "sse2"


def gl_renderer(given, report):
    if given:
        return given
    if report.get("gl_renderer"):
        return report["gl_renderer"]
    if os.environ.get("BOUNCE_GL_RENDERER"):
        return os.environ["BOUNCE_GL_RENDERER"]
    if shutil.which("eglinfo"):
        try:
            out = subprocess.run(["eglinfo", "-B"], capture_output=True, text=True, timeout=20).stdout
            m = re.search(r"OpenGL core profile renderer:\s*(.+)", out) or re.search(r"renderer:\s*(.+)", out)
            if m:
                return m.group(1).strip()
        except (OSError, subprocess.SubprocessError):
            pass
    return None


def git_head():
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=True,
                              cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def load(path):
    """The results file as a dict; its runs in the order they were added."""
    with open(path) as f:
        return json.load(f)


def runs_by_name(path):
    """{name: run} in the file's order."""
    return {r["name"]: r for r in load(path)["runs"]}


def monte_carlo_at_equal_error(r):
    """(ratio, spp, extrapolated) of Monte Carlo at the cache's debiased error, from a row of
    docs/studies/ic_image_size.py run with --mc-compare (None without one). Where the sweep
    (--mc-max-spp) did not reach the cache's error (`lower_bound`), spp and time are
    extrapolated from its last run with the debiased error falling as spp^-1/2 (exact for
    independent samples: the reference's noise is taken out of the error), spp' = spp (e /
    target)^2 and time in proportion; the ratio is against the cache run's total time."""
    m = r.get("mc_equal_error") or {}
    if "speedup" not in m:
        return None
    if not m.get("lower_bound"):
        return m["speedup"], m["spp"], False
    scale = (m["measured_rel_rms"] / m["rel_rms"]) ** 2
    return m["measured_ms"] * scale / r["total_ms_loaded_machine"], m["measured_spp"] * scale, True


def monte_carlo_rays_ratio(r, spp):
    """Monte Carlo's rays at `spp` over the cache's, which the machine's load does not move:
    spp times the pixels against the records' 1,026 rays each plus, with --verify, the probes'
    8 rays on half the pixels (an upper bound: pixels that see nothing are not probed)."""
    w, h = (int(v) for v in r["size"].split("x"))
    cache = r["records"] * 1026 + (w * h // 2 * 8 if "verify_tiles" in r else 0)
    return spp * w * h / cache


def dumps(value, depth=0):
    """JSON with one key per line, but a list of plain values (a per-iteration series) on one
    line: a study's curves stay readable in a diff without a line per number."""
    pad = " " * (depth + 1)
    if isinstance(value, dict) and value:
        items = (f"{pad}{json.dumps(k)}: {dumps(v, depth + 1)}" for k, v in value.items())
        return "{\n" + ",\n".join(items) + "\n" + " " * depth + "}"
    if isinstance(value, list) and value and any(isinstance(v, (dict, list)) for v in value):
        return "[\n" + ",\n".join(pad + dumps(v, depth + 1) for v in value) + "\n" + " " * depth + "]"
    return json.dumps(value, separators=(",", ":"))


def save(path, results):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(dumps(results))
        f.write("\n")
    os.replace(tmp, path)


def add(path, study, name, report, renderer=None, commit=None, date=None):
    """Adds (or replaces) run `name` of `report` (a run report dict) in the results file."""
    results = load(path) if os.path.exists(path) else {"study": study, "provenance": {}, "runs": []}
    if results.get("study") != study:
        sys.exit(f"{path} holds study {results.get('study')!r}, not {study!r}")
    model, cores, flags = cpu_model()
    commit = commit or git_head()
    date = date or datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    config = report.get("parameters", {}).get("embree_config", "")
    provenance = {"commit": commit, "date": date, "cpu": model, "cores": cores,
                  "gl_renderer": gl_renderer(renderer, report), "embree_isa": embree_isa(flags, config)}
    run = {"name": name, "provenance": provenance}
    run.update({k: v for k, v in report.items() if k not in ("name", "provenance")})
    runs = results["runs"]
    at = next((i for i, r in enumerate(runs) if r["name"] == name), None)
    if at is None:
        runs.append(run)
    else:
        runs[at] = run
    results["provenance"] = provenance
    save(path, results)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    a = sub.add_parser("add", help="add one run report to a results file")
    a.add_argument("results", help="docs/results/<study>.json")
    a.add_argument("name", help="the run's name, unique in the study")
    a.add_argument("report", help="the --json report the run wrote")
    a.add_argument("--study", help="study name (default: the file's, or its stem when the file is new)")
    a.add_argument("--gl-renderer", help="GL renderer string of the run's context")
    args = parser.parse_args(argv)
    with open(args.report) as f:
        report = json.load(f)
    study = args.study or (load(args.results)["study"] if os.path.exists(args.results)
                           else os.path.splitext(os.path.basename(args.results))[0])
    add(args.results, study, args.name, report, renderer=args.gl_renderer)


if __name__ == "__main__":
    main(sys.argv[1:])
