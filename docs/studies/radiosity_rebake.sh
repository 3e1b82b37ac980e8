#!/bin/sh
# Re-baking what changed (docs/radiosity.md, "Re-baking what changed"): on the Cornell boxes
# and every shared scene, one object moved and one light dimmed, each re-baked from the
# previous solution and solved fresh (build/bin/radiosity --rebake-move / --rebake-light, 30,000
# elements, ray casts, to 90% of the indirect power); the runs' JSON merged with provenance
# into docs/results/radiosity_rebake.json.
#   BIN=build/bin OUT=/tmp/rebake docs/studies/radiosity_rebake.sh
BIN=${BIN:-build/bin}
OUT=${OUT:-/tmp/rebake}
mkdir -p "$OUT"
run() {  # name scene check change-option value [extra]
    name=$1 scene=$2 check=$3 opt=$4 value=$5
    shift 5
    nice "$BIN/radiosity" --scene "$scene" --elements 30000 --visibility rays --quiet --rebake-check "$check" \
        "$opt" "$value" --json "$OUT/$name.json" "$@" || echo "$name failed"
}
run sponza-column sponza 0.97 --rebake-move 'default#67,0,0,0.3' --reference off
run hall-bench modern-hall 0.97 --rebake-move 'Wood#11,0.3,0,0' --reference off
run cornell-tall cornell 0.98 --rebake-move 'white#2,0.1,0,0.1' --reference on
run living-table living-room 0.97 --rebake-move 'TableWood#1,0.2,0,0.2' --reference off
run cornellbox-tall cornell-box 0.98 --rebake-move 'tallBox,0.1,0,0.1' --reference off
run conference-chair conference 0.97 --rebake-move 'default#160,30,0,0' --reference off
run cornell-light cornell 0.98 --rebake-light 0,0.5 --reference on
run bunny-light bunny 0.97 --rebake-light 0,0.5 --reference off
python3 - "$OUT" <<'PY'
import json, os, subprocess, sys, platform
out = sys.argv[1]
runs = [json.load(open(os.path.join(out, f))) | {"run": f[:-5]} for f in sorted(os.listdir(out)) if f.endswith(".json")]
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []
doc = {"provenance": {"commit": commit, "script": "docs/studies/radiosity_rebake.sh", "machine": platform.node(),
                      "load_average_at_end": load,
                      "options": "--elements 30000 --visibility rays --converge 0.9 (indirect) --shooter-groups 0"},
       "runs": runs}
json.dump(doc, open("docs/results/radiosity_rebake.json", "w"), indent=1)
for r in runs:
    print(f'{r["run"]:18} ratio {r["ratio"]:.3f} fresh {r["fresh"]["ms"]:.0f} ms err {r["fresh"]["error"]:.4f} '
          f'rebake {r["rebake"]["ms"]:.0f} ms (corr {r["rebake"]["correction_ms"]:.0f}) err {r["rebake"]["error"]:.4f} '
          f'reached {r["rebake"]["reached"]} pairs {r["pairs"]["ratio"]:.3f} apart {r["converged_rel_rms"]:.4f}')
PY
