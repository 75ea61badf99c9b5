#!/usr/bin/env bash
# limn graph: the SVG parses as XML and names every pass the frame ran (as
# limn capture lists them) and no other as run; the DOT names each pass; both
# have an edge for every input a pass reads of an earlier pass's output (its
# last writer, found here from the targets the SVG lists each pass reading
# and writing) and no other; bad flags exit 2 and write nothing.
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
ran, culled, reads, writes, ids = [], [], [], [], []
for g in root.iter(ns + 'g'):
    texts = list(g.iter(ns + 'text'))
    name = next(t.text for t in texts if t.get('class') == 'name')
    (culled if 'culled' in g.get('class') else ran).append(name)
    ids.append(g.get('id'))
    reads.append([t.text for t in texts if t.get('class') == 'read'])
    writes.append([t.text for t in texts if t.get('class') == 'write'])
listed = [m.group(1) for m in re.finditer(r'^  (\S+)\s+(?:scene|fullscreen|cpu|points)\s', open(capture).read(), re.M)]
if not listed or sorted(ran) != sorted(listed):
    sys.exit(f'FAIL: the SVG ran {sorted(ran)}, capture lists {sorted(listed)}')
if ids != [f'p{i}' for i in range(len(ids))]:
    sys.exit(f'FAIL: the passes are not p0..p{len(ids) - 1} in recording order: {ids}')
# Every input of an earlier pass's output: from its last writer before the reader.
want = set()
for i, targets in enumerate(reads):
    for t in targets:
        w = next((j for j in range(i - 1, -1, -1) if t in writes[j]), None)
        if w is not None:
            want.add((f'p{w}', f'p{i}', t))
if len(want) < len(ran):
    sys.exit(f'FAIL: only {len(want)} edges expected for {len(ran)} passes: the SVG lists too few targets')
got = {(e.get('data-from'), e.get('data-to'), e.get('data-target'))
       for e in root.iter(ns + 'path') if 'edge' in e.get('class', '')}
if got != want:
    sys.exit(f'FAIL: SVG edges missing {sorted(want - got)}, extra {sorted(got - want)}')
text = open(dot).read()
if not text.startswith('digraph'):
    sys.exit('FAIL: the DOT file is no digraph')
missing = [n for n in ran + culled if f'label="{n}\\n' not in text]
if missing:
    sys.exit(f'FAIL: the DOT file lacks passes {missing}')
dot_edges = set(re.findall(r'^  (p\d+) -> (p\d+) \[label="([^"]*)"', text, re.M))
if dot_edges != want:
    sys.exit(f'FAIL: DOT edges missing {sorted(want - dot_edges)}, extra {sorted(dot_edges - want)}')
print(f'{len(ran)} passes ran, {len(culled)} culled, {len(want)} edges, in both files')
PY
echo "test_graph_command: passed"
