#!/usr/bin/python3
"""Where an irradiance cache's error sits against a reference in two halves (issue 28, third
session): the debiased squared error per pixel, (c - r)^2 - (a - b)^2 / 4 with r = (a + b) / 2
(the second term takes the reference's own noise out, as the study's debiased rel_rms does),
its share in the worst pixels, the connected regions of the worst 1% with their share, size,
bounding box and sign (cache above or below the reference), and a picture: the cache, the
reference and the signed error (red: cache too bright, blue: too dark).

    /usr/bin/python3 docs/studies/ic_error_map.py REF_A.exr REF_B.exr CACHE.exr [CACHE2.exr ...]
        [--png OUT.png] [--rows Y0:Y1] [--cols X0:X1] [--regions N]

With several cache images, each is reported in turn and the picture has one row per image
(--rows and --cols crop every panel to those image rows and columns).

Reads EXRs through `oiiotool --dumpdata` (no Python binding needed). The images are the
indirect radiance ic_splatting writes with --indirect-exr and the reference cache's
`<key>.indirect-a.exr` / `-b.exr`."""
import argparse
import re
import subprocess
import sys

import numpy as np

PIXEL = re.compile(r"\s*Pixel \((\d+), (\d+)\): (\S+) (\S+) (\S+)")
REC709 = np.array([0.2126, 0.7152, 0.0722])


def luminance(path):
    text = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    rows = np.array([tuple(float(g) for g in m.groups()) for m in map(PIXEL.match, text.splitlines()) if m])
    if rows.size == 0:
        sys.exit(f"{path}: no pixels read")
    w, h = int(rows[:, 0].max()) + 1, int(rows[:, 1].max()) + 1
    image = np.zeros((h, w, 3))
    image[rows[:, 1].astype(int), rows[:, 0].astype(int)] = rows[:, 2:5]
    return image @ REC709


def regions(mask):
    """Connected components (8-neighbours) of a boolean image: a label image and the count."""
    h, w = mask.shape
    label = np.zeros((h, w), dtype=np.int32)
    n = 0
    for y0, x0 in zip(*np.nonzero(mask)):
        if label[y0, x0]:
            continue
        n += 1
        stack = [(y0, x0)]
        label[y0, x0] = n
        while stack:
            y, x = stack.pop()
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    yy, xx = y + dy, x + dx
                    if 0 <= yy < h and 0 <= xx < w and mask[yy, xx] and not label[yy, xx]:
                        label[yy, xx] = n
                        stack.append((yy, xx))
    return label, n


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("ref_a")
    p.add_argument("ref_b")
    p.add_argument("caches", nargs="+")
    p.add_argument("--png")
    p.add_argument("--rows", help="Y0:Y1, the image rows the picture keeps")
    p.add_argument("--cols", help="X0:X1, the image columns the picture keeps")
    p.add_argument("--regions", type=int, default=8)
    o = p.parse_args()
    a, b = luminance(o.ref_a), luminance(o.ref_b)
    panels = []
    for path in o.caches:
        print(path)
        panels.append(report(a, b, luminance(path), o))
    if o.png:
        from PIL import Image

        y0, y1 = (int(v) for v in o.rows.split(":")) if o.rows else (0, a.shape[0])
        x0, x1 = (int(v) for v in o.cols.split(":")) if o.cols else (0, a.shape[1])
        rows = [np.concatenate([q[y0:y1, x0:x1] for q in p], axis=1) for p in panels]
        Image.fromarray(np.concatenate(rows, axis=0)).save(o.png, optimize=True)
        print(f"wrote {o.png}")


def report(a, b, c, o):
    """Prints where the error of cache image c sits; returns its picture row."""
    if not (a.shape == b.shape == c.shape):
        sys.exit(f"sizes differ: {a.shape} {b.shape} {c.shape}")
    r = 0.5 * (a + b)
    d = c - r
    e = d ** 2 - 0.25 * (a - b) ** 2
    total = e.sum()
    print(f"debiased rel_rms {np.sqrt(max(total, 0) / e.size / np.mean(r ** 2)):.4f} "
          f"(raw {np.sqrt(np.mean(d ** 2) / np.mean(r ** 2)):.4f}); cache / reference sums {c.sum() / r.sum():.4f}")
    order = np.sort(e.ravel())[::-1]
    for f in (0.001, 0.01, 0.05, 0.2):
        k = max(1, int(f * e.size))
        print(f"  worst {100 * f:g}% of pixels ({k}): {100 * order[:k].sum() / total:.0f}% of the squared error")
    # Regions of the worst 1%, largest share first.
    worst = e >= order[max(1, int(0.01 * e.size)) - 1]
    label, n = regions(worst)
    rows = []
    for i in range(1, n + 1):
        m = label == i
        ys, xs = np.nonzero(m)
        rows.append((e[m].sum() / total, m.sum(), xs.min(), xs.max(), ys.min(), ys.max(), d[m].mean() / max(r[m].mean(), 1e-30),
                     r[m].mean()))
    rows.sort(reverse=True)
    print(f"  the worst 1% form {n} regions; the largest shares:")
    for s, k, x0, x1, y0, y1, rel, mean in rows[: o.regions]:
        print(f"    {100 * s:5.1f}%  {k:5d} px  x {x0}-{x1}  y {y0}-{y1}  cache {100 * rel:+.0f}% of the reference's {mean:.4g}")
    # Share by the sign of the error.
    print(f"  cache above the reference: {100 * e[d > 0].sum() / total:.0f}% of the squared error, below: "
          f"{100 * e[d < 0].sum() / total:.0f}%")
    if True:
        scale = np.percentile(r[r > 0], 99) if np.any(r > 0) else 1.0
        tone = lambda x: (255 * np.clip(x / scale, 0, 1) ** (1 / 2.2)).astype(np.uint8)
        lim = np.sqrt(np.percentile(np.maximum(e, 0), 99.5)) or 1.0
        err = np.zeros(d.shape + (3,), dtype=np.uint8)
        t = np.clip(np.abs(d) / lim, 0, 1)
        err[..., 0] = (255 * t * (d > 0)).astype(np.uint8)
        err[..., 2] = (255 * t * (d < 0)).astype(np.uint8)
        err[..., 1] = (60 * t).astype(np.uint8)
        grey = lambda x: np.repeat(tone(x)[..., None], 3, axis=2)
        return grey(c), grey(r), err


if __name__ == "__main__":
    main()
