#!/usr/bin/env bash
# One GI technique against POV-Ray's radiosity on cornell_pov at 64x48:
# its mean error must lie below dl+esm's by a stated margin (ambient 0 on the
# engine's side, as the export has none). The reference is rendered here, with
# the export's (the seed's) radiosity settings. Skipped (77) without povray.
#   test_gi_reference.sh LIMN ROOT NAME TECH [MIN_RATIO..]MAX_RATIO [--set ...]
# passes when MIN_RATIO * error(dl+esm) <= error(TECH) <= MAX_RATIO * error(dl+esm).
set -u
limn=$1 root=$2 name=$3 tech=$4 ratio=${5#*..} low=0
case $5 in *..*) low=${5%%..*} ;; esac
shift 5
. "$(dirname "$0")/shell_test.sh"
needs povray "tools/dev.sh installs it"
scratch gi
size=64x48 w=64 h=48
"$limn" export-pov --scene cornell_pov --size $size --output "$tmp/ref.pov" || fail "export-pov"
(cd "$tmp" && povray -D -V +Iref.pov +Oref.exr +FE +W$w +H$h -A >"$tmp/pov.log" 2>&1) \
  || { sed 's/^/  | /' "$tmp/pov.log" | tail -20; fail "povray could not render the reference"; }
error_of() { # TECH [--set ...]: mean error against the reference
  local t=$1
  shift
  "$limn" capture --scene cornell_pov --script "$root/scripts/pp.lua" --tech "$t" --set ambient=0 "$@" \
    --size $size --output "$tmp/$t.exr" --quiet || fail "capture $t $*"
  "$limn" compare "$tmp/$t.exr" "$tmp/ref.exr" --json | grep -o '"mean_error": [-0-9.e+]*' | awk '{print $2}'
}
base=$(error_of dl+esm) || exit 1
e=$(error_of "$tech" "$@") || exit 1
echo "$name ($tech $*) at $size: mean error $e; dl+esm $base; ratio $(awk -v e="$e" -v b="$base" \
  'BEGIN { printf "%.4f", e / b }'), bounds $low..$ratio"
awk -v e="$e" -v b="$base" -v r="$ratio" -v l="$low" 'BEGIN { exit !(e <= r * b && e >= l * b) }' \
  || fail "$name: mean error $e is not within $low..$ratio x dl+esm's $base"
echo "passed"
