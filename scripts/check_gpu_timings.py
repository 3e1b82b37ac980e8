#!/usr/bin/env python3
"""Checks a gpu_timings results file (docs/gpu-timings.md): the GL strings and provenance are
there, and every pass of the fixed set is present, once, with positive times.

    scripts/check_gpu_timings.py RESULTS.json [--sizes 1920x1080,512x512] [--markdown]

Prints one line per problem and exits 1 when there is any, 0 otherwise. --markdown prints,
for a well-formed file, the table docs/gpu-timings.md shows (median, min-max, host clock)."""
import argparse
import json
import math
import sys

SCENE_PASSES = ["rsm_maps", "radiosity_shot", "radiosity_shot_unoccluded", "radiosity_item_buffer",
                "hemisphere_raster"]
IMAGE_PASSES = ["gbuffer", "direct_light", "ic_splat", "ic_normalize", "rsm_gather", "rsm_gather_8x8", "sii",
                "sii_8x8", "volume_lookup"]
METHODS = {"gl_timestamp", "wall_clock_finish"}


def positive(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x > 0


def check_pass(where, p, problems):
    name = p.get("name", "?")
    if p.get("method") not in METHODS:
        problems.append(f"{where} {name}: method {p.get('method')!r} is none of {sorted(METHODS)}")
    samples = p.get("samples_ms")
    if not isinstance(samples, list) or not samples or len(samples) != p.get("repetitions"):
        problems.append(f"{where} {name}: samples_ms does not hold `repetitions` figures")
        return
    for key in ("median_ms", "min_ms", "max_ms"):
        if not positive(p.get(key)):
            problems.append(f"{where} {name}: {key} is {p.get(key)!r}, not a positive number")
    if not all(positive(s) for s in samples):
        problems.append(f"{where} {name}: a repetition's time is not positive: {samples}")
    elif not (p["min_ms"] <= p["median_ms"] <= p["max_ms"]) or p["min_ms"] != min(samples) or p["max_ms"] != max(samples):
        problems.append(f"{where} {name}: min/median/max disagree with samples_ms")
    if not isinstance(p.get("covers"), str) or not p["covers"]:
        problems.append(f"{where} {name}: no `covers` text")


def check_passes(where, passes, expected, problems):
    if not isinstance(passes, list):
        problems.append(f"{where}: no list of passes")
        return
    names = [p.get("name") for p in passes]
    for name in expected:
        if names.count(name) != 1:
            problems.append(f"{where}: pass {name} appears {names.count(name)} times, expected once")
    for name in names:
        if name not in expected:
            problems.append(f"{where}: unexpected pass {name}")
    for p in passes:
        check_pass(where, p, problems)


def check(results, sizes):
    problems = []
    gl = results.get("gl", {})
    for key in ("vendor", "renderer", "version"):
        if not isinstance(gl.get(key), str) or not gl[key].strip():
            problems.append(f"gl.{key} is missing or empty")
    prov = results.get("provenance", {})
    for key in ("commit", "date", "build_type"):
        if not isinstance(prov.get(key), str) or not prov[key]:
            problems.append(f"provenance.{key} is missing or empty")
    check_passes("scene_passes", results.get("scene_passes"), SCENE_PASSES, problems)
    for p in results.get("scene_passes") or []:
        if p.get("name") == "hemisphere_raster" and not positive(p.get("planes_per_second")):
            problems.append("hemisphere_raster: planes_per_second is not a positive number")
    got = results.get("sizes")
    if not isinstance(got, list) or not got:
        problems.append("no sizes")
        return problems
    if sizes is not None and [(s.get("width"), s.get("height")) for s in got] != sizes:
        problems.append(f"sizes {[(s.get('width'), s.get('height')) for s in got]} are not the {sizes} asked for")
    for s in got:
        check_passes(f"{s.get('width')}x{s.get('height')}", s.get("passes"), IMAGE_PASSES, problems)
    return problems


def markdown(results):
    """The results as a Markdown table: one row per pass and size."""
    def ms(x):
        return f"{x:.3g}" if x < 100 else f"{x:.0f}"
    rows = ["| pass | size | median ms | min-max ms | host clock ms |", "|---|---|---:|---:|---:|"]
    def add(p, size):
        wall = ms(p["wall_median_ms"]) if "wall_median_ms" in p else "(is one)"
        extra = f" ({p['planes_per_second']:.3g} planes/s)" if "planes_per_second" in p else ""
        rows.append(f"| {p['name']}{extra} | {size} | {ms(p['median_ms'])} | {ms(p['min_ms'])}-{ms(p['max_ms'])} | {wall} |")
    for p in results["scene_passes"]:
        add(p, "-")
    for name in IMAGE_PASSES:
        for s in results["sizes"]:
            for p in s["passes"]:
                if p["name"] == name:
                    add(p, f"{s['width']}x{s['height']}")
    return "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results")
    parser.add_argument("--sizes", help="the sizes the run was asked for, WxH,WxH")
    parser.add_argument("--markdown", action="store_true", help="print the results as a Markdown table")
    args = parser.parse_args()
    sizes = None
    if args.sizes:
        sizes = [tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")]
    try:
        with open(args.results) as f:
            results = json.load(f)
    except (OSError, ValueError) as e:
        print(f"check_gpu_timings: {args.results}: {e}")
        return 1
    problems = check(results, sizes) if isinstance(results, dict) else ["the file holds no JSON object"]
    for p in problems:
        print(f"check_gpu_timings: {args.results}: {p}")
    if not problems:
        gl = results["gl"]
        print(f"check_gpu_timings: {args.results}: well formed ({gl['renderer']}, {len(results['sizes'])} sizes)")
        if args.markdown:
            print(markdown(results))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
