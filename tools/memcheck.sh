#!/usr/bin/env bash
# One small capture under valgrind's memcheck: fails when anything is
# definitely lost. (Other reports come from the dynamic loader and Mesa's
# driver, which the project does not own; the log keeps them for reading.)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
log=$(mktemp /tmp/limn-memcheck-XXXXXX.log)
out=$(mktemp -d)
valgrind --leak-check=full --log-file="$log" "$build/limn" capture --scene cornell --tech dl+esm \
  --size 64x48 --quiet --output "$out/frame.png"
rm -rf "$out"
summary=$(grep -E "definitely lost:" "$log" || echo "definitely lost: 0 bytes in 0 blocks")
echo "memcheck: ${summary#*== }"
if ! grep -qE "definitely lost: 0 bytes in 0 blocks" <<<"$summary"; then
  grep -B2 -A20 "definitely lost in" "$log" | head -80
  exit 1
fi
rm -f "$log"
