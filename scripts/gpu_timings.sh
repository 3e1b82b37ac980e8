#!/usr/bin/env bash
# Runs the fixed set of GL timings (docs/gpu-timings.md) from a build folder made on another
# machine, with the runtime libraries scripts/pack_gpu_runtime.sh unpacked beside it, on the
# vendor's OpenGL driver of this machine, and writes one JSON results file.
#
#   scripts/gpu_timings.sh --build DIR [--runtime DIR] [--out FILE] [--sizes WxH,...]
#                          [--timeout SECONDS] [--check] [-- gpu_timings options...]
#
# --build    the build folder holding bin/gpu_timings (a GL-only build will do:
#            -DBOUNCE_WITH_IO=OFF -DBOUNCE_WITH_EMBREE=OFF)
# --runtime  the libraries pack_gpu_runtime.sh copied (default DIR/gpu-runtime; none: the
#            system's own)
# --out      the results file (default gpu_timings.json)
# --sizes    image sizes (default 1920x1080,512x512; on llvmpipe say 64x64)
# --timeout  the program is stopped after this many seconds (default 290: under 5 minutes)
# --check    the results file must pass scripts/check_gpu_timings.py (python3 required);
#            without it the check runs when python3 is there
# Options after -- go to the program (--repeat N, --subdivide N, ...: gpu_timings --help).
#
# The vendor's GL: the NVIDIA driver's folders (/usr/local/nvidia/lib64, where the lent GPU
# machines mount it) go on LD_LIBRARY_PATH and its EGL vendor file is named in
# __EGL_VENDOR_LIBRARY_FILENAMES (unless set already), so glvnd's libEGL loads the vendor's
# driver, never Mesa's. Without one, glvnd picks what the system offers (Mesa's llvmpipe here).
#
# Exit status: 0 done; 3 no OpenGL 4.5 context could be made (one line says why); 124 the
# timeout; 4 the results file is not well formed; 2 bad use; else the program's.
set -euo pipefail

die() { echo "gpu_timings.sh: $*" >&2; exit 2; }

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build="" runtime="" out="gpu_timings.json" sizes="1920x1080,512x512" limit=290 check=0
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=${2:?--build needs a folder}; shift 2 ;;
    --runtime) runtime=${2:?--runtime needs a folder}; shift 2 ;;
    --out) out=${2:?--out needs a file}; shift 2 ;;
    --sizes) sizes=${2:?--sizes needs WxH,...}; shift 2 ;;
    --timeout) limit=${2:?--timeout needs seconds}; shift 2 ;;
    --check) check=1; shift ;;
    --) shift; args=("$@"); break ;;
    -h|--help) sed -n "2,26p" "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option $1 (see --help)" ;;
  esac
done
[ -n "$build" ] || die "--build DIR is required (see --help)"
program="$build/bin/gpu_timings"
[ -x "$program" ] || die "$program is missing: build the gpu_timings target in $build"
[[ "$limit" =~ ^[0-9]+$ ]] && [ "$limit" -gt 0 ] || die "--timeout must be a positive number of seconds"

# Libraries: the packed ones first, the vendor's driver folders after them.
[ -n "$runtime" ] || runtime="$build/gpu-runtime"
paths=()
[ -d "$runtime/lib" ] && paths+=("$runtime/lib")
for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib; do
  [ -d "$d" ] && paths+=("$d")
done
if [ -z "${__EGL_VENDOR_LIBRARY_FILENAMES:-}" ]; then
  for f in /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json \
           /etc/glvnd/egl_vendor.d/10_nvidia.json; do
    if [ -f "$f" ]; then export __EGL_VENDOR_LIBRARY_FILENAMES="$f"; break; fi
  done
fi
join() { local IFS=:; echo "$*"; }
if [ ${#paths[@]} -gt 0 ]; then
  export LD_LIBRARY_PATH="$(join "${paths[@]}")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
# The packed C++ runtime only where this system's is missing or older than the build's.
unresolved() { ldd "$program" 2>&1 | grep "not found" || true; }
if [ -d "$runtime/fallback" ] && [ -n "$(unresolved)" ]; then
  export LD_LIBRARY_PATH="$runtime/fallback${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
fi
missing=$(unresolved)
[ -z "$missing" ] || die "libraries not found (pack them with scripts/pack_gpu_runtime.sh): $(echo "$missing" | tr '\n' ' ')"
echo "gpu_timings.sh: LD_LIBRARY_PATH=${LD_LIBRARY_PATH:-} __EGL_VENDOR_LIBRARY_FILENAMES=${__EGL_VENDOR_LIBRARY_FILENAMES:-(unset: glvnd picks)}"

status=0
timeout --kill-after=10 "$limit" "$program" --sizes "$sizes" --out "$out" ${args[@]+"${args[@]}"} || status=$?
case $status in
  0) ;;
  3) echo "gpu_timings.sh: no OpenGL 4.5 context on this machine (the line above says why)" >&2; exit 3 ;;
  124|137) echo "gpu_timings.sh: stopped after ${limit} s: ask for fewer --sizes or -- --repeat" >&2; exit 124 ;;
  *) echo "gpu_timings.sh: gpu_timings failed with status $status" >&2; exit $status ;;
esac

if command -v python3 > /dev/null; then
  python3 "$here/check_gpu_timings.py" "$out" --sizes "$sizes" || exit 4
elif [ $check = 1 ]; then
  die "--check needs python3"
fi
