#!/usr/bin/env python3
"""Where the RSM gather's error with occlusion rays sits (issue 29; docs/rsm-sii-interleaved.md,
section 15.5). Reads the raw frames `rsm_visibility_study --configs
gather --dump DIR` writes (256x256 float32 RGB, row-major) and

  - prints each frame's debiased rel_rms (as bench::measure_error, luminance over the covered
    pixels), |b_none| / |r_occluded| (the error without visibility in the units of the occluded
    reference: b = frame - its reference per pixel), |b_rays - b_none| / |r_occluded| (what
    visibility changes) and |r_unoccluded| / |r_occluded|, with and without the 65 worst pixels;
  - writes a PNG: the occluded reference, the gather with rays, and the signed error of the
    frame with rays (against the occluded reference) and without (against the unoccluded one),
    each averaged over 4 x 4 blocks (the references' noise averages out, a bias stays) and
    relative to the block's reference: red brighter, blue darker, full at 15%.

    docs/studies/rsm_gather_error_map.py DIR SCENE OUT.png
    docs/studies/rsm_gather_error_map.py table

`table` prints the gather's cells from docs/results/rsm_gather_visibility.json (runs of
`rsm_visibility_study --configs gather --json`, added with docs/studies/results.py): per scene
and count, the errors with rays and without and their ratio, the mean over the seeds, and the
split of each frame with rays (the report's "split"; mean over the seeds), one row per count of
the clamp's compensation rays (the run's parameter; 0 for runs before it; "K both" where the
frame without visibility is compensated too, by its unoccluded near field) with the share of
the frame's light they add to the frame with rays.

Pure Python (zlib for the PNG): no numpy needed.
"""
import array
import json
import math
import os
import struct
import sys
import zlib

W = H = 256
BLOCK = 4
GAIN = 0.15


def load(folder, scene, name):
    a = array.array("f")
    with open(f"{folder}/{scene}.{name}.f32", "rb") as f:
        a.frombytes(f.read())
    return [0.2126 * a[3 * i] + 0.7152 * a[3 * i + 1] + 0.0722 * a[3 * i + 2] for i in range(W * H)], a


def write_png(path, w, h, rgb):
    raw = b"".join(b"\x00" + bytes(rgb[y * w * 3:(y + 1) * w * 3]) for y in range(h))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def split(pixels, x_rays, x_none, occ, unocc):
    """Debiased sums over `pixels`: |b_rays|^2, |b_none|^2, |b_rays - b_none|^2, |r_occ|^2, |r_unocc|^2."""
    (oa, ob), (ua, ub) = occ, unocc
    s = [0.0] * 5
    for i in pixels:
        ro, ru = 0.5 * (oa[i] + ob[i]), 0.5 * (ua[i] + ub[i])
        no, nu = 0.25 * (oa[i] - ob[i]) ** 2, 0.25 * (ua[i] - ub[i]) ** 2
        br, bn = x_rays[i] - ro, x_none[i] - ru
        s[0] += br * br - no
        s[1] += bn * bn - nu
        s[2] += (br - bn) ** 2 - no - nu
        s[3] += ro * ro - no
        s[4] += ru * ru - nu
    return s


def report(label, s):
    root = lambda a, b: math.sqrt(max(a, 0.0) / b)
    print(f"{label}: rays {root(s[0], s[3]):.4f} (occluded), none {root(s[1], s[4]):.4f} (unoccluded), "
          f"ratio {root(s[0], s[3]) / root(s[1], s[4]):.3f}; none in occluded units {root(s[1], s[3]):.4f}, "
          f"visibility's change {root(s[2], s[3]):.4f}, references' rms ratio {root(s[4], s[3]):.3f}")


def block_error(x, ref, covered):
    (a, b) = ref
    out = [None] * (W * H)
    for by in range(0, H, BLOCK):
        for bx in range(0, W, BLOCK):
            idx = [(by + j) * W + bx + k for j in range(BLOCK) for k in range(BLOCK) if covered[(by + j) * W + bx + k]]
            r = sum(0.5 * (a[i] + b[i]) for i in idx)
            if not idx or r <= 0:
                continue
            d = sum(x[i] - 0.5 * (a[i] + b[i]) for i in idx) / r
            for i in idx:
                out[i] = d
    return out


def table():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "results", "rsm_gather_visibility.json")
    with open(path) as f:
        runs = json.load(f)["runs"]
    cells = {}
    for r in runs:
        # Runs whose frame without visibility is compensated too (its unoccluded near field).
        both = any(fr["visibility"] == "none" and fr.get("compensation_share", 0.0) > 0 for fr in r["frames"])
        for fr in r["frames"]:
            if fr["config"] != "gather":
                continue
            k = r["parameters"].get("compensation_rays", 0)
            key = (fr["scene"], fr["vpls"], f"{k} both" if both else str(k) if "compensation_rays" in r["parameters"]
                   else "0")
            c = cells.setdefault(key, {}).setdefault(r["parameters"]["seed"], {})
            c[fr["visibility"]] = fr["rel_rms_debiased"]
            if fr["visibility"] == "rays":
                c["share"] = fr.get("compensation_share", 0.0)
            if "split" in fr:
                c["split"] = fr["split"]
    print("| scene | samples | compensation rays | seeds | rays / none = ratio | none in occluded units | "
          "visibility's change | references' rms ratio | light the compensation adds |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (scene, n, k), seeds in sorted(cells.items()):
        both = [c for c in seeds.values() if "rays" in c and "none" in c]
        if not both:
            continue
        mean = lambda f: sum(f(c) for c in both) / len(both)
        rays, none = mean(lambda c: c["rays"]), mean(lambda c: c["none"])
        mark = "**" if rays / none > 1.2 else ""
        splits = [c["split"] for c in both if "split" in c]
        sm = lambda k: f"{sum(s[k] for s in splits) / len(splits):.3f}" if splits else "-"
        share = f"{100 * mean(lambda c: c.get('share', 0.0)):.2f}%" if k != "0" else "-"
        print(f"| {scene} | {n} | {k} | {','.join(str(s) for s in sorted(seeds))} | {rays:.3f} / {none:.3f} = "
              f"{mark}{rays / none:.2f}{mark} | {sm('none_error_in_occluded_units')} | {sm('visibility_change')} | "
              f"{sm('references_rms_ratio')} | {share} |")


def main():
    if sys.argv[1] == "table":
        return table()
    folder, scene, out = sys.argv[1:4]
    _, albedo = load(folder, scene, "albedo")
    covered = [albedo[3 * i] + albedo[3 * i + 1] + albedo[3 * i + 2] > 0 for i in range(W * H)]
    pixels = [i for i in range(W * H) if covered[i]]
    occ = (load(folder, scene, "ref_occluded_a")[0], load(folder, scene, "ref_occluded_b")[0])
    unocc = (load(folder, scene, "ref_unoccluded_a")[0], load(folder, scene, "ref_unoccluded_b")[0])
    x_rays, x_none = load(folder, scene, "gather-rays")[0], load(folder, scene, "gather-none")[0]
    report("all pixels", split(pixels, x_rays, x_none, occ, unocc))
    worst = sorted(pixels, key=lambda i: -(x_rays[i] - 0.5 * (occ[0][i] + occ[1][i])) ** 2)[:65]
    rest = set(pixels) - set(worst)
    report("without the 65 worst", split(sorted(rest), x_rays, x_none, occ, unocc))

    mean = sum(0.5 * (occ[0][i] + occ[1][i]) for i in pixels) / len(pixels)
    e_rays, e_none = block_error(x_rays, occ, covered), block_error(x_none, unocc, covered)

    def tone(v):
        g = int(255 * min(1.0, max(v, 0.0) / (4 * mean)) ** (1 / 2.2))
        return bytes((g, g, g))

    def signed(d):
        if d is None:
            return bytes((0, 0, 0))
        t = max(-1.0, min(1.0, d / GAIN))
        return bytes((int(255 * t), 0, 0)) if t > 0 else bytes((0, 0, int(-255 * t)))

    rgb = bytearray()
    for y in range(H):
        for panel in range(4):
            for x in range(W):
                i = y * W + x
                rgb += (tone(0.5 * (occ[0][i] + occ[1][i])) if panel == 0 else tone(x_rays[i]) if panel == 1 else
                        signed(e_rays[i]) if panel == 2 else signed(e_none[i]))
    write_png(out, 4 * W, H, rgb)


if __name__ == "__main__":
    main()
