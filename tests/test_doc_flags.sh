#!/usr/bin/env bash
# docs/commands.md and each command's --help name the same flags
# (tests/check_doc_flags.py), and the checker fails, naming the command and
# flag, on a flag the page lacks, one --help lacks, and a command without a
# section. Skipped (77) without python3.
set -euo pipefail
limn=${1:?usage: test_doc_flags.sh LIMN ROOT}
root=${2:?usage: test_doc_flags.sh LIMN ROOT}
command -v python3 >/dev/null || { echo "skipped: python3 not installed"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/docs" "$tmp/help"

# The checks of the checker read the help texts this first run saves.
python3 "$root/tests/check_doc_flags.py" "$limn" "$root" --save "$tmp/help"
check="python3 $root/tests/check_doc_flags.py $tmp/help"
expect_fail() {  # a sed script for the page, the line the checker must print
  sed "$1" "$root/docs/commands.md" >"$tmp/docs/commands.md"
  cmp -s "$root/docs/commands.md" "$tmp/docs/commands.md" && { echo "FAIL: '$1' changed nothing"; exit 1; }
  if out=$($check "$tmp"); then echo "FAIL: '$1' passed"; exit 1; fi
  echo "$out"
  grep -qxF "$2" <<<"$out" || { echo "FAIL: '$1' did not print '$2'"; exit 1; }
}
expect_fail 's/--diff-scale/DIFF-SCALE/g' 'limn compare: --diff-scale is in --help but not in docs/commands.md'
expect_fail '/^## limn capture/a --no-such-flag' 'limn capture: --no-such-flag is in docs/commands.md but not in --help'
expect_fail 's/^## limn compare/## compare/' 'limn compare: no "## limn compare" section in docs/commands.md'
echo "ok"
