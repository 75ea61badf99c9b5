#!/usr/bin/env bash
# data/scenes is what tools/gen_scenes.c writes, byte for byte: regenerate
# into a scratch folder and compare every file.
set -euo pipefail
gen=$1 root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$gen" "$tmp" >/dev/null
n=0
for f in "$tmp"/*; do
  cmp "$f" "$root/data/scenes/$(basename "$f")" || { echo "FAIL: $(basename "$f") differs from the checked-in copy"; exit 1; }
  n=$((n + 1))
done
[ "$n" -ge 10 ] || { echo "FAIL: only $n files generated"; exit 1; }
total=$(du -cb "$root"/data/scenes/* | tail -1 | cut -f1)
[ "$total" -lt 15000000 ] || { echo "FAIL: data/scenes is $total bytes"; exit 1; }
echo "ok: $n files reproduce, $total bytes"
