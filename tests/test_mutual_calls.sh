#!/usr/bin/env bash
# No two source files of the build call each other both ways, nor two
# scripts require each other (tools/mutual_calls.py over the build's
# objects); and the checker fails, naming the pair, on two objects that do.
# Skipped (77) without python3 or nm.
set -euo pipefail
build=${1:?usage: test_mutual_calls.sh BUILD_DIR ROOT}
root=${2:?usage: test_mutual_calls.sh BUILD_DIR ROOT}
for p in python3 nm cc; do
  command -v "$p" >/dev/null || { echo "skipped: $p not installed"; exit 77; }
done
check="python3 $root/tools/mutual_calls.py"

$check "$build" "$root"

# A checkout of three files: a.c and b.c call each other, c.c calls a.c only.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/src" "$tmp/scripts" "$tmp/build/CMakeFiles/t.dir/src"
echo 'int b(void); int a(void) { return b() + 1; }' >"$tmp/src/a.c"
echo 'int a(void); int b(void) { return 2; } int b2(void) { return a(); }' >"$tmp/src/b.c"
echo 'int a(void); int c(void) { return a(); }' >"$tmp/src/c.c"
for f in a b c; do cc -c "$tmp/src/$f.c" -o "$tmp/build/CMakeFiles/t.dir/src/$f.c.o"; done
if out=$($check "$tmp/build" "$tmp"); then echo "FAIL: a.c and b.c passed"; echo "$out"; exit 1; fi
echo "$out"
grep -qxF 'src/a.c <-> src/b.c: src/a.c uses b, src/b.c uses a' <<<"$out" || { echo "FAIL: the pair not named"; exit 1; }
grep -qF '1 file pairs' <<<"$out" || { echo "FAIL: c.c's one-way call counted"; exit 1; }

# Two scripts that require each other.
rm "$tmp/build/CMakeFiles/t.dir/src/b.c.o"
echo 'require "y"' >"$tmp/scripts/x.lua"
echo 'local x = require("x")' >"$tmp/scripts/y.lua"
if out=$($check "$tmp/build" "$tmp"); then echo "FAIL: x.lua and y.lua passed"; echo "$out"; exit 1; fi
echo "$out"
grep -qF 'scripts/x.lua <-> scripts/y.lua' <<<"$out" || { echo "FAIL: the scripts not named"; exit 1; }
echo "ok"
