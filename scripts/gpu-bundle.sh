#!/usr/bin/env bash
# Packs the GI binaries (bench_gi, ldc_gi_tests, ldc) and the libraries they
# need beyond glibc into .gpu/bundle.tgz, for a machine with a GPU but none
# of the Debian packages (binaries built here, run there by
# scripts/gpu-gi-check.sh; libstdc++ goes into fallback/, used only where
# the machine's own is older than GCC 12's).
set -euo pipefail
cd "$(dirname "$0")/.."
stage=.gpu/stage
rm -rf "$stage" && mkdir -p "$stage/bin" "$stage/lib" "$stage/fallback"
bins=(build/bench/bench_gi build/tests/ldc_gi_tests build/tools/ldc)
cp "${bins[@]}" "$stage/bin/"
cp build/tools/*.so "$stage/bin/" 2>/dev/null || true  # plugins beside the tool
for lib in $(ldd "${bins[@]}" | awk '/=> \//{print $3}' | sort -u); do
  case "$lib" in
    */libc.so*|*/libm.so*|*/libgcc_s.so*) ;;
    */libstdc++*) cp -L "$lib" "$stage/fallback/" ;;
    *) cp -L "$lib" "$stage/lib/" ;;
  esac
done
tar czf .gpu/bundle.tgz -C "$stage" . && rm -rf "$stage"
ls -la .gpu/bundle.tgz
