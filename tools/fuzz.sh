#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a
# bounded time from its checked-in seed corpus (tests/fuzz/corpus/<target>).
# A crash, leak or sanitizer report fails the run; the input that caused it
# is left in build-fuzz/ as crash-*/leak-* for a regression test.
#   tools/fuzz.sh [SECONDS_PER_TARGET]   (default 20)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DLIMN_FUZZ=ON -DCMAKE_BUILD_TYPE=Debug >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target fuzz_shader_source fuzz_gltf fuzz_pipeline fuzz_job
for target in fuzz_shader_source fuzz_gltf fuzz_pipeline fuzz_job; do
  work=$(mktemp -d)
  echo "fuzzing $target for ${seconds}s"
  log=$(mktemp)
  if ! (cd build-fuzz && "./tests/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
          -print_final_stats=1 "$work" "../tests/fuzz/corpus/$target" >"$log" 2>&1); then
    grep -v "^INFO\|^#" "$log" | head -60 # the sanitizer's report and the input's file name
    rm -rf "$work" "$log"
    exit 1
  fi
  tail -4 "$log"
  rm -rf "$work" "$log"
done
