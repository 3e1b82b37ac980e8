#!/usr/bin/env python3
"""Progressive radiosity, "shooting that scales" (issue 30; docs/radiosity.md section 7,
"Derived groups and the scaling plot").

    docs/studies/radiosity_scaling.py compare [--elements 10000 30000 100000] [--scenes ...]
    docs/studies/radiosity_scaling.py scaling [--elements 300000 1000000] [--max-seconds 1500]
    docs/studies/radiosity_scaling.py table        # the markdown tables of the doc
    docs/studies/radiosity_scaling.py plot         # docs/figures/radiosity_scaling.png

`compare`: every shared scene and the built-in Cornell box at each element count, ray casts
to 90% of the indirect power against the 64-path multi-bounce reference (the shared cache),
the grouped shooters with the budget derived from the scene (--shooter-groups -1, "derived")
and one shooter a block (--shooter-groups 0, "blocks"), run back to back (the machine is
shared: wall times of runs far apart do not compare). `scaling`: Sponza with the derived
groups only (no reference) at the larger counts; Sponza's 10k-100k points come from
`compare`. Each run is added to docs/results/radiosity_scaling.json (results.py: commit and
machine) with the load average before it (`load_before`): the seconds are those of a loaded
machine. The plot: time to 90% against elements on Sponza (both ways), shooting time per step
against elements, and steps to 90% against charts (every scene, both ways).
"""
import argparse
import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
RESULTS = os.path.join(ROOT, "docs", "results", "radiosity_scaling.json")
FIGURE = os.path.join(ROOT, "docs", "figures", "radiosity_scaling.png")
SCENES = ["cornell", "cornell-box", "bunny", "sponza", "conference", "living-room", "modern-hall"]
MODES = {"derived": "-1", "blocks": "0"}
PER_STEP = ("converged_fraction", "iteration_ms")  # left out of the results file


def run(name, scene, elements, mode, max_seconds, reference=True):
    binary = os.path.join(os.environ.get("BOUNCE_BIN", os.path.join(ROOT, "build", "bin")), "radiosity")
    out = os.path.join("/tmp", "radiosity_scaling")
    os.makedirs(out, exist_ok=True)
    report = os.path.join(out, name + ".json")
    load = os.getloadavg()
    cmd = [binary, "--scene", scene, "--elements", str(elements), "--visibility", "rays", "--converge", "0.9",
           "--curve-points", "0", "--shooter-groups", MODES[mode], "--max-seconds", str(max_seconds), "--quiet",
           "--json", report]
    cmd += ["--reference-paths", "64"] if reference else ["--reference", "off"]
    subprocess.run(["nice"] + cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    with open(report) as f:
        r = json.load(f)
    r["load_before"] = list(load)
    r["load_after"] = list(os.getloadavg())
    r["mode"] = mode
    for series in PER_STEP:  # thousands of numbers a run, which no table or plot here reads
        r.pop(series, None)
    results.add(RESULTS, "radiosity_scaling", name, r)
    print(row(r, name), flush=True)


def solve_ms(r):
    return r["timings_ms"]["reconstruction"] + r["timings_ms"]["shooter_choice"]


def row(r, name=None):
    e = r.get("error") or {}
    return (f"| {name or r['name']} | {r['elements']:,} | {r['charts']:,} | {r['shooters']:,} | {r['iterations']:,} | "
            f"{100 * (1 - r['indirect_unshot_fraction']):.1f}% ({r['stopped']}) | {solve_ms(r) / 1000:.1f} | "
            f"{r['timings_ms']['total'] / 1000:.1f} | {solve_ms(r) / max(r['iterations'], 1):.1f} | "
            + (f"{e['rel_rms']:.4f}" if 'rel_rms' in e else "-") + f" | {r['load_before'][0]:.1f} |")


def table():
    """The doc's tables: the pairs (derived against blocks), then Sponza's scaling."""
    runs = results.runs_by_name(RESULTS)
    print("| scene, elements | shooters derived / blocks | steps derived / blocks | solve s derived / blocks "
          "| ratio | rel_rms derived / blocks | load before |")
    print("|---|---|---|---|---|---|---|")
    for s in SCENES:
        for n in (10000, 30000, 100000):
            d, b = runs.get(f"derived-{s}-{n}"), runs.get(f"blocks-{s}-{n}")
            if not d or not b:
                continue
            ed, eb = (d.get("error") or {}).get("rel_rms"), (b.get("error") or {}).get("rel_rms")
            def cut(r):
                return "" if r["stopped"] == "converged" else f" (cut at {100 * (1 - r['indirect_unshot_fraction']):.1f}%)"
            print(f"| {s}, {d['elements']:,} | {d['shooters']:,} / {b['shooters']:,} | {d['iterations']:,}{cut(d)} / "
                  f"{b['iterations']:,}{cut(b)} | {solve_ms(d) / 1000:.1f} / {solve_ms(b) / 1000:.1f} | "
                  f"{solve_ms(d) / solve_ms(b):.2f} | {ed:.4f} / {eb:.4f} | {d['load_before'][0]:.0f}, "
                  f"{b['load_before'][0]:.0f} |")
    print()
    print("| Sponza, shooters | elements | shooters | steps | converged (indirect) | solve s | solve ms per step "
          "| load before |")
    print("|---|---|---|---|---|---|---|---|")
    for mode in ("derived", "blocks"):
        for n in (10000, 30000, 100000, 300000, 1000000):
            r = runs.get(f"{mode}-sponza-{n}")
            if r:
                print(f"| {mode} | {r['elements']:,} | {r['shooters']:,} | {r['iterations']:,} | "
                      f"{100 * (1 - r['indirect_unshot_fraction']):.1f}% ({r['stopped']}) | {solve_ms(r) / 1000:.1f} | "
                      f"{solve_ms(r) / max(r['iterations'], 1):.0f} | {r['load_before'][0]:.0f} |")
    print()
    print("Repeated pairs (run in turn, the -rK suffix):")
    for name, r in runs.items():
        if re.search(r"-r[0-9]+$", name):
            print(f"  {name}: {solve_ms(r) / 1000:.1f} s, {r['iterations']} steps, {r['shooters']} shooters")


def plot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    runs = [r for r in results.load(RESULTS)["runs"] if re.fullmatch(r"(derived|blocks)-[a-z-]+-[0-9]+", r["name"])]
    fig, ax = plt.subplots(1, 3, figsize=(13, 4))
    for mode, colour in (("derived", "tab:blue"), ("blocks", "tab:red")):
        sp = sorted((r for r in runs if r["scene"] == "sponza" and r["mode"] == mode), key=lambda r: r["elements"])
        if sp:
            x = [r["elements"] for r in sp]
            ax[0].plot(x, [solve_ms(r) / 1000 for r in sp], "o-", color=colour, label=f"Sponza, {mode}")
            ax[1].plot(x, [solve_ms(r) / r["iterations"] for r in sp], "o-", color=colour, label=f"Sponza, {mode}")
            for r in sp:
                if r["stopped"] != "converged":
                    ax[0].annotate(f"cut at {100 * (1 - r['indirect_unshot_fraction']):.0f}%", (r["elements"], solve_ms(r) / 1000),
                                   fontsize=7)
        other = [r for r in runs if r["mode"] == mode and r["stopped"] == "converged"]
        ax[2].scatter([r["charts"] for r in other], [r["iterations"] for r in other], color=colour, s=14,
                      label=f"{mode} (every scene and count, converged runs)")
    x = sorted({r["elements"] for r in runs if r["scene"] == "sponza"})
    if x:
        ax[1].plot(x, [x0 / x[0] * min(solve_ms(r) / r["iterations"] for r in runs if r["scene"] == "sponza"
                                       and r["elements"] == x[0] and r["mode"] == "derived") for x0 in x],
                   ":", color="grey", label="linear in elements")
    for a, title, ylabel in ((ax[0], "time to 90% (indirect), Sponza", "solve s (loaded machine)"),
                             (ax[1], "cost per step, Sponza", "solve ms per step (loaded machine)"),
                             (ax[2], "steps to 90% against charts", "steps")):
        a.set_xscale("log")
        a.set_yscale("log")
        a.set_title(title, fontsize=10)
        a.set_ylabel(ylabel)
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize=7)
    ax[0].set_xlabel("elements")
    ax[1].set_xlabel("elements")
    ax[2].set_xlabel("charts")
    fig.tight_layout()
    os.makedirs(os.path.dirname(FIGURE), exist_ok=True)
    fig.savefig(FIGURE, dpi=80)
    print(FIGURE, os.path.getsize(FIGURE), "bytes")


def main(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("what", choices=["compare", "scaling", "table", "plot"])
    p.add_argument("--elements", type=int, nargs="+")
    p.add_argument("--scenes", nargs="+", default=SCENES)
    p.add_argument("--max-seconds", type=float, default=300)
    a = p.parse_args(argv)
    if a.what == "compare":
        for n in a.elements or [10000, 30000, 100000]:
            for s in a.scenes:
                for mode in ("derived", "blocks"):
                    run(f"{mode}-{s}-{n}", s, n, mode, a.max_seconds)
    elif a.what == "scaling":
        for n in a.elements or [300000, 1000000]:
            run(f"derived-sponza-{n}", "sponza", n, "derived", a.max_seconds, reference=False)
    elif a.what == "table":
        table()
    else:
        plot()


if __name__ == "__main__":
    main(sys.argv[1:])
