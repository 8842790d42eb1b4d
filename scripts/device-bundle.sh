#!/usr/bin/env bash
# Packs what the GPU machine needs to run the device check into one small
# folder (the device tool carries at most 64 MiB of ignored paths): the GPU
# tests, the GPU fluid and coupling benchmarks, the CPU fluid benchmark and flocsim itself, built here with
# the CUDA back-end, and every shared library they load except the CUDA driver,
# which is the machine's own. The C library and its loader go apart, in
# lib/glibc, used only where the machine's own C library is older than the one
# the bundle was built against (scripts/device-check.sh decides).
# Usage: scripts/device-bundle.sh [BUILD_DIR] [BUNDLE_DIR]
#   defaults: build/device  build/device-bundle
# Build first with the device preset (x86-64-v3: the GPU machine's processor
# is not known here, and a native build may stop there with "Illegal
# instruction"):
#   cmake --preset device && cmake --build --preset device -j 2
# Then, on the GPU machine, from the repository root:
#   scripts/device-check.sh build/device-bundle "$OUT"
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/device}
bundle=${2:-build/device-bundle}
programs=(
  "$build/tests/lattice_gpu/test_gpu_lattice"
  "$build/tests/coupling_gpu/test_gpu_coupling"
  "$build/bench/bench_fluid_gpu"
  "$build/bench/bench_coupling_gpu"
  "$build/bench/bench_fluid"
  "$build/apps/flocsim"
)
for p in "${programs[@]}"; do
  if [[ ! -x $p ]]; then
    echo "device-bundle: $p is missing: build first (cmake --preset device &&" \
         "cmake --build --preset device -j 2)" >&2
    exit 2
  fi
done
if [[ ! -f $build/engine/libflocsim_lattice_gpu_kernels.a ]]; then
  echo "device-bundle: $build was configured without the CUDA back-end" >&2
  exit 2
fi
rm -rf "$bundle.tmp"
mkdir -p "$bundle.tmp/bin" "$bundle.tmp/lib/glibc"
cp "${programs[@]}" "$bundle.tmp/bin/"
# libraries: everything ldd resolves, less the CUDA driver (the machine's
# own). The C library, its loader and the libraries that come with it (they
# use each other's private symbols, so they go together or not at all) go to
# lib/glibc: the programs and the libraries built here on Debian 12 want
# symbols of its C library (2.36: arc4random in libstdc++, hypot@2.35), which
# an older machine (Ubuntu 22.04: 2.35; RHEL 9: 2.34) lacks; there the device
# check starts each program through the bundled loader instead.
for p in "${programs[@]}"; do
  ldd "$p" | awk '/=> \// {print $3} /^[[:space:]]*\/.*ld-linux/ {print $1}'
done | sort -u | while read -r lib; do
  case "$(basename "$lib")" in
    libcuda.so.*|libnss_*) ;;
    libc.so.*|libm.so.*|ld-linux*|libpthread.so.*|libdl.so.*|librt.so.*|libresolv.so.*|\
      libnsl.so.*|libutil.so.*|libanl.so.*|libmvec.so.*) cp -L "$lib" "$bundle.tmp/lib/glibc/" ;;
    *) cp -L "$lib" "$bundle.tmp/lib/" ;;
  esac
done
if ! ls "$bundle.tmp"/lib/glibc/ld-linux* > /dev/null 2>&1; then
  echo "device-bundle: the loader (ld-linux*) was not found by ldd" >&2
  exit 1
fi
# The rest of the C library's family, which the programs do not name but the
# machine's CUDA driver (loaded at run time) does: with the bundled C library
# these must be its companions too, not the machine's (below glibc 2.34 they
# are real libraries that use their own C library's private symbols).
libc_dir=$(dirname "$(ldd "${programs[-1]}" | awk '/libc\.so\.6 => \// {print $3}')")
for name in libpthread.so.0 libdl.so.2 librt.so.1 libutil.so.1 libanl.so.1 libmvec.so.1; do
  [[ -e $libc_dir/$name ]] && cp -L "$libc_dir/$name" "$bundle.tmp/lib/glibc/"
done
# its version, for the device check's comparison with the machine's (sed reads
# all of ldd's output: `head` would end the pipe early, and ldd's SIGPIPE
# would stop this script under pipefail)
ldd --version 2>&1 | sed -n '1s/.* //p' > "$bundle.tmp/lib/glibc/version.txt"
# The vector instructions the build assumed, which the device check looks for
# in the processor before it starts: a native build's are this processor's
# (more than any other may have); the device preset's are x86-64-v3's.
march=$(sed -n 's/^FLOCSIM_MARCH:STRING=//p' "$build/CMakeCache.txt")
if [[ $march == x86-64-v3 ]]; then
  echo "avx avx2 fma bmi1 bmi2 f16c movbe" | tr ' ' '\n' > "$bundle.tmp/cpu-flags.txt"
elif [[ -n $march ]]; then
  echo "device-bundle: FLOCSIM_MARCH=$march: no flag list for it; the device check will not" \
       "check the processor" >&2
elif grep -q "FLOCSIM_NATIVE:BOOL=ON" "$build/CMakeCache.txt"; then
  echo "device-bundle: $build is a native build: it runs only on processors with every vector" \
       "instruction of this one; the device preset (x86-64-v3) is the safe build to carry" >&2
  grep -o -w "avx[0-9a-z_]*\|fma\|f16c\|bmi[12]\|vpclmulqdq\|gfni\|vaes" /proc/cpuinfo |
    sort -u > "$bundle.tmp/cpu-flags.txt"
fi
# what was packed, for the device check's machine.txt
echo "$(git rev-parse --short HEAD 2> /dev/null)$(git diff --quiet 2> /dev/null || echo +changes)" \
  "march=${march:-native?} $(nvcc --version 2> /dev/null | tail -n 1)" > "$bundle.tmp/build.txt"
strip --strip-unneeded "$bundle.tmp"/bin/* 2>/dev/null || true
rm -rf "$bundle"
mv "$bundle.tmp" "$bundle"
du -sh "$bundle"
size=$(du -sm "$bundle" | cut -f1)
if ((size > 60)); then
  echo "device-bundle: $bundle is $size MiB, more than the device tool carries (64 MiB in all)" >&2
  exit 1
fi
