#!/usr/bin/env python3
"""Where radiosity's view error is (issue 30, fourth session; docs/radiosity.md, "Where the error is").

For each scene: `radiosity --scene S --elements N --visibility rays --converge C --reference-paths 64
--curve-points 0 --shooter-groups 256 --oracle-out F` (examples/radiosity/oracle.hpp). The oracle
JSON splits the solve's view error into the lights' direct light and the rest, gives the
direct+indirect view's error (the lights per pixel, the rest looked up), and the error of the
best lightmap of the same atlas (the reference integrator over each texel), each against the
64-path reference and with the references' noise (a second seed) and the oracle's own noise
(two seeds) taken out. Appends one record per run, with provenance, to
docs/results/radiosity_oracle.json.

    python3 docs/studies/radiosity_oracle.py [--elements 100000] [--converge 0.9] [--scenes a,b] [--build build-charts]
        [--extra '--ambient on']

The oracle file also ranks the charts by their share of the bounced light's error
(indirect_by_chart, direct_by_chart) and writes the bounced light of the solver, the
reference and the oracle as PNGs beside it; --holes-out lists the black pixels (holes.hpp).
"""
import argparse, json, os, subprocess, sys, time, datetime

SCENES = ["cornell", "cornell-box", "bunny", "modern-hall", "sponza", "living-room", "conference"]
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--elements", type=int, default=100000)
    ap.add_argument("--converge", type=float, default=0.9)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--build", default="build-charts")
    ap.add_argument("--tmp", default="/tmp/radbound")
    ap.add_argument("--results", default=os.path.join(ROOT, "docs/results/radiosity_oracle.json"))
    ap.add_argument("--extra", default="", help="more radiosity options, e.g. '--ambient on'")
    ap.add_argument("--binary", default="", help="the radiosity program (default: BUILD/bin/radiosity)")
    ap.add_argument("--note", default="", help="provenance kept with each record (what the binary was built from)")
    a = ap.parse_args()
    os.makedirs(a.tmp, exist_ok=True)
    env = dict(os.environ)
    env.setdefault("BOUNCE_CACHE", os.path.join(ROOT, "build/cache"))
    env.setdefault("BOUNCE_SCENES", os.path.join(os.path.dirname(ROOT), "shared/scenes"))
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    results = json.load(open(a.results)) if os.path.exists(a.results) else {"runs": []}
    for scene in a.scenes.split(","):
        stem = os.path.join(a.tmp, f"{scene}-{a.elements}")
        cmd = [a.binary or os.path.join(ROOT, a.build, "bin/radiosity"), "--scene", scene, "--elements", str(a.elements),
               "--visibility", "rays", "--converge", str(a.converge), "--reference-paths", "64", "--curve-points", "0",
               "--shooter-groups", "256", "--quiet", "--json", stem + ".json", "--oracle-out", stem + "-oracle.json",
               "--holes-out", stem + "-holes.csv"] + a.extra.split()
        load = os.getloadavg()[0]  # the 1-minute load average before the run
        t0 = time.time()
        p = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if p.returncode != 0:
            print(scene, "failed:", p.stderr[-2000:], file=sys.stderr)
            continue
        run = json.load(open(stem + ".json"))
        oracle = json.load(open(stem + "-oracle.json"))
        rec = {"scene": scene, "elements_asked": a.elements, "converge": a.converge, "commit": commit,
               "command": " ".join(cmd[1:]), "note": a.note, "date": datetime.datetime.utcnow().isoformat(timespec="seconds") + "Z",
               "load_before": load, "load_after": os.getloadavg()[0], "wall_s_loaded": time.time() - t0,
               "run": {k: run.get(k) for k in ("counts", "error", "black_pixels", "elements",
                                               "iterations", "timings_ms", "indirect_unshot_fraction")},
               "split": oracle}
        # The per-step convergence series is left out (no table reads it): its last value only.
        for k in ("indirect_by_chart", "direct_by_chart"):  # the 12 charts with the largest share
            if isinstance(oracle.get(k), list):
                oracle[k] = oracle[k][:12]
        rec["run"]["converged_fraction_final"] = (run.get("converged_fraction") or [None])[-1]
        # Read again before appending: another run of this script may have added records since.
        results = json.load(open(a.results)) if os.path.exists(a.results) else {"runs": []}
        results["runs"].append(rec)
        json.dump(results, open(a.results, "w"), indent=1)
        s, o = oracle["solver"], oracle["oracle"]
        print(f"{scene} {oracle['elements']}: solver {s['total']['rel_rms']:.4f}/{s['total']['rel_rms_noise_removed']:.4f} "
              f"direct {s['direct']['rel_rms_noise_removed']:.4f} indirect {s['indirect']['rel_rms_noise_removed']:.4f} "
              f"d+i view {s['direct_indirect_view']['rel_rms']:.4f}/{s['direct_indirect_view']['rel_rms_noise_removed']:.4f} "
              f"black {run.get('black_pixels')}->{s['direct_indirect_black_pixels']} | oracle "
              f"{o['total']['rel_rms_all_noise_removed']:.4f} direct {o['direct']['rel_rms_all_noise_removed']:.4f} "
              f"indirect {o['indirect']['rel_rms_all_noise_removed']:.4f} black {o['black_pixels']} (load {load:.1f})",
              flush=True)


if __name__ == "__main__":
    main()
