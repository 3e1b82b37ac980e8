#!/usr/bin/env bash
# gpu_timings.sh where EGL has no driver (glvnd pointed at a vendor file that does not
# exist): it must end with status 3, the program's one line naming the missing context, and
# leave no results file.
set -u
script=$1 build=$2
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
status=0
__EGL_VENDOR_LIBRARY_FILENAMES="$scratch/none.json" bash "$script" --build "$build" --sizes 8x8 \
  --out "$scratch/results.json" > "$scratch/stdout" 2> "$scratch/stderr" || status=$?
cat "$scratch/stderr"
fail() { echo "no_context.sh: $*"; exit 1; }
[ $status = 3 ] || fail "exit status $status, expected 3"
lines=$(grep -c "^gpu_timings: no OpenGL 4.5 context: " "$scratch/stderr")
[ "$lines" = 1 ] || fail "expected one line 'gpu_timings: no OpenGL 4.5 context: ...' on stderr"
[ "$(grep -c '^gpu_timings: ' "$scratch/stderr")" = 1 ] || fail "the program printed more than one line"
[ ! -e "$scratch/results.json" ] || fail "a results file was left behind"
echo "no_context.sh: status 3, one line"
