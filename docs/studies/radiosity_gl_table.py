#!/usr/bin/env python3
"""Prints the table of docs/radiosity-gl.md section 4 from docs/results/radiosity_gl.json:
per configuration, the GL and CPU runs (same process, same atlas) to 90% convergence, their
stage times, the GL run without the per-stage glFinish, and the GL / CPU ratio of the totals
(stage-timed GL against the CPU).

    python3 docs/studies/radiosity_gl_table.py [docs/results/radiosity_gl.json]
"""
import json
import sys


def main(path):
    with open(path) as f:
        runs = {r["name"]: r for r in json.load(f)["runs"]}
    def order(name):  # cornell-stereo-b4-r128: visibility, then blocks, then resolution
        parts = name.split("-")
        return (parts[0] != "cornell", "hemicube" in name, int(parts[-2][1:]), int(parts[-1][1:]))

    configs = sorted({n.split("-r")[0] + "-r" + n.split("-r")[1].split("-")[0] for n in runs}, key=order)
    print("| scene | visibility | blocks | buffer | shots | GL total (visibility / choice / distribution) | "
          "GL total, one wait per step | CPU total (visibility / choice / distribution) | GL / CPU | "
          "GL vs CPU solution (rel. L1) | load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for c in configs:
        gl, cpu, untimed = runs.get(c + "-gl"), runs.get(c + "-cpu"), runs.get(c + "-gl-untimed")
        if not gl or not cpu:
            continue
        p = gl["parameters"]

        def stages(r):
            t = r["timings_ms"]
            return "%.0f ms (%.0f / %.0f / %.0f)" % (t["total"], t["visibility"], t["shooter_choice"],
                                                    t["distribution"])

        load = p.get("load_average")
        versus = p.get("relative_l1_versus_cpu")
        print("| %s | %s | %d x %d | %d^2%s | %d | %s | %s | %s | %.2f | %s | %s |" % (
            gl["scene"], p["visibility"], p["block_texels"], p["block_texels"], p["resolution"],
            " per face" if p["visibility"] == "hemicube" else "", gl["iterations"], stages(gl),
            "%.0f ms" % untimed["timings_ms"]["total"] if untimed else "-", stages(cpu),
            gl["timings_ms"]["total"] / cpu["timings_ms"]["total"], "%.1e" % versus if versus is not None else "-",
            "%.1f" % load if load is not None else "-"))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/results/radiosity_gl.json")
