#!/usr/bin/env bash
# Packs what the GPU machine needs to run the device check into one small
# folder (the device tool carries at most 64 MiB of ignored paths): the GPU
# tests, the GPU fluid and coupling benchmarks, the CPU fluid benchmark and flocsim itself, built here with
# the CUDA back-end, and every shared library they load except the C library
# and the loader, which the machine has (and the CUDA driver, which is its own).
# Usage: scripts/device-bundle.sh [BUILD_DIR] [BUNDLE_DIR]
#   defaults: build/release  build/device-bundle
# Then, on the GPU machine, from the repository root:
#   scripts/device-check.sh build/device-bundle "$OUT"
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/release}
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
    echo "device-bundle: $p is missing: build first (cmake --build --preset release)" >&2
    exit 2
  fi
done
if [[ ! -f $build/engine/libflocsim_lattice_gpu_kernels.a ]]; then
  echo "device-bundle: $build was configured without the CUDA back-end" >&2
  exit 2
fi
rm -rf "$bundle.tmp"
mkdir -p "$bundle.tmp/bin" "$bundle.tmp/lib"
cp "${programs[@]}" "$bundle.tmp/bin/"
# libraries: everything ldd resolves, less the C library and the loader
for p in "${programs[@]}"; do
  ldd "$p" | awk '/=> \// {print $3}'
done | sort -u | while read -r lib; do
  case "$(basename "$lib")" in
    libc.so.*|libm.so.*|ld-linux*|libpthread.so.*|libdl.so.*|librt.so.*|libcuda.so.*) ;;
    *) cp -L "$lib" "$bundle.tmp/lib/" ;;
  esac
done
# A native build (FLOCSIM_NATIVE, the default) runs only on processors with
# this one's vector instructions: the device check compares before it starts.
if grep -q "FLOCSIM_NATIVE:BOOL=ON" "$build/CMakeCache.txt"; then
  grep -o -w "avx[0-9a-z_]*\|fma\|f16c\|bmi[12]\|vpclmulqdq\|gfni\|vaes" /proc/cpuinfo |
    sort -u > "$bundle.tmp/cpu-flags.txt"
fi
strip --strip-unneeded "$bundle.tmp"/bin/* 2>/dev/null || true
rm -rf "$bundle"
mv "$bundle.tmp" "$bundle"
du -sh "$bundle"
size=$(du -sm "$bundle" | cut -f1)
if ((size > 60)); then
  echo "device-bundle: $bundle is $size MiB, more than the device tool carries (64 MiB in all)" >&2
  exit 1
fi
