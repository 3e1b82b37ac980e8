#!/usr/bin/env python3
"""Importance-sampled records against the defaults (issue 28, docs/irradiance-splatting.md,
"Importance-sampled records").

usage: ic_importance.py TAG SIZE SPP [scenes...] [-- ic_splatting options]
  Runs ic_splatting at SIZE (WxH) against SPP-spp references in halves on each scene (default:
  the built-in Cornell box and every shared scene) and appends one JSON object per run to
  $RESULTS (docs/results/ic_importance_rays.jsonl): records, rays per record, debiased
  rel_rms with its standard error, the stage times (loaded machine: with the load average),
  Monte Carlo at equal error where --mc-compare was given, the options and the commit.
  IC_BIN: the binary (build/bin/ic_splatting); BOUNCE_CACHE, BOUNCE_SCENES as ever.

  docs/studies/ic_importance.py defaults 256x256 1024
  docs/studies/ic_importance.py imp-256 256x256 1024 -- --importance-rays
"""
import json, os, resource, subprocess, sys, tempfile

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
args = sys.argv[1:]
extra = []
if '--' in args:
    i = args.index('--')
    extra, args = args[i + 1:], args[:i]
if len(args) < 3:
    sys.exit(__doc__)
tag, size, spp = args[0], args[1], args[2]
scenes = args[3:] or ['cornell', 'cornell-box', 'bunny', 'sponza', 'conference', 'living-room', 'modern-hall']
binary = os.environ.get('IC_BIN', os.path.join(root, 'build/bin/ic_splatting'))
scenes_dir = os.environ.get('BOUNCE_SCENES', os.path.join(root, '../shared/scenes'))
results = os.environ.get('RESULTS', os.path.join(root, 'docs/results/ic_importance_rays.jsonl'))
commit = subprocess.run(['git', '-C', root, 'rev-parse', '--short', 'HEAD'], capture_output=True, text=True).stdout.strip()
w, h = size.split('x')
with open(results, 'a') as out, tempfile.TemporaryDirectory() as tmp:
    for s in scenes:
        report = os.path.join(tmp, f'{tag}-{s}.json')
        scene = s if s == 'cornell' else os.path.join(scenes_dir, s)
        cmd = [binary, '--scene', scene, '--width', w, '--height', h, '--ref-spp', spp, '--json', report] + extra
        load_before = os.getloadavg()[0]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        r = subprocess.run(cmd, capture_output=True, text=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        # CPU seconds of the whole run (setup, references from the cache, frame): less
        # inflated by the load than wall-clock times.
        cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        if r.returncode != 0:
            print(s, 'failed:', r.stderr[-500:], flush=True)
            continue
        j = json.load(open(report))
        e = j['error']
        t = j['timings_ms']
        row = {'tag': tag, 'scene': s, 'size': size, 'reference_spp': int(spp), 'records': j['records'],
               'rays_per_record': j.get('rays_per_record'), 'rel_rms': e['rel_rms'],
               'rel_rms_debiased': e.get('rel_rms_debiased'), 'rel_rms_debiased_se': e.get('rel_rms_debiased_se'),
               'reference_noise': e.get('reference_noise_rel_rms'),
               'compute_records_ms_loaded_machine': t.get('compute_records'), 'total_ms_loaded_machine': t.get('total'),
               'cpu_s': cpu_s, 'load_average': [load_before, os.getloadavg()[0]], 'cores': os.cpu_count(),
               'options': ' '.join(extra) or '(defaults)', 'commit': commit}
        if 'mc_equal_error' in j:
            row['mc_equal_error'] = j['mc_equal_error']
        out.write(json.dumps(row) + '\n')
        out.flush()
        print(f"{tag} {s} {size}: {row['records']} records, rel_rms {row['rel_rms']:.4f} debiased "
              f"{row['rel_rms_debiased']:.4f}, records {row['compute_records_ms_loaded_machine']:.0f} ms, "
              f"total {row['total_ms_loaded_machine']:.0f} ms, cpu {cpu_s:.1f} s (load {load_before:.1f})", flush=True)
