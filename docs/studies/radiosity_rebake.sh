#!/bin/sh
# Re-baking what changed (docs/radiosity.md, "Re-baking what changed"): on the Cornell boxes
# and every shared scene, one object moved and one light dimmed, each re-baked from the
# previous solution and solved fresh (build/bin/radiosity --rebake-move / --rebake-light, 30,000
# elements, ray casts, to 90% of the indirect power); the runs' JSON merged with provenance
# into docs/results/radiosity_rebake.json.
#   BIN=build/bin OUT=/tmp/rebake docs/studies/radiosity_rebake.sh
# BACKEND=gl: the GL solver instead (the Cornell boxes' tall block moved and the Cornell box's
# light halved, 5,000 elements, stereographic item buffers and hemicubes; Mesa's llvmpipe here
# unless a GPU's driver is current) into docs/results/radiosity_rebake_gl.json.
BIN=${BIN:-build/bin}
BACKEND=${BACKEND:-cpu}
OUT=${OUT:-/tmp/rebake-$BACKEND}
mkdir -p "$OUT"
run() {  # name scene check change-option value [extra]
    name=$1 scene=$2 check=$3 opt=$4 value=$5
    shift 5
    nice "$BIN/radiosity" --scene "$scene" --quiet --rebake-check "$check" "$opt" "$value" --json "$OUT/$name.json" "$@" ||
        echo "$name failed"
}
if [ "$BACKEND" = gl ]; then
    RESULT=docs/results/radiosity_rebake_gl.json
    OPTIONS="--backend gl --elements 5000 --converge 0.9 (indirect) --rebake-check 0.98 --reference off"
    for v in stereo hemicube; do
        gl="--backend gl --visibility $v --elements 5000 --reference off"
        run "cornell-tall-$v" cornell 0.98 --rebake-move 'white#2,0.1,0,0.1' $gl
        run "cornellbox-tall-$v" cornell-box 0.98 --rebake-move 'tallBox,0.1,0,0.1' $gl
        run "cornell-light-$v" cornell 0.98 --rebake-light 0,0.5 $gl
    done
else
    RESULT=docs/results/radiosity_rebake.json
    OPTIONS="--elements 30000 --visibility rays --converge 0.9 (indirect) --shooter-groups 0"
    cpu="--elements 30000 --visibility rays"
    run sponza-column sponza 0.97 --rebake-move 'default#67,0,0,0.3' --reference off $cpu
    run hall-bench modern-hall 0.97 --rebake-move 'Wood#11,0.3,0,0' --reference off $cpu
    run cornell-tall cornell 0.98 --rebake-move 'white#2,0.1,0,0.1' --reference on $cpu
    run living-table living-room 0.97 --rebake-move 'TableWood#1,0.2,0,0.2' --reference off $cpu
    run cornellbox-tall cornell-box 0.98 --rebake-move 'tallBox,0.1,0,0.1' --reference off $cpu
    run conference-chair conference 0.97 --rebake-move 'default#160,30,0,0' --reference off $cpu --clusters never  # the chair's tiny charts share a cluster with others'
    run cornell-light cornell 0.98 --rebake-light 0,0.5 --reference on $cpu
    run bunny-light bunny 0.97 --rebake-light 0,0.5 --reference off $cpu
fi
python3 - "$OUT" "$RESULT" "$OPTIONS" <<'PY'
import json, os, subprocess, sys, platform
out, result, options = sys.argv[1:4]
runs = [json.load(open(os.path.join(out, f))) | {"run": f[:-5]} for f in sorted(os.listdir(out)) if f.endswith(".json")]
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []
doc = {"provenance": {"commit": commit, "script": "docs/studies/radiosity_rebake.sh", "machine": platform.node(),
                      "load_average_at_end": load, "options": options},
       "runs": runs}
json.dump(doc, open(result, "w"), indent=1)
for r in runs:
    print(f'{r["run"]:24} ratio {r["ratio"]:.3f} fresh {r["fresh"]["ms"]:.0f} ms (setup {r["fresh"]["setup_ms"]:.0f}) '
          f'err {r["fresh"]["error"]:.4f} rebake {r["rebake"]["ms"]:.0f} ms (corr {r["rebake"]["correction_ms"]:.0f}, '
          f're-shots {r["rebake"]["shooters"]}) err {r["rebake"]["error"]:.4f} reached {r["rebake"]["reached"]} '
          f'pairs {r["pairs"]["ratio"]:.3f} apart {r["converged_rel_rms"]:.4f}')
PY
