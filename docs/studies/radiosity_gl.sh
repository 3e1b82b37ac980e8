#!/usr/bin/env bash
# Runs the GL radiosity study behind docs/radiosity-gl.md: the Cornell box (about 10,000
# elements) to 90% convergence with gl::progressive_radiosity and, in the same process and on
# the same atlas, cpu::progressive_radiosity; adds each run's report (with its commit and
# machine) to the study's one results file, docs/results/radiosity_gl.json (committed).
# Usage: docs/studies/radiosity_gl.sh [BUILD_DIR]   (default build; needs study_gl_radiosity)
# Takes about a minute on 2 cores with llvmpipe.
set -euo pipefail
cd "$(dirname "$0")/../.."
build="${1:-build}"
results=docs/results/radiosity_gl.json
runs="$build/runs/radiosity_gl"
rm -rf "$runs"
mkdir -p "$runs"
BOUNCE_STUDY_OUT="$runs" "$build/bin/study_gl_radiosity"
for report in "$runs"/*.json; do
  name=$(basename "$report" .json)
  python3 docs/studies/results.py add "$results" "$name" "$report" --study radiosity_gl
done
