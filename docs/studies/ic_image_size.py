#!/usr/bin/env python3
"""Records and debiased error of ic_splatting per scene and image size (issue 28).

usage: ic_image_size.py TAG SIZES SPP [scenes...] [-- ic_splatting options]
  SIZES: comma-separated WxH; SPP: the reference's samples per pixel (in halves; 2 for
  record counts alone). Appends one JSON object per run to $RESULTS
  (docs/results/ic_image_size.jsonl), with the commit and the machine's load, and prints a
  line per run. IC_BIN: the ic_splatting binary (build/bin/ic_splatting); BOUNCE_CACHE: the
  reference cache; BOUNCE_SCENES: the scenes folder (../shared/scenes).

  docs/studies/ic_image_size.py base 256x256,512x512 1024
  docs/studies/ic_image_size.py hess 1920x1080 2 sponza -- --radius hessian
  RESULTS=docs/results/ic_verification.jsonl docs/studies/ic_image_size.py verify 512x512 256 -- --verify 2 --mc-compare
"""
import json, os, resource, subprocess, sys, tempfile, time

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
args = sys.argv[1:]
extra = []
if '--' in args:
    i = args.index('--')
    extra, args = args[i + 1:], args[:i]
if len(args) < 3:
    sys.exit(__doc__)
tag, sizes, spp = args[0], args[1].split(','), args[2]
scenes = args[3:] or ['cornell', 'cornell-box', 'bunny', 'sponza', 'conference', 'living-room', 'modern-hall']
binary = os.environ.get('IC_BIN', os.path.join(root, 'build/bin/ic_splatting'))
scenes_dir = os.environ.get('BOUNCE_SCENES', os.path.join(root, '../shared/scenes'))
results = os.environ.get('RESULTS', os.path.join(root, 'docs/results/ic_image_size.jsonl'))
commit = subprocess.run(['git', '-C', root, 'rev-parse', '--short', 'HEAD'], capture_output=True, text=True).stdout.strip()
with open(results, 'a') as out, tempfile.TemporaryDirectory() as tmp:
    for size in sizes:
        w, h = size.split('x')
        for s in scenes:
            report = os.path.join(tmp, f'{tag}-{s}-{size}.json')
            scene = s if s == 'cornell' else os.path.join(scenes_dir, s)
            cmd = [binary, '--scene', scene, '--width', w, '--height', h, '--ref-spp', spp, '--json', report] + extra
            t0, load_before = time.time(), os.getloadavg()[0]
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            r = subprocess.run(cmd, capture_output=True, text=True)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            # CPU seconds of the whole run (setup, references from the cache, frame): less
            # inflated by the load than wall-clock times.
            cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            if r.returncode != 0:
                print(s, size, 'failed:', r.stderr[-500:], flush=True)
                continue
            j = json.load(open(report))
            e = j['error']
            row = {'tag': tag, 'scene': s, 'size': size, 'reference_spp': int(spp), 'records': j['records'],
                   'records_per_pixel': j['records'] / (int(w) * int(h)), 'rel_rms': e['rel_rms'],
                   'rel_rms_debiased': e.get('rel_rms_debiased'), 'rel_rms_debiased_se': e.get('rel_rms_debiased_se'),
                   'reference_noise': e.get('reference_noise_rel_rms'), 'rays_per_record': j.get('rays_per_record'),
                   'compute_records_ms_loaded_machine': j['timings_ms'].get('compute_records'),
                   'total_ms_loaded_machine': j['timings_ms']['total'], 'cpu_s': cpu_s, 'options': ' '.join(extra),
                   'commit': commit, 'load_before': load_before, 'load_average': os.getloadavg()[0],
                   'cores': os.cpu_count()}
            # --mc-compare: Monte Carlo at equal (debiased) error and its time over the cache's.
            if 'mc_equal_error' in j:
                row['mc_equal_error'] = j['mc_equal_error']
            # --verify: the verification pass's counts (docs/irradiance-splatting.md, "Error the
            # records cannot see").
            for k in ('verify_tiles', 'verify_disagreed', 'verify_shrunk', 'verify_ms'):
                if k in j:
                    row[k] = j[k]
            out.write(json.dumps(row) + '\n')
            out.flush()
            deb = row['rel_rms_debiased']
            print(f"{tag} {s} {size}: {row['records']} records ({row['records_per_pixel']:.3f} per pixel), "
                  f"debiased rel_rms {deb if deb is None else round(deb, 4)}, {time.time() - t0:.0f} s, cpu {cpu_s:.1f} s"
                  + (f", Monte Carlo {row['mc_equal_error'].get('speedup', 0):.1f}x" if 'mc_equal_error' in row else ''),
                  flush=True)
