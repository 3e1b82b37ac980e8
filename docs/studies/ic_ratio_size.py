#!/usr/bin/env python3
"""The cache against Monte Carlo at equal debiased error, per scene and image size (issue 28):
a markdown table and docs/figures/ic-ratio-size.png (one panel per scene, the ratio against
the image's pixels on a log axis).

    docs/studies/ic_ratio_size.py [RESULTS.jsonl ...]

Rows: docs/results/ic_ratio_size.jsonl (docs/studies/ic_image_size.py with the defaults and
--mc-compare) and the 512x512 rows of docs/results/ic_verification.jsonl tagged
`quiet-verify` (the same defaults on a quiet machine); the last row of each (scene, size).
Records without the verification pass: the rows tagged `records-noverify` (--verify 0), else
the `base` rows of docs/results/ic_image_size.jsonl (the defaults before the pass existed).
Monte Carlo at equal error is that of results.monte_carlo_at_equal_error: past the sweep
(--mc-max-spp) extrapolated as spp ~ err^-2, marked "~". The cache and its Monte Carlo are
timed in the same run, so the ratio is comparable across loads only as far as the load stayed
the same during the run: the load average before and after is in the table."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results import monte_carlo_at_equal_error, monte_carlo_rays_ratio  # noqa: E402

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ORDER = ['cornell', 'cornell-box', 'bunny', 'sponza', 'conference', 'living-room', 'modern-hall']
# The targets: 3x at 512x512, 6x at 1920x1080 (the Cornell boxes 20x).
TARGETS = {'512x512': 3.0, '1920x1080': 6.0}
CORNELL_1080 = 20.0


def pixels(size):
    w, h = (int(v) for v in size.split('x'))
    return w * h


def load_rows(paths):
    """({(scene, size): row}, the last of each with Monte Carlo, the verification file's
    `quiet-verify` only; {(scene, size): records} of the runs tagged `records-noverify`)."""
    rows, records = {}, {}
    for path in paths:
        for line in open(path):
            r = json.loads(line)
            if r['tag'] == 'records-noverify':
                records[(r['scene'], r['size'])] = r['records']
            # Before --verify existed: ic_image_size.jsonl's defaults (tag `base`), equal to the
            # records-noverify counts wherever both were measured.
            if os.path.basename(path) == 'ic_image_size.jsonl' and r['tag'] == 'base' and not r['options']:
                records.setdefault((r['scene'], r['size']), r['records'])
            if 'mc_equal_error' not in r or os.path.basename(path) == 'ic_image_size.jsonl':
                continue
            if os.path.basename(path) == 'ic_verification.jsonl' and r['tag'] != 'quiet-verify':
                continue
            rows[(r['scene'], r['size'])] = r
    return rows, records


def resolved(r):
    """False where the debiased error's standard error is over half the error: the reference's
    noise hides the cache's error, and Monte Carlo at that error means nothing."""
    se = r.get('rel_rms_debiased_se')
    return se is None or se <= 0.5 * r['rel_rms_debiased']


def target(scene, size):
    if size == '1920x1080' and scene in ('cornell', 'cornell-box'):
        return CORNELL_1080
    return TARGETS.get(size)


def table(rows, records):
    print('| scene | size | records | per pixel | debiased rel_rms (se) | cache | Monte Carlo at equal error '
          '| ratio | rays | target | load before / after |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for s in ORDER:
        for size in sorted({k[1] for k in rows if k[0] == s}, key=pixels):
            r = rows[(s, size)]
            ratio, spp, extrapolated = monte_carlo_at_equal_error(r)
            if not resolved(r):
                print(f"| {s} | {size} | {r['records']:,} | {r['records_per_pixel']:.3f} | {r['rel_rms_debiased']:.4f} "
                      f"({r['rel_rms_debiased_se']:.4f}) | | not resolved: the error's standard error is over half the error "
                      f"| | | | {r['load_before']:.1f} / {r['load_average']:.1f} |")
                continue
            cache_s = r['total_ms_loaded_machine'] / 1000
            se = r.get('rel_rms_debiased_se')
            err = f"{r['rel_rms_debiased']:.4f}" + (f" ({se:.4f})" if se is not None else '')
            t = target(s, size)
            mark = '' if t is None else (f"{t:.0f}x " + ('met' if ratio >= t else '**missed**'))
            load = f"{r['load_before']:.1f} / {r['load_average']:.1f}" if 'load_before' in r else f"{r['load_average']:.1f}"
            print(f"| {s} | {size} | {r['records']:,} | {r['records_per_pixel']:.3f} | {err} | {cache_s:.1f} s "
                  f"| {'~' if extrapolated else ''}{ratio * cache_s:.0f} s ({spp:.0f} spp) | {'~' if extrapolated else ''}{ratio:.1f}x | {monte_carlo_rays_ratio(r, spp):.0f}x | {mark} | {load} |")
    print()
    print('| scene | records 512x512 | 1920x1080 | ratio | without verification: 512x512 | 1920x1080 | ratio '
          '| verification\'s records 512x512 | 1920x1080 |')
    print('|---|---|---|---|---|---|---|---|---|')
    for s in ORDER:
        a, b = rows.get((s, '512x512')), rows.get((s, '1920x1080'))
        c, d = records.get((s, '512x512')), records.get((s, '1920x1080'))
        a, b = a and a['records'], b and b['records']
        cells = [f"{a:,}" if a else '', f"{b:,}" if b else '', f"{b / a:.2f}x" if a and b else '',
                 f"{c:,}" if c else '', f"{d:,}" if d else '', f"{d / c:.2f}x" if c and d else '',
                 f"{a - c:,} ({(a - c) / a:.0%})" if a and c else '', f"{b - d:,} ({(b - d) / b:.0%})" if b and d else '']
        print(f"| {s} | " + ' | '.join(cells) + ' |')


def plot(rows, out):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    scenes = [s for s in ORDER if any(k[0] == s for k in rows)]
    cols = 4
    fig, axes = plt.subplots((len(scenes) + cols - 1) // cols, cols, figsize=(12, 6), sharex=True, squeeze=False)
    for ax in axes.flat[len(scenes):]:
        ax.axis('off')
    for ax, s in zip(axes.flat, scenes):
        sizes = sorted({k[1] for k in rows if k[0] == s and resolved(rows[k])}, key=pixels)
        px = [pixels(z) for z in sizes]
        mc = [monte_carlo_at_equal_error(rows[(s, z)]) for z in sizes]
        ax.plot(px, [m[0] for m in mc], '-', color='C0')
        for x, z, m in zip(px, sizes, mc):
            quiet = rows[(s, z)]['load_average'] < 3  # filled: quiet machine; open: loaded
            ax.plot([x], [m[0]], 'o', color='C0', markerfacecolor='C0' if quiet else 'white')
        for x, z, m in zip(px, sizes, mc):
            ax.annotate(f"{m[0]:.0f}x", (x, m[0]), textcoords='offset points', xytext=(0, 5), ha='center', fontsize=7)
        for z, t in ((z, target(s, z)) for z in ('512x512', '1920x1080')):
            ax.plot([pixels(z)], [t], 'v', color='C3', markersize=6)
        ax.axhline(1, color='0.6', lw=0.8)
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_title(s, fontsize=10)
        ax.set_xticks([pixels(z) for z in ('256x256', '512x512', '1024x1024', '1920x1080')])
        ax.set_xticklabels(['256²', '512²', '1024²', '1080p'], fontsize=8)
        ax.minorticks_off()
        ax.tick_params(axis='y', labelsize=8)
        ax.grid(True, which='major', color='0.9')
    axes[0][0].set_ylabel('Monte Carlo time / cache time')
    fig.suptitle('Cache against Monte Carlo at equal debiased error, defaults (red: the issue\'s target; '
                 'filled: quiet machine, open: loaded 2-core machine, load 2-24; cache and Monte Carlo timed in one run)',
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    print(f"wrote {out} ({os.path.getsize(out) // 1024} KB)", file=sys.stderr)


if __name__ == '__main__':
    paths = sys.argv[1:] or [os.path.join(root, 'docs/results/ic_verification.jsonl'),
                             os.path.join(root, 'docs/results/ic_ratio_size.jsonl'),
                             os.path.join(root, 'docs/results/ic_image_size.jsonl')]
    rows, records = load_rows(paths)
    table(rows, records)
    plot(rows, os.path.join(root, 'docs/figures/ic-ratio-size.png'))
