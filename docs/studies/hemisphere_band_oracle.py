#!/usr/bin/python3
"""How far any choice of fall-off factor could take border stretching, from the per-point
CSV of hemisphere_study (--points-csv, ray-cast sampler):

    build/bin/hemisphere_study --scene sponza --points 10000 \\
        --no-raster --points-csv build/points.csv
    /usr/bin/python3 docs/studies/hemisphere_band_oracle.py build/points.csv

E(kappa) = E_plane + kappa (E_stretch - E_plane) is linear in kappa, so the kappa that
minimizes the squared error over a set of points is a least-squares fit against the
reference. Fitting it to the reference is an oracle (no renderer knows the reference):
it bounds what a kappa shared by all points, by a class of surfaces, or by each point
could reach."""
import sys

import numpy as np


def rel_rms(e, ref):
    return np.sqrt(np.mean((e - ref) ** 2)) / np.sqrt(np.mean(ref ** 2))


def best_kappa(ref, plane, band):
    return float(np.sum((ref - plane) * band) / np.sum(band * band))


def main(path, sampler="ray_cast"):
    d = np.genfromtxt(path, delimiter=",", names=True)
    ref, plane, stretch = d["reference"], d[f"{sampler}_plane"], d[f"{sampler}_stretch"]
    band = stretch - plane  # the band's share at kappa = 1
    print(f"{len(ref)} points, {sampler}: plane {100 * rel_rms(plane, ref):.2f}%, "
          f"stretching {100 * rel_rms(stretch, ref):.2f}% ({rel_rms(stretch, ref) / rel_rms(plane, ref):.2f}x the plane's)")
    k = best_kappa(ref, plane, band)
    print(f"one kappa for all points (oracle): {k:.3f}, {100 * rel_rms(plane + k * band, ref):.2f}%")
    up = d["ny"]  # scene up is +y
    classes = {"floors (n.y > 0.7)": up > 0.7, "ceilings (n.y < -0.7)": up < -0.7, "walls": np.abs(up) <= 0.7}
    per_class = plane.copy()
    total = np.sum((stretch - ref) ** 2)
    for name, m in classes.items():
        km = best_kappa(ref[m], plane[m], band[m])
        per_class[m] = plane[m] + km * band[m]
        print(f"  {name}: {m.sum()} points, kappa {km:.3f}, "
              f"{100 * np.sum((stretch[m] - ref[m]) ** 2) / total:.0f}% of stretching's squared error")
    print(f"one kappa per class (oracle): {100 * rel_rms(per_class, ref):.2f}%")
    per_point = plane + np.clip((ref - plane) / np.where(band > 0, band, 1), 0, 3) * np.where(band > 0, band, 0)
    print(f"one kappa per point in [0, 3] (oracle): {100 * rel_rms(per_point, ref):.2f}%")
    print(f"0.5x the plane's error would be {50 * rel_rms(plane, ref):.2f}%")


if __name__ == "__main__":
    main(*sys.argv[1:])
