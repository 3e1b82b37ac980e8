#!/usr/bin/env python3
"""The verification pass against the defaults (issue 28, third session): one markdown row per
scene from docs/results/ic_verification.jsonl (rows of docs/studies/ic_image_size.py run with
--mc-compare), the last row of each (tag, scene).

    docs/studies/ic_verification_table.py [RESULTS.jsonl] [TAG_A TAG_B]

Monte Carlo at equal error: where the sweep (--mc-max-spp) did not reach the cache's debiased
error, its spp and time are extrapolated from the last measured run with the debiased error
falling as spp^-1/2 (exact for independent samples: the reference's noise is taken out of the
error), spp' = spp (e / target)^2 and time in proportion; such ratios are marked "~".

"rays": the same comparison counted in rays, which the machine's load does not move: Monte
Carlo's spp times the pixels against the records' 1,026 rays each plus, with --verify, the
probes' 8 rays on half the pixels (an upper bound: pixels that see nothing are not probed). The
batched scan's wasted guesses (5-20% more records measured) and the splats are left out."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results import monte_carlo_at_equal_error as monte_carlo, monte_carlo_rays_ratio as rays  # noqa: E402

root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
args = sys.argv[1:]
path = args.pop(0) if args and args[0].endswith('.jsonl') else os.path.join(root, 'docs/results/ic_verification.jsonl')
tags = args[:2] if len(args) >= 2 else ['defaults', 'verify2']
order = ['cornell', 'cornell-box', 'bunny', 'sponza', 'conference', 'living-room', 'modern-hall']

rows = {}
for line in open(path):
    r = json.loads(line)
    if r['tag'] in tags:
        rows[(r['tag'], r['scene'])] = r


def cell(r):
    if r is None:
        return 'not run', '', '', '', ''
    mc = monte_carlo(r)
    ratio = '' if mc is None else f"{'~' if mc[2] else ''}{mc[0]:.1f}x ({mc[1]:.0f} spp)"
    by_rays = '' if mc is None else f"{rays(r, mc[1]):.1f}x"
    return (f"{r['records']:,}", f"{r['rel_rms_debiased']:.4f}", f"{r['total_ms_loaded_machine'] / 1000:.1f} s", ratio, by_rays)


print(f"| scene | {tags[0]}: records | rel_rms | time | Monte Carlo at equal error | rays | {tags[1]}: records | rel_rms | time "
      f"| Monte Carlo at equal error | rays | tiles disagreed | load |")
print('|---|' + '---|' * 12)
for s in order:
    a, b = rows.get((tags[0], s)), rows.get((tags[1], s))
    if a is None and b is None:
        continue
    extra = f"{b.get('verify_disagreed', '')}" if b else ''
    load = ' / '.join(f"{r['load_average']:.0f}" for r in (a, b) if r)
    print(f"| {s} | " + ' | '.join(cell(a)) + ' | ' + ' | '.join(cell(b)) + f" | {extra} | {load} |")
