#!/usr/bin/env bash
# data/scenes is what tools/gen_scenes.c writes, byte for byte: regenerate
# into a scratch folder and compare every file (the reference set's scenes
# under reference/ included).
set -euo pipefail
gen=$1 root=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$gen" "$tmp" >/dev/null
n=0
while IFS= read -r f; do
  cmp "$tmp/$f" "$root/data/scenes/$f" || { echo "FAIL: $f differs from the checked-in copy"; exit 1; }
  n=$((n + 1))
done < <(cd "$tmp" && find . -type f | sort)
[ "$n" -ge 16 ] || { echo "FAIL: only $n files generated"; exit 1; }
total=$(du -sb "$root"/data/scenes | cut -f1)
[ "$total" -lt 15000000 ] || { echo "FAIL: data/scenes is $total bytes"; exit 1; }
echo "ok: $n files reproduce, $total bytes"
