#!/usr/bin/env python3
"""Runs docs/studies/benchmark_report.py on a fixture results file written here (two scenes, with
nulls, a failed technique, bounded and skipped speed-ups, missing optional keys) and checks the page
and figures: one technique table per scene, one PNG per scene under 300 KB linked from the page,
nulls shown as a dash, the speed-ups and times of the fixture on the page, the verdicts following
the speed-ups, and a results file without scenes refused.

Usage: check_benchmark_report.py REPORT_SCRIPT WORKDIR   (exit 77: matplotlib missing, skipped)

The fixture's numbers are made up to exercise the script; they are test data, never results.
"""
import json
import os
import re
import subprocess
import sys

try:
    import matplotlib  # noqa: F401
except ImportError:
    print("matplotlib is not installed (scripts/setup.sh installs python3-matplotlib): skipped")
    sys.exit(77)


def mc_sweep(scale):
    return [{"spp": s, "ms": 10.0 * s, "rel_rms": scale / s ** 0.5, "rel_rms_debiased": 0.98 * scale / s ** 0.5,
             "rel_rms_debiased_se": 0.001, "ssim": 1 - 0.5 / s ** 0.5} for s in (1, 2, 4, 8, 16, 32)]


def technique(name, quantity, ms, debiased, ssim, speedup_rms, speedup_ssim, **extra):
    t = {"technique": name, "quantity": quantity, "ms": ms, "parameters": {"a": 0.4}, "counts": {"records": 1234},
         "error": {"rel_rms": debiased * 1.1 if debiased is not None else None, "rel_rms_debiased": debiased,
                   "rel_rms_debiased_se": 0.002, "ssim": ssim},
         "mc_equal_error": {"rel_rms": {"spp": 37.2, "ms": ms * speedup_rms, "reached": True, "speedup": speedup_rms},
                            "ssim": {"spp": 12.0, "ms": ms * speedup_ssim, "reached": True, "speedup": speedup_ssim}}}
    t.update(extra)
    return t


FIXTURE = {
    "provenance": {"commit": "0123abc", "date": "2026-01-01T00:00:00+00:00", "cpu": "test CPU", "cores": 2,
                   "embree": "avx2", "command": "benchmark --quick",
                   "settings": {"width": 64, "height": 48, "quick": True,
                                "reference_spp": {"one_bounce": 64, "unoccluded": 64}}},
    "scenes": [
        {"scene": "cornell", "triangles": 36, "lights": 1, "bounds_diagonal": 9.5,
         "references": {"one_bounce": {"spp": 64, "ms": 0, "cached": True, "noise_rel_rms": 0.0123},
                        "unoccluded": {"spp": 64, "ms": 321.0, "cached": False, "noise_rel_rms": None}},
         "techniques": [
             technique("irradiance_cache", "one_bounce", 123.0, 0.045, 0.93, 6.5, 2.4),
             technique("rsm_gather", "one_bounce", 40.0, 0.33, 0.71, 0.61, 0.77,
                       error_unoccluded={"rel_rms": 0.12, "rel_rms_debiased": 0.111, "rel_rms_debiased_se": 0.003,
                                         "ssim": 0.88},
                       mc_equal_error_unoccluded={"rel_rms": {"spp": 2, "ms": 20.0, "reached": True, "speedup": 0.5,
                                                              "bound": "upper"},
                                                  "ssim": {"skipped": "no SSIM"}}),
             {"technique": "sii", "failed": "out of memory | at 4096 VPLs"},
         ],
         "monte_carlo": {"one_bounce": mc_sweep(0.9), "unoccluded": mc_sweep(0.7)}},
        {"scene": "dining room/v2", "triangles": 270000, "lights": 2, "bounds_diagonal": None,
         "references": {"one_bounce": {"spp": 64, "ms": 4567.0, "cached": False, "noise_rel_rms": 0.02}},
         "techniques": [
             technique("irradiance_cache", "one_bounce", 2500.0, 0.08, None, 0.8, 1.04),
             {"technique": "radiosity", "quantity": "all_bounces", "ms": 777.0,
              "counts": {"elements": 9966, "stopped_at_time_cap": False},
              "error": {"rel_rms": 0.5, "rel_rms_debiased": None, "rel_rms_debiased_se": None, "ssim": 0.5},
              "mc_equal_error": {"rel_rms": {"skipped": "the debiased error is not above 0"},
                                 "ssim": {"spp": 64, "ms": 640.0, "reached": False, "speedup": 3.3,
                                          "bound": "lower"}}},
             technique("sii_interleaved", "one_bounce", 50.0, 0.9, 0.5, 0.7, 0.2,
                       mc_equal_error={"rel_rms": {"spp": 32, "ms": 35.0, "reached": False, "speedup": 0.7,
                                                   "bound": "lower"},
                                       "ssim": {"spp": 1, "ms": 10.0, "reached": True, "speedup": 0.2,
                                                "bound": "upper"}}),
         ],
         "monte_carlo": {"one_bounce": mc_sweep(1.2), "all_bounces": []}},
    ],
}


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def main(script, workdir):
    os.makedirs(workdir, exist_ok=True)
    results = os.path.join(workdir, "benchmark.json")
    md = os.path.join(workdir, "docs", "benchmark.md")
    figures = os.path.join(workdir, "docs", "figures")
    for name in os.listdir(figures) if os.path.isdir(figures) else []:
        os.remove(os.path.join(figures, name))
    with open(results, "w") as f:
        json.dump(FIXTURE, f)
    run = subprocess.run([sys.executable, script, results, "--md", md, "--figures", figures],
                         capture_output=True, text=True, timeout=120)
    if run.returncode != 0:
        fail(f"the report script exited {run.returncode}: {run.stderr}")
    with open(md) as f:
        text = f.read()

    # One section and exactly one technique table per scene, in order.
    sections = re.split(r"^## Scene: ", text, flags=re.M)[1:]
    if len(sections) != len(FIXTURE["scenes"]):
        fail(f"{len(sections)} scene sections for {len(FIXTURE['scenes'])} scenes")
    for scene, section in zip(FIXTURE["scenes"], sections):
        if not section.startswith(scene["scene"]):
            fail(f"section {section.splitlines()[0]!r} where {scene['scene']!r} was expected")
        tables = re.findall(r"^\| technique \| quantity \|", section, flags=re.M)
        if len(tables) != 1:
            fail(f"{len(tables)} technique tables in the section of {scene['scene']}")
        rows = re.findall(r"^\| (irradiance_cache|rsm_gather|sii|sii_interleaved|radiosity) \|", section, flags=re.M)
        if len(rows) != len(scene["techniques"]):
            fail(f"{len(rows)} technique rows for {len(scene['techniques'])} techniques in {scene['scene']}")
        # The figure: linked, present, a PNG, under 300 KB.
        link = re.search(r"!\[[^\]]*\]\(([^)]+)\)", section)
        if not link:
            fail(f"no figure linked for {scene['scene']}")
        png = os.path.join(os.path.dirname(md), link.group(1))
        if not os.path.isfile(png):
            fail(f"figure {png} missing")
        with open(png, "rb") as f:
            if f.read(8) != b"\x89PNG\r\n\x1a\n":
                fail(f"{png} is not a PNG")
        if os.path.getsize(png) >= 300 * 1024:
            fail(f"{png} is {os.path.getsize(png)} bytes, over 300 KB")
    pngs = [n for n in os.listdir(figures) if n.startswith("benchmark-") and n.endswith(".png")]
    if len(pngs) != len(FIXTURE["scenes"]):
        fail(f"{len(pngs)} figures for {len(FIXTURE['scenes'])} scenes: {pngs}")

    # Figures of the fixture on the page, nulls as a dash, nothing unformatted.
    for needle in ("6.5x", "2.4x", "0.61x", "123 ms", "2.50 s", "0.0450 ± 0.0020", "0.930", "≥ 3.3x", "≤ 0.50x",
                   "0.1110 ± 0.0030", "failed: out of memory \\| at 4096 VPLs", "0123abc", "`benchmark --quick`",
                   "records 1234", "0.0123", "avx2", "1.04x", "stopped_at_time_cap false"):
        if needle not in text:
            fail(f"{needle!r} is not on the page")
    if re.search(r"\b(None|nan|NaN|inf|null)\b", text):
        fail("an unformatted null or non-finite value is on the page")
    dining = sections[1]
    radiosity_row = next(line for line in dining.splitlines() if line.startswith("| radiosity |"))
    if "—" not in radiosity_row or "skipped" not in radiosity_row:
        fail(f"radiosity's null error and skipped speed-up are not shown as such: {radiosity_row}")

    # The verdicts follow the speed-ups.
    paragraphs = text.split("## Where each technique pays", 1)
    if len(paragraphs) != 2:
        fail("no per-technique paragraphs")
    verdicts = paragraphs[1]
    ic = next(p for p in verdicts.split("\n\n") if p.startswith("**irradiance_cache**"))
    if not re.search(r"At equal rel_rms it beats its Monte Carlo baseline on cornell \(6\.5x\); it does not pay on dining room/v2 \(0\.80x\)", ic):
        fail(f"the cache's win on cornell is not stated: {ic}")
    rsm = next(p for p in verdicts.split("\n\n") if p.startswith("**rsm_gather**"))
    if "does not pay on any scene it ran on" not in rsm or "0.111" not in rsm:
        fail(f"the gather's paragraph misses its loss or its unoccluded error: {rsm}")
    sii = next(p for p in verdicts.split("\n\n") if p.startswith("**sii**"))
    if "failed on cornell" not in sii or "Not run on dining room/v2" not in sii:
        fail(f"the failed technique's paragraph: {sii}")
    interleaved = next(p for p in verdicts.split("\n\n") if p.startswith("**sii_interleaved**"))
    if ("At equal rel_rms it is not settled by the sweep on dining room/v2" not in interleaved
            or "the speed-up is at least 0.70x" not in interleaved
            or "At equal SSIM it does not pay on any scene it ran on: dining room/v2 (≤ 0.20x)" not in interleaved):
        fail(f"a bound on the far side of 1 is not reported as unsettled, or one on the near side as a loss: {interleaved}")
    if "generated from the numbers" not in verdicts:
        fail("no note that the paragraphs are generated")

    # A results file without scenes is refused with a message.
    bad = os.path.join(workdir, "no_scenes.json")
    with open(bad, "w") as f:
        json.dump({"provenance": {}}, f)
    run = subprocess.run([sys.executable, script, bad, "--md", os.path.join(workdir, "bad.md"),
                          "--figures", os.path.join(workdir, "bad")], capture_output=True, text=True, timeout=60)
    if run.returncode == 0 or "scenes" not in run.stderr:
        fail(f"a results file without scenes gave exit {run.returncode}: {run.stderr}")
    check_merge(script, workdir, results)
    print("benchmark report: page, tables, figures and verdicts as the fixture says; a merged run marked")


def check_merge(script, workdir, results):
    """benchmark_merge.py: a run of the cache alone replaces its rows, keeps its own sweep, is marked."""
    merge = os.path.join(os.path.dirname(script), "benchmark_merge.py")
    partial = {"provenance": dict(FIXTURE["provenance"], commit="4567def", command="benchmark --techniques x",
                                  machine_use={"wall_s": 12.0, "load_average_start": 3.5, "load_average_end": 4.5}),
               "scenes": [{"scene": "cornell",
                           "techniques": [technique("irradiance_cache", "one_bounce", 246.0, 0.021, 0.95, 9.25, 2.4)],
                           "monte_carlo": {"one_bounce": mc_sweep(0.5)}}]}
    part_path, merged = os.path.join(workdir, "partial.json"), os.path.join(workdir, "merged.json")
    with open(part_path, "w") as f:
        json.dump(partial, f)
    run = subprocess.run([sys.executable, merge, results, part_path, "--out", merged, "--note", "loaded machine"],
                         capture_output=True, text=True, timeout=60)
    if run.returncode != 0:
        fail(f"the merge exited {run.returncode}: {run.stderr}")
    with open(merged) as f:
        m = json.load(f)
    cache = m["scenes"][0]["techniques"][0]
    if cache.get("ms") != 246.0 or cache.get("merged_run") != 0 or len(cache.get("monte_carlo") or []) != 6:
        fail(f"the merged row is not the partial run's with its sweep: {cache}")
    if m["scenes"][0]["techniques"][1] != FIXTURE["scenes"][0]["techniques"][1] or \
            m["scenes"][1] != FIXTURE["scenes"][1] or m["scenes"][0]["monte_carlo"] != FIXTURE["scenes"][0]["monte_carlo"]:
        fail("the merge changed rows or sweeps of the base run")
    md = os.path.join(workdir, "merged", "benchmark.md")
    run = subprocess.run([sys.executable, script, merged, "--md", md, "--figures", os.path.join(workdir, "merged")],
                         capture_output=True, text=True, timeout=120)
    if run.returncode != 0:
        fail(f"the report script exited {run.returncode} on the merged file: {run.stderr}")
    with open(md) as f:
        text = f.read()
    for needle in ("| irradiance_cache † | one_bounce | 246 ms |", "9.2x", "merged run (irradiance_cache; rows marked †): "
                   "commit 4567def", "load average 3.50 -> 4.50; loaded machine", "† from a later run"):
        if needle not in text:
            fail(f"{needle!r} is not on the merged page")
    if "| irradiance_cache † | one_bounce | 2.50 s" in text:
        fail("the second scene's cache row, not in the partial run, is marked merged")
    # Runs of another size or reference are not merged.
    partial["provenance"]["settings"] = dict(partial["provenance"]["settings"], width=128)
    with open(part_path, "w") as f:
        json.dump(partial, f)
    run = subprocess.run([sys.executable, merge, results, part_path, "--out", merged], capture_output=True, text=True,
                         timeout=60)
    if run.returncode == 0 or "not comparable" not in run.stderr:
        fail(f"a run of another size was merged (exit {run.returncode}): {run.stderr}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
