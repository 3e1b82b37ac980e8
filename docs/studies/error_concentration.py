#!/usr/bin/python3
"""Where an indirect image's error sits: luminance relative RMS against a reference, the
ratio of the image sums, the share of the squared error held by the worst 1% and 5% of
the pixels, and the worst rows. Reads EXRs through `oiiotool --dumpdata` (OpenImageIO's
command line; no Python binding needed).

    /usr/bin/python3 docs/studies/error_concentration.py REFERENCE.exr IMAGE.exr [IMAGE.exr ...]"""
import re
import subprocess
import sys

import numpy as np

PIXEL = re.compile(r"\s*Pixel \((\d+), (\d+)\): (\S+) (\S+) (\S+)")
REC709 = np.array([0.2126, 0.7152, 0.0722])


def luminance(path):
    text = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    rows = [tuple(float(g) for g in m.groups()) for m in map(PIXEL.match, text.splitlines()) if m]
    if not rows:
        sys.exit(f"{path}: no pixels read")
    w, h = int(max(r[0] for r in rows)) + 1, int(max(r[1] for r in rows)) + 1
    image = np.zeros((h, w, 3))
    for x, y, *rgb in rows:
        image[int(y), int(x)] = rgb
    return image @ REC709


def main(reference, images):
    ref = luminance(reference)
    for path in images:
        img = luminance(path)
        if img.shape != ref.shape:
            sys.exit(f"{path}: {img.shape} pixels, the reference has {ref.shape}")
        d2 = (img - ref) ** 2
        worst = np.sort(d2.ravel())[::-1]
        share = lambda f: worst[: max(1, int(f * worst.size))].sum() / d2.sum()
        rows = d2.sum(axis=1) / d2.sum()
        top_rows = np.argsort(rows)[::-1][:5]
        print(f"{path}: rel_rms {np.sqrt(d2.mean() / np.mean(ref ** 2)):.4f}, sum / reference's "
              f"{img.sum() / ref.sum():.4f}, worst 1% of pixels {100 * share(0.01):.0f}% of the squared "
              f"error, worst 5% {100 * share(0.05):.0f}%, worst rows "
              + ", ".join(f"{r} ({100 * rows[r]:.1f}%)" for r in top_rows))


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
