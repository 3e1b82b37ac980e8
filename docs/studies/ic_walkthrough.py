#!/usr/bin/env python3
"""The walkthrough against Monte Carlo (issue 28: "the walkthrough at 512x512 over 16 frames: at
equal mean per-frame error, the cache's total time at least 1.5 times its single-frame ratio
below Monte Carlo's").

usage: ic_walkthrough.py run TAG FRAMES SIZE SPP STRIDE [scenes...] [-- ic_splatting options]
       ic_walkthrough.py table [WALK_TAG SINGLE_TAG]

run: `ic_splatting --walkthrough FRAMES --walkthrough-mc-stride STRIDE` per scene at SIZE (WxH)
with references of SPP samples per pixel in halves; appends one JSON object per scene to
$RESULTS (docs/results/ic_walkthrough.jsonl) with the commit, the options and the machine's
load (before and after), and the per-frame figures (records, new records, time, debiased error
and its standard error, the verification's counts, the stages, Monte Carlo where it ran).
The single-frame rows it is compared with come from ic_image_size.py into the same file:

  RESULTS=docs/results/ic_walkthrough.jsonl docs/studies/ic_image_size.py single 512x512 128 \
      cornell -- --mc-compare --mc-max-spp 32
  docs/studies/ic_walkthrough.py run walk 16 512x512 128 4 cornell -- --mc-max-spp 32

table: one markdown row per scene, the last walkthrough row of WALK_TAG (walk) against the last
single-frame row of SINGLE_TAG (single). Monte Carlo at equal error: its time at error E is
taken from the last run of its sweep (--mc-max-spp) with the debiased error falling as
spp^-1/2 (exact for independent samples: the reference's noise is taken out of the error),
time' = time (e / E)^2, as ic_verification_table.py does ("~": extrapolated beyond the sweep).
The walkthrough's E is the mean of the frames' debiased errors (the issue's "equal mean
per-frame error"): each measured frame's Monte Carlo time at E, their mean times the frames,
over the cache's total. Matching each frame's own error instead is unstable: a frame whose
debiased error is within its standard error of 0 asks for an unbounded Monte Carlo time. The
table also gives the walkthrough's first frame (an empty cache, the same references and load)
as a single frame. IC_BIN: the binary (build/bin/ic_splatting); BOUNCE_CACHE, BOUNCE_SCENES as
for ic_splatting."""
import json
import os
import subprocess
import sys
import tempfile
import time

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
results = os.environ.get('RESULTS', os.path.join(root, 'docs/results/ic_walkthrough.jsonl'))
order = ['cornell', 'cornell-box', 'bunny', 'sponza', 'conference', 'living-room', 'modern-hall']


def monte_carlo_ms(m, target):
    """(Monte Carlo's time at debiased error `target`, extrapolated beyond its sweep) from one
    mc_equal_error object."""
    return m['measured_ms'] * (m['measured_rel_rms'] / target) ** 2, target < m['measured_rel_rms']


def frame_row(f):
    keep = ('frame', 'records', 'new_records', 'ms', 'rel_rms', 'rel_rms_debiased', 'rel_rms_debiased_se',
            'reference_noise_rel_rms', 'reclamped', 'verify', 'stages_ms', 'mc_equal_error')
    return {k: f[k] for k in keep if k in f}


def run(args):
    sep = args.index('--') if '--' in args else len(args)
    args, extra = args[:sep], args[sep + 1:]
    if len(args) < 5:
        sys.exit(__doc__)
    tag, frames, size, spp, stride = args[:5]
    scenes = args[5:] or order
    w, h = size.split('x')
    binary = os.environ.get('IC_BIN', os.path.join(root, 'build/bin/ic_splatting'))
    scenes_dir = os.environ.get('BOUNCE_SCENES', os.path.join(root, '../shared/scenes'))
    commit = subprocess.run(['git', '-C', root, 'rev-parse', '--short', 'HEAD'], capture_output=True,
                            text=True).stdout.strip()
    with open(results, 'a') as out, tempfile.TemporaryDirectory() as tmp:
        for s in scenes:
            report = os.path.join(tmp, f'{tag}-{s}.json')
            scene = s if s == 'cornell' else os.path.join(scenes_dir, s)
            options = ['--width', w, '--height', h, '--ref-spp', spp, '--walkthrough', frames,
                       '--walkthrough-mc-stride', stride] + extra
            t0, load_before = time.time(), os.getloadavg()[0]
            r = subprocess.run([binary, '--scene', scene, '--json', report] + options, capture_output=True, text=True)
            if r.returncode != 0:
                print(s, 'failed:', r.stderr[-500:], flush=True)
                continue
            j = json.load(open(report))
            walk = j['walkthrough']
            fr = walk['frames']
            row = {'tag': tag, 'scene': s, 'size': size, 'reference_spp': int(spp), 'frames_count': int(frames),
                   'mc_stride': int(stride), 'records': j['records'],
                   'total_ms_loaded_machine': walk['total_ms'], 'mean_rel_rms': walk['mean_rel_rms'],
                   'mean_rel_rms_debiased': walk['mean_rel_rms_debiased'],
                   'frames_debiased_unresolved': walk['frames_debiased_unresolved'],
                   'reference_noise': walk['mean_reference_noise_rel_rms'], 'mc_equal_error': walk.get('mc_equal_error'),
                   'frames': [frame_row(f) for f in fr], 'options': ' '.join(options),
                   'parameters': j.get('parameters'), 'commit': commit, 'load_before': load_before,
                   'load_average': os.getloadavg()[0], 'cores': os.cpu_count(), 'wall_s': time.time() - t0}
            out.write(json.dumps(row) + '\n')
            out.flush()
            ratio = walkthrough_ratio(row)
            print(f"{tag} {s}: {row['records']} records, {row['total_ms_loaded_machine'] / 1000:.1f} s over {frames} "
                  f"frames, mean debiased {row['mean_rel_rms_debiased']:.4f}, Monte Carlo at that error "
                  f"{'~' if ratio[2] else ''}{ratio[0]:.1f}x, {time.time() - t0:.0f} s wall, load "
                  f"{load_before:.1f} -> {row['load_average']:.1f}", flush=True)


def walkthrough_ratio(row):
    """(ratio, Monte Carlo's total ms, extrapolated) at the frames' mean debiased error."""
    target = row['mean_rel_rms_debiased']
    measured = [monte_carlo_ms(f['mc_equal_error'], target) for f in row['frames']
                if 'measured_ms' in (f.get('mc_equal_error') or {})]
    if not measured or not target > 0:
        return float('nan'), float('nan'), False
    total = sum(m[0] for m in measured) / len(measured) * row['frames_count']
    return total / row['total_ms_loaded_machine'], total, any(m[1] for m in measured)


def single_ratio(row):
    """(ratio, extrapolated) of a single-frame row (ic_image_size.py with --mc-compare)."""
    m = row.get('mc_equal_error') or {}
    if 'measured_ms' not in m:
        return float('nan'), False
    ms, extra = monte_carlo_ms(m, m['rel_rms'])
    return ms / row['total_ms_loaded_machine'], extra


def first_frame_ratio(row):
    """(ratio, debiased error) of the walkthrough's first frame alone."""
    f = row['frames'][0]
    m = f.get('mc_equal_error') or {}
    if 'measured_ms' not in m:
        return float('nan'), f['rel_rms_debiased']
    return monte_carlo_ms(m, m['rel_rms'])[0] / f['ms'], f['rel_rms_debiased']


RAYS_PER_RECORD = 1026  # the default 32 x 32 grid and its two gradient rays (ic_verification_table.py)


def rays_ratio(row, frames, target):
    """Monte Carlo's rays at debiased error `target` over the cache's, for `frames` frames of
    `row` (a walkthrough row: its measured frames; a single-frame row: itself): spp times
    pixels against the records' rays plus the verification's probes (8 rays on half the
    pixels: an upper bound); the scan's wasted guesses and the splats left out. The machine's
    load does not move it."""
    w, h = (int(v) for v in row['size'].split('x'))
    verified = 'verify_tiles' in row or any('verify' in f for f in row.get('frames', []))
    probes = w * h // 2 * 8 if verified else 0
    if 'frames' in row:
        ms = [f['mc_equal_error'] for f in row['frames'] if 'measured_ms' in (f.get('mc_equal_error') or {})]
        records = sum(f['new_records'] for f in row['frames'])
    else:
        ms, records = [row['mc_equal_error']], row['records']
    spp = sum(m['measured_spp'] * (m['measured_rel_rms'] / target) ** 2 for m in ms) / len(ms)
    return spp * w * h * frames / (records * RAYS_PER_RECORD + probes * frames)


def table(args):
    walk_tag, single_tag = (args + ['walk', 'single'])[:2] if len(args) != 1 else (args[0], 'single')
    walks, singles = {}, {}
    for line in open(results):
        r = json.loads(line)
        if r['tag'] == walk_tag and 'frames' in r:
            walks[r['scene']] = r
        elif r['tag'] == single_tag:
            singles[r['scene']] = r
    print('| scene | single frame: records | debiased rel_rms (se) | time | Monte Carlo | walkthrough: records | '
          'mean debiased rel_rms (se) | time | Monte Carlo | walk / single (by rays) | first frame: rel_rms, Monte Carlo | '
          'later frames: new records, s, of which clamp + splat, verify | load |')
    print('|---|' + '---|' * 12)
    for s in order:
        w, one = walks.get(s), singles.get(s)
        if w is None and one is None:
            continue
        cells = [s]
        r1 = float('nan')
        if one:
            r1, x1 = single_ratio(one)
            cells += [f"{one['records']:,}", f"{one['rel_rms_debiased']:.4f} ({one.get('rel_rms_debiased_se', 0):.4f})",
                      f"{one['total_ms_loaded_machine'] / 1000:.1f} s", f"{'~' if x1 else ''}{r1:.0f}x"]
        else:
            cells += ['not run', '', '', '']
        if w:
            fr = w['frames']
            later = fr[1:] or fr
            n = len(later)
            new = sum(f['new_records'] for f in later) / n
            ms = sum(f['ms'] for f in later) / n
            splat = sum(f['stages_ms'].get('splat_existing', 0.0) for f in later) / n
            verify = sum(f['stages_ms'].get('verify', 0.0) for f in later) / n
            se = (sum(f.get('rel_rms_debiased_se', 0.0) ** 2 for f in fr)) ** 0.5 / len(fr)
            rw, _, xw = walkthrough_ratio(w)
            r0, e0 = first_frame_ratio(w)
            cells += [f"{w['records']:,}", f"{w['mean_rel_rms_debiased']:.4f} ({se:.4f})",
                      f"{w['total_ms_loaded_machine'] / 1000:.1f} s", f"{'~' if xw else ''}{rw:.0f}x",
                      f"{rw / r1:.2f} ({rays_ratio(w, 16, w['mean_rel_rms_debiased']) / rays_ratio(one, 1, one['rel_rms_debiased']):.2f})"
                      if one else '', f"{e0:.4f}, {r0:.0f}x",
                      f"{new:,.0f}, {ms / 1000:.1f} s, {splat / 1000:.1f} s, {verify / 1000:.1f} s"]
        else:
            cells += ['not run', '', '', '', '', '', '']
        load = ' / '.join(f"{r['load_average']:.0f}" for r in (one, w) if r)
        print('| ' + ' | '.join(cells + [load]) + ' |')


if __name__ == '__main__':
    if len(sys.argv) < 2 or sys.argv[1] not in ('run', 'table'):
        sys.exit(__doc__)
    (run if sys.argv[1] == 'run' else table)(sys.argv[2:])
