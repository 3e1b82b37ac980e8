#!/usr/bin/env bash
# Copies the shared libraries gpu_timings needs at run time beyond a vendor's GL driver and
# the C library into BUILD/gpu-runtime, so that the build folder (bin/gpu_timings and that
# folder) runs on a machine where none of the project's dependencies are installed
# (scripts/gpu_timings.sh, docs/gpu-timings.md).
#
#   scripts/pack_gpu_runtime.sh BUILD [--apt]
#
# lib/       what `ldd bin/gpu_timings` resolves (libepoxy, libfmt, glvnd's libEGL and
#            libGLdispatch ...) plus libOpenGL.so.0, which libepoxy opens by name at run time;
# fallback/  libstdc++ and libgcc_s, which gpu_timings.sh puts on the path only where the
#            GPU machine's own are missing or too old.
# Left out: the C library and the loader (they must be the machine's own), and every Mesa
# library (libEGL_mesa, libGLX_mesa, libgbm, libglapi, DRI drivers): the vendor's driver
# does the GL there. --apt takes the files from the Debian packages they belong to instead
# (apt-get download + dpkg -x), for a system where only the development packages' links are
# installed; it needs the package registry.
set -euo pipefail

die() { echo "pack_gpu_runtime.sh: $*" >&2; exit 2; }
[ $# -ge 1 ] || die "usage: scripts/pack_gpu_runtime.sh BUILD [--apt]"
build=$1
apt=0
[ "${2:-}" = "--apt" ] && apt=1
program="$build/bin/gpu_timings"
[ -x "$program" ] || die "$program is missing: build the gpu_timings target first"
dest="$build/gpu-runtime"
rm -rf "$dest"
mkdir -p "$dest/lib" "$dest/fallback"

# name -> path of every library the program loads, and libOpenGL.so.0 that libepoxy dlopens.
declare -A found
while read -r name path; do
  found[$name]=$path
done < <(ldd "$program" | awk '$2 == "=>" && $3 ~ /^\// { print $1, $3 }')
opengl=$(ldconfig -p | awk '$1 == "libOpenGL.so.0" && /x86-64/ && !seen { print $NF; seen = 1 }')
[ -n "$opengl" ] && found[libOpenGL.so.0]=$opengl

for name in "${!found[@]}"; do
  case "$name" in
    linux-vdso*|ld-linux*|libc.so*|libm.so*|libpthread.so*|libdl.so*|librt.so*|libresolv.so*) continue ;;
    *mesa*|libgbm*|libglapi*|*_dri*) die "$name would bring Mesa's GL along: not packed" ;;
    libstdc++.so*|libgcc_s.so*) where=fallback ;;
    *) where=lib ;;
  esac
  if [ $apt = 1 ]; then
    # dpkg knows a file by the path its package ships (/lib or /usr/lib, link or target).
    package=""
    for path in "${found[$name]}" "$(readlink -f "${found[$name]}")" "${found[$name]/#\/lib\//\/usr\/lib\/}"; do
      package=$(dpkg -S "$path" 2>/dev/null | awk -F: 'NR == 1 { print $1 }') || true
      [ -n "$package" ] && break
    done
    [ -n "$package" ] || die "no Debian package owns ${found[$name]}"
    scratch=$(mktemp -d)
    (cd "$scratch" && apt-get download -q "$package" > /dev/null && dpkg -x ./*.deb root)
    cp -L "$(find "$scratch/root" -name "$name" -print -quit)" "$dest/$where/$name"
    rm -rf "$scratch"
  else
    cp -L "${found[$name]}" "$dest/$where/$name"
  fi
  echo "pack_gpu_runtime.sh: $where/$name <- ${found[$name]}"
done

bytes=$(du -cb "$program" "$dest" | tail -1 | cut -f1)
echo "pack_gpu_runtime.sh: $dest and bin/gpu_timings: $((bytes / 1024)) KiB (the device tool carries 64 MiB at most)"
[ "$bytes" -lt $((64 * 1024 * 1024)) ] || die "more than 64 MiB to carry"
