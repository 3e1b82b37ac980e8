#!/usr/bin/python3
"""Tabulates docs/studies/hemisphere_turn.sh's runs (docs/results/hemisphere_turn.json): RMS
error of each weighting against the plane's turn, per scene, in Markdown, and stretching's
ratio to the plane alone.

    /usr/bin/python3 docs/studies/hemisphere_turn_table.py docs/results/hemisphere_turn.json"""
import json
import sys

KEYS = ("rms_plane", "rms_coverage", "rms_stretch", "rms_falloff")
SCENES = {"sponza": "Sponza", "cornell": "Cornell box"}


def rows(results, scene):
    runs = []
    for d in results["runs"]:
        if not d["name"].startswith(f"{scene}-"):
            continue
        p = d["parameters"]
        label = "hashed" if p["hashed_turn"] else f"{p['plane_turn_deg']:g}"
        order = 1e9 if p["hashed_turn"] else p["plane_turn_deg"]
        runs.append((order, label, d["error"]["ray_cast"], p["points"]))
    return sorted(runs, key=lambda r: r[0])


def main(path):
    with open(path) as f:
        results = json.load(f)
    for scene in ("sponza", "cornell"):
        runs = rows(results, scene)
        if not runs:
            continue
        print(f"\n**{SCENES[scene]}**, ray-cast, 64^2 at 126 deg, {runs[0][3]} points:\n")
        print("| turn (deg) | plane | coverage | stretching | fall-off (kappa) | stretching / plane |")
        print("|---|---|---|---|---|---|")
        for _, label, e, _ in runs:
            cells = [f"{100 * e[k]:.2f}%" for k in KEYS]
            cells[3] += f" ({e['falloff_kappa']:.3f})"
            print(f"| {label} | " + " | ".join(cells) + f" | {e['rms_stretch'] / e['rms_plane']:.3f} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/results/hemisphere_turn.json")
