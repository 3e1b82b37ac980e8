#!/bin/sh
# Re-baking what changed on the GL solver (docs/radiosity.md, "GL solver: re-bake and shaped
# ambient"): the Cornell boxes' tall block moved and the Cornell box's light dimmed, each
# re-baked from the previous GL solution and solved fresh on GL (build/bin/radiosity --backend
# gl, 5,000 elements, stereographic item buffers and hemicubes, to 90% of the indirect power;
# Mesa's llvmpipe here unless a GPU's driver is current); merged with provenance into
# docs/results/radiosity_rebake_gl.json.
#   BIN=build/bin OUT=/tmp/rebake-gl docs/studies/radiosity_rebake_gl.sh
BIN=${BIN:-build/bin}
OUT=${OUT:-/tmp/rebake-gl}
mkdir -p "$OUT"
run() {  # name scene visibility change-option value
    nice "$BIN/radiosity" --backend gl --scene "$2" --visibility "$3" --elements 5000 --quiet --reference off \
        --rebake-check 0.98 "$4" "$5" --json "$OUT/$1.json" || echo "$1 failed"
}
for v in stereo hemicube; do
    run "cornell-tall-$v" cornell $v --rebake-move 'white#2,0.1,0,0.1'
    run "cornellbox-tall-$v" cornell-box $v --rebake-move 'tallBox,0.1,0,0.1'
    run "cornell-light-$v" cornell $v --rebake-light 0,0.5
done
python3 - "$OUT" <<'PY'
import json, os, subprocess, sys, platform
out = sys.argv[1]
runs = [json.load(open(os.path.join(out, f))) | {"run": f[:-5]} for f in sorted(os.listdir(out)) if f.endswith(".json")]
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
load = open("/proc/loadavg").read().split()[:3] if os.path.exists("/proc/loadavg") else []
doc = {"provenance": {"commit": commit, "script": "docs/studies/radiosity_rebake_gl.sh", "machine": platform.node(),
                      "load_average_at_end": load,
                      "options": "--backend gl --elements 5000 --converge 0.9 (indirect) --rebake-check 0.98"},
       "runs": runs}
json.dump(doc, open("docs/results/radiosity_rebake_gl.json", "w"), indent=1)
for r in runs:
    print(f'{r["run"]:22} ratio {r["ratio"]:.3f} fresh {r["fresh"]["ms"]:.0f} ms (setup {r["fresh"]["setup_ms"]:.0f}) '
          f'err {r["fresh"]["error"]:.4f} rebake {r["rebake"]["ms"]:.0f} ms (corr {r["rebake"]["correction_ms"]:.0f}, '
          f're-shots {r["rebake"]["shooters"]}) err {r["rebake"]["error"]:.4f} reached {r["rebake"]["reached"]} '
          f'apart {r["converged_rel_rms"]:.4f}')
PY
