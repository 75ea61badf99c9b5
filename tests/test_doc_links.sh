#!/usr/bin/env bash
# The docs' relative links resolve and README.md links every docs page
# (tests/check_doc_links.py on this checkout), and the checker fails, naming
# file:line, on a link to a missing file, outside the checkout or to an
# anchor no heading has, and names a page README.md does not link. Skipped
# (77) without python3.
set -euo pipefail
root=${1:?usage: test_doc_links.sh ROOT}
command -v python3 >/dev/null || { echo "skipped: python3 not installed"; exit 77; }
check="python3 $root/tests/check_doc_links.py"

$check "$root"

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
tmp=$scratch/checkout
mkdir -p "$tmp/docs"
touch "$scratch/outside.md"  # exists, but not in the checkout
cat >"$tmp/docs/page.md" <<'EOF'
# A page

## Two words, `code` and more
EOF

# Every form the checker reads, all good: it passes and counts them.
cat >"$tmp/README.md" <<'EOF'
# Top
[page](docs/page.md), [heading](docs/page.md#two-words-code-and-more), [here](#top), [web](https://example.org/x)
![picture](docs/page.md)

[ref]: docs/page.md
`[in code](missing.md)` is not a link, nor is this:

    [indented code](missing.md)
EOF
out=$($check "$tmp")
echo "$out"
[[ $out == "5 relative links resolve" ]] || { echo "FAIL: expected 5 good links"; exit 1; }

expect_broken() {  # what to add to README.md, the line the checker must print
  printf '%s\n' "$1" >>"$tmp/README.md"
  if out=$($check "$tmp"); then
    echo "FAIL: '$1' passed"; exit 1
  fi
  echo "$out"
  grep -qF "$2" <<<"$out" || { echo "FAIL: '$1' did not print '$2'"; exit 1; }
  sed -i '$d' "$tmp/README.md"
}
expect_broken '[gone](docs/gone.md)' 'README.md:9: docs/gone.md: no such file'
expect_broken 'see [the heading](docs/page.md#no-such-heading)' \
  'README.md:9: docs/page.md#no-such-heading: no heading #no-such-heading in docs/page.md'
expect_broken '[up](../outside.md)' 'README.md:9: ../outside.md: outside the checkout'
expect_broken '[self](#nowhere)' 'README.md:9: #nowhere: no heading #nowhere in README.md'

# A docs page README.md does not link is named.
echo '# Alone' >"$tmp/docs/alone.md"
if out=$($check "$tmp"); then echo "FAIL: a page README.md does not link passed"; exit 1; fi
echo "$out"
grep -qxF 'docs/alone.md: not linked from README.md' <<<"$out" || { echo "FAIL: docs/alone.md not named"; exit 1; }
rm "$tmp/docs/alone.md"

# A broken link in a docs page and in scripts/README.md is found too.
echo '[back](../READ.md)' >>"$tmp/docs/page.md"
mkdir -p "$tmp/scripts"
echo '[x](nothing.lua)' >"$tmp/scripts/README.md"
if out=$($check "$tmp"); then echo "FAIL: broken links in docs/ and scripts/ passed"; exit 1; fi
echo "$out"
grep -qF 'docs/page.md:4: ../READ.md: no such file' <<<"$out" || { echo "FAIL: docs/page.md not named"; exit 1; }
grep -qF 'scripts/README.md:1: nothing.lua: no such file' <<<"$out" || { echo "FAIL: scripts/README.md not named"; exit 1; }
echo "ok"
