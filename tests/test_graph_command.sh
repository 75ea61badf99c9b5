#!/usr/bin/env bash
# limn graph: the SVG parses as XML and names every pass the frame ran (as
# limn capture lists them) and no other as run; the DOT names each pass; bad
# flags exit 2 and write nothing.
set -u
limn=$1
. "$(dirname "$0")/shell_test.sh"
needs python3 "Debian python3"
scratch graph

"$limn" graph --help >"$tmp/help" || fail "graph --help exited $?"
grep -q -- "--output" "$tmp/help" || fail "graph --help names no --output"
"$limn" graph --output "$tmp/g.png" 2>"$tmp/err"; rc=$?
[ "$rc" -eq 2 ] || fail "--output g.png exited $rc, wanted 2"
grep -q "give a .svg or .dot" "$tmp/err" || fail "--output g.png: $(cat "$tmp/err")"
"$limn" graph --tech nonesuch --output "$tmp/bad.svg" 2>"$tmp/err"; rc=$?
[ "$rc" -eq 2 ] && [ ! -e "$tmp/bad.svg" ] || fail "an unknown technique exited $rc or wrote a file"

"$limn" graph --tech isr+esm --size 64x48 --quiet --output "$tmp/g.svg" || fail "graph --output g.svg exited $?"
"$limn" graph --tech isr+esm --size 64x48 --quiet --output "$tmp/g.dot" || fail "graph --output g.dot exited $?"
"$limn" capture --tech isr+esm --size 64x48 --frames 2 --output "$tmp/c.png" >"$tmp/capture" 2>&1 ||
  fail "capture exited $?"
python3 - "$tmp/g.svg" "$tmp/g.dot" "$tmp/capture" <<'PY' || exit 1
import re, sys
import xml.etree.ElementTree as ET
svg, dot, capture = sys.argv[1:]
ns = '{http://www.w3.org/2000/svg}'
root = ET.parse(svg).getroot()  # raises on anything that is not XML
ran, culled = [], []
for g in root.iter(ns + 'g'):
    name = next(t.text for t in g.iter(ns + 'text') if t.get('class') == 'name')
    (culled if 'culled' in g.get('class') else ran).append(name)
listed = [m.group(1) for m in re.finditer(r'^  (\S+)\s+(?:scene|fullscreen|cpu|points)\s', open(capture).read(), re.M)]
if not listed or sorted(ran) != sorted(listed):
    sys.exit(f'FAIL: the SVG ran {sorted(ran)}, capture lists {sorted(listed)}')
text = open(dot).read()
if not text.startswith('digraph'):
    sys.exit('FAIL: the DOT file is no digraph')
missing = [n for n in ran + culled if f'label="{n}\\n' not in text]
if missing:
    sys.exit(f'FAIL: the DOT file lacks passes {missing}')
print(f'{len(ran)} passes ran, {len(culled)} culled, in both files')
PY
echo "test_graph_command: passed"
