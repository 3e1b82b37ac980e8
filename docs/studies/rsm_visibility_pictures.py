#!/usr/bin/python3
"""The leak and its two fixes side by side (docs/rsm-sii-interleaved.md section 17).

For each scene runs `rsm_sii --technique sii --vpls 1024 --pattern 4x4` (blur on, 256x256)
with --visibility ism and with --visibility rays, each with --indirect-out, which writes
[no visibility | the chosen visibility | occluded one-bounce reference] in one exposure (the
reference's, the program's own tone mapping). The four panels are cut from those two PNGs
unchanged: no visibility, ISM and the reference from the ISM run, exact (rays) from the rays
run; the script checks that the two runs' shared panels are the same to the byte, so all four
stand under one exposure. A third run without visibility (its report only) gives that
panel's error. Labels: each frame's raw rel_rms against the occluded reference, from the
runs' reports. Writes docs/figures/rsm-visibility-<scene>.png.

Usage: /usr/bin/python3 docs/studies/rsm_visibility_pictures.py [--bin build/bin] [--runs build/runs]
       [scene ...]   (default: cornell-box conference; scenes as rsm_sii's --scene)
References come from the program's cache ($BOUNCE_CACHE, else cache/ beside bin/) or are
computed there (about 30 s a scene at 256x256 and 1024 rays per pixel).
"""
import argparse
import json
import os
import subprocess
import sys

from PIL import Image, ImageDraw, ImageFont

SIZE = 256
LABEL_HEIGHT = 40
MAX_BYTES = 300 * 1024
COMMON = ["--technique", "sii", "--vpls", "1024", "--pattern", "4x4",
          "--width", str(SIZE), "--height", str(SIZE)]


def run(binary, scene, visibility, runs):
    """Runs rsm_sii once; returns (its report, its --indirect-out panels or None)."""
    stem = os.path.join(runs, f"rsm-visibility-{scene}-{visibility}")
    args = [binary, "--scene", scene, *COMMON, "--visibility", visibility, "--json", stem + ".json"]
    if visibility != "none":
        args += ["--indirect-out", stem + ".png"]
    print(" ".join(args), flush=True)
    subprocess.run(args, check=True)
    with open(stem + ".json") as f:
        report = json.load(f)
    if visibility == "none":
        return report, None
    row = Image.open(stem + ".png").convert("RGB")
    if row.size != (3 * SIZE, SIZE):
        sys.exit(f"{stem}.png is {row.size}, expected three panels of {SIZE}x{SIZE}")
    return report, [row.crop((k * SIZE, 0, (k + 1) * SIZE, SIZE)) for k in range(3)]


def compose(scene, panels, labels, out):
    try:
        font = ImageFont.truetype("DejaVuSans.ttf", 14)
    except OSError:  # no DejaVu where FreeType looks: PIL's own small bitmap font
        font = ImageFont.load_default()
    sheet = Image.new("RGB", (len(panels) * SIZE, SIZE + LABEL_HEIGHT), "white")
    draw = ImageDraw.Draw(sheet)
    for k, (panel, (title, detail)) in enumerate(zip(panels, labels)):
        sheet.paste(panel, (k * SIZE, LABEL_HEIGHT))
        draw.text((k * SIZE + 6, 3), title, fill="black", font=font)
        draw.text((k * SIZE + 6, 21), detail, fill=(70, 70, 70), font=font)
    sheet.save(out, optimize=True)
    if os.path.getsize(out) > MAX_BYTES:  # a palette keeps photographic panels small
        sheet.quantize(colors=256, method=Image.Quantize.MEDIANCUT).save(out, optimize=True)
    print(f"{out}: {os.path.getsize(out) // 1024} KB ({scene})")


def main():
    root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bin", default=os.path.join(root, "build", "bin"))
    p.add_argument("--runs", default=os.path.join(root, "build", "runs"))
    p.add_argument("scenes", nargs="*", default=["cornell-box", "conference"])
    a = p.parse_args()
    binary = os.path.join(a.bin, "rsm_sii")
    os.makedirs(a.runs, exist_ok=True)
    os.makedirs(os.path.join(root, "docs", "figures"), exist_ok=True)
    for scene in a.scenes:
        none, _ = run(binary, scene, "none", a.runs)
        ism, (leak, ism_panel, reference) = run(binary, scene, "ism", a.runs)
        rays, (leak_rays, rays_panel, reference_rays) = run(binary, scene, "rays", a.runs)
        if leak.tobytes() != leak_rays.tobytes() or reference.tobytes() != reference_rays.tobytes():
            sys.exit(f"{scene}: the ISM and rays runs disagree on the frame without visibility or the "
                     "reference; their panels would not share one exposure")
        err = {name: r["error"]["rel_rms_occluded"] for name, r in
               (("none", none), ("ism", ism), ("rays", rays))}
        spp = ism["parameters"]["reference_spp"]
        labels = [("no visibility (leaks)", f"rel_rms {err['none']:.3f}"),
                  ("imperfect shadow maps", f"rel_rms {err['ism']:.3f}"),
                  ("exact (occlusion rays)", f"rel_rms {err['rays']:.3f}"),
                  ("occluded reference", f"{spp} rays a pixel")]
        compose(scene, [leak, ism_panel, rays_panel, reference], labels,
                os.path.join(root, "docs", "figures", f"rsm-visibility-{scene}.png"))


if __name__ == "__main__":
    main()
