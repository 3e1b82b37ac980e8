#!/usr/bin/env python3
"""Tables and plots of docs/radiosity.md from docs/results/radiosity.json (written by
docs/studies/radiosity.sh): prints the Markdown tables, and draws

  docs/figures/radiosity_convergence.png  unshot fraction and error against time (run cornell-curve)
  docs/figures/radiosity_adaptive.png     error against elements, uniform and adaptive
  docs/figures/radiosity_sponza_scaling.png  Sponza: time per iteration and memory against elements

Usage: docs/studies/radiosity_figures.py [docs/results/radiosity.json]
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
figures = os.path.join(here, "..", "figures")


def runs(path):
    with open(path) as f:
        return {r["name"]: r for r in json.load(f)["runs"]}


def ms(run, stage):
    return run["timings_ms"].get(stage, float("nan"))


def err(run):
    return run.get("error", {}).get("rel_rms", float("nan"))


def versus(run):
    return run.get("versus", {}).get("rel_rms", float("nan"))


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "results", "radiosity.json")
    r = runs(path)

    print("### Cornell box, about 10,000 elements, to 90% (medians of the repeats)\n")
    print("| run | backend | elements | iterations | total ms | visibility ms | reconstruction ms | choice ms | rel_rms vs reference | rel_rms vs rays |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in ["cornell-rays", "cornell-stereo-128", "cornell-hemicube-128", "cornell-gl-stereo-128"]:
        if name not in r:
            continue
        x = r[name]
        print(f"| {name} | {x['backend']} | {x['elements']} | {x['iterations']} | {ms(x, 'total'):.0f} | "
              f"{ms(x, 'visibility'):.0f} | {ms(x, 'reconstruction'):.0f} | {ms(x, 'shooter_choice'):.1f} | "
              f"{err(x):.4f} | {versus(x):.4f} |")

    print("\n### Item buffers against ray-cast visibility (10,000 elements, 90%)\n")
    print("| run | resolution | tolerance px | total ms | visibility ms | rel_rms vs rays | rel_rms vs reference |")
    print("|---|---|---|---|---|---|---|")
    for name, x in r.items():
        if not (name.startswith("cornell-stereo") or name.startswith("cornell-hemicube")):
            continue
        p = x["parameters"]
        print(f"| {name} | {p['resolution']} | {p['tolerance_px'] if p['visibility'] == 'stereo' else '-'} | "
              f"{ms(x, 'total'):.0f} | {ms(x, 'visibility'):.0f} | {versus(x):.4f} | {err(x):.4f} |")

    print("\n### Adaptive against uniform elements (ray-cast visibility, 99%)\n")
    print("| run | block | elements | base elements | rel_rms | total ms |")
    print("|---|---|---|---|---|---|")
    series = {}
    for name, x in r.items():
        if not (name.startswith("cornell-uniform") or name.startswith("cornell-adaptive")):
            continue
        p = x["parameters"]
        print(f"| {name} | {p['block']} | {x['elements']} | {x['elements_base']} | {err(x):.4f} | {ms(x, 'total'):.0f} |")
        key = ("adaptive" if p["adaptive"] == "on" else "uniform", p["block"])
        series.setdefault(key, []).append((x["elements"], err(x)))
    if series:
        fig, ax = plt.subplots(figsize=(5.5, 3.6), dpi=100)
        for (kind, block), pts in sorted(series.items()):
            pts.sort()
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-" if kind == "uniform" else "s--",
                    label=f"{kind}, blocks of {block}x{block}")
        ax.set_xscale("log")
        ax.set_xlabel("elements")
        ax.set_ylabel("rel_rms against the multi-bounce reference")
        ax.set_title("Cornell box, ray-cast visibility, 99% converged", fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(figures, "radiosity_adaptive.png"))

    if "cornell-curve" in r:
        c = r["cornell-curve"]["convergence"]
        fig, ax = plt.subplots(figsize=(5.5, 3.6), dpi=100)
        t = [p["time_ms"] / 1000 for p in c]
        ax.plot(t, [p["unshot_fraction"] for p in c], "o-", label="unshot fraction")
        ax.plot(t, [p["rel_rms"] for p in c], "s-", label="rel_rms against the reference")
        ax.set_yscale("log")
        ax.set_xlabel("solve time, s (shared 2-core machine)")
        ax.set_title("Cornell box, 10,000 elements, stereographic 128^2", fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(os.path.join(figures, "radiosity_convergence.png"))
        print("\n### Convergence curve (cornell-curve)\n")
        print("| step | time ms | unshot fraction | rel_rms |")
        print("|---|---|---|---|")
        for p in c:
            print(f"| {p['step']} | {p['time_ms']:.0f} | {p['unshot_fraction']:.4f} | {p['rel_rms']:.4f} |")

    sponza = sorted((x for n, x in r.items() if n.startswith("sponza-")), key=lambda x: (x["parameters"]["visibility"], x["elements"]))
    if sponza:
        print("\n### Sponza to 95%\n")
        print("| run | elements | charts | iterations | converged | total s | ms per iteration | visibility ms | reconstruction ms | peak RSS MB |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for x in sponza:
            print(f"| {x['name']} | {x['elements']} | {x['charts']} | {x['iterations']} | {1 - x['unshot_fraction']:.3f} | "
                  f"{ms(x, 'total') / 1000:.1f} | {x['ms_per_iteration']:.1f} | {ms(x, 'visibility'):.0f} | "
                  f"{ms(x, 'reconstruction'):.0f} | {x['peak_rss_mb']:.0f} |")
        rays = [x for x in sponza if x["parameters"]["visibility"] == "rays"]
        fig, ax = plt.subplots(figsize=(5.5, 3.6), dpi=100)
        e = [x["elements"] for x in rays]
        ax.plot(e, [x["ms_per_iteration"] for x in rays], "o-", label="ms per iteration")
        ax.plot(e, [x["peak_rss_mb"] for x in rays], "s-", label="peak memory, MB")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("elements")
        ax.set_title("Sponza, ray-cast visibility, to 95%", fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3, which="both")
        fig.tight_layout()
        fig.savefig(os.path.join(figures, "radiosity_sponza_scaling.png"))


if __name__ == "__main__":
    main()
