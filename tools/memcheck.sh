#!/usr/bin/env bash
# One small capture under valgrind's memcheck: fails when anything is
# definitely lost. (Other reports come from the dynamic loader and Mesa's
# driver, which the project does not own; the log keeps them for reading.)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
log=$(mktemp /tmp/limn-memcheck-XXXXXX.log)
out=$(mktemp -d)
rc=0
valgrind --leak-check=full --log-file="$log" "$build/limn" capture --scene cornell --tech dl+esm \
  --size 64x48 --quiet --output "$out/frame.png" || rc=$?
rm -rf "$out"
# Some virtual CPUs hide RDTSCP from cpuid while a library executes it anyway
# (libhwy's start-up did, when OpenImageIO was linked; a PNG capture no longer
# loads either, engine/image/image.c): valgrind then stops before limn's main
# with "Unrecognised instruction". That is valgrind and this CPU, not the
# project; say so and leave leaks to the LeakSanitizer suite.
if [ "$rc" -ne 0 ] && grep -q "valgrind: Unrecognised instruction" "$log"; then
  where=$(grep -A1 "valgrind: Unrecognised instruction" "$log" | tail -1 | sed 's/^==[0-9]*== *//')
  echo "memcheck: skipped: valgrind cannot run this CPU's code ($where); LeakSanitizer checks leaks in CI"
  rm -f "$log"
  exit 0
fi
[ "$rc" -eq 0 ] || { cat "$log"; exit "$rc"; }
summary=$(grep -E "definitely lost:" "$log" || echo "definitely lost: 0 bytes in 0 blocks")
echo "memcheck: ${summary#*== }"
if ! grep -qE "definitely lost: 0 bytes in 0 blocks" <<<"$summary"; then
  grep -B2 -A20 "definitely lost in" "$log" | head -80
  exit 1
fi
rm -f "$log"
