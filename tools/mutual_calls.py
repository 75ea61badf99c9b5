#!/usr/bin/env python3
"""Pairs of source files that call each other both ways, read from the
objects a build made: file A calls file B where A's object leaves a symbol
undefined that B's object defines (nm). Prints each such pair and exits 1
when there is one; a layer's files should depend one way (docs/architecture.md).
Scripts count too: a Lua module that requires one that requires it back.

usage: mutual_calls.py BUILD_DIR [ROOT]"""
import os
import re
import subprocess
import sys

# Text, data, bss, read-only, small: what a file defines. Not weak symbols: C++ inline
# functions and templates, which each object that uses them defines.
DEFINED = set('TDBRGS')


def objects(build):
    """{source path relative to the root: its object}: CMake names an object
    after its source (CMakeFiles/T.dir/engine/core/core.c.o); the first
    target's copy of a source serves (tests link the same engine)."""
    found = {}
    for top, _, names in os.walk(build):
        for name in sorted(names):
            if not name.endswith('.o'):
                continue
            path = os.path.join(top, name)
            parts = path.split(os.sep)
            dirs = [i for i, p in enumerate(parts) if p.endswith('.dir')]
            if not dirs:
                continue
            source = '/'.join(parts[dirs[-1] + 1:])[:-2]
            found.setdefault(source, path)
    return found


def symbols(obj):
    """(defined, undefined) external symbols of one object."""
    out = subprocess.run(['nm', obj], capture_output=True, text=True, check=True).stdout
    defined, undefined = set(), set()
    for line in out.splitlines():
        f = line.split()
        if len(f) == 2 and f[0] == 'U':
            undefined.add(f[1])
        elif len(f) == 3 and f[1] in DEFINED:
            defined.add(f[2])
    return defined, undefined


def c_edges(build, root):
    # Objects of sources the checkout still has (a build folder keeps those of moved files).
    objs = {s: o for s, o in objects(build).items()
            if not s.startswith(('tests/', 'data/')) and os.path.exists(os.path.join(root, s))}
    table = {s: symbols(o) for s, o in objs.items()}
    owner = {}
    for s, (defined, _) in table.items():
        for sym in defined:
            owner.setdefault(sym, set()).add(s)
    edges = {}
    for s, (_, undefined) in table.items():
        for sym in undefined:
            for t in owner.get(sym, ()):
                if t != s:
                    edges.setdefault((s, t), sym)
    return edges, len(table)


def lua_edges(root):
    edges, count = {}, 0
    scripts = os.path.join(root, 'scripts')
    for top, _, names in os.walk(scripts):
        for name in names:
            if not name.endswith('.lua'):
                continue
            count += 1
            path = os.path.join(top, name)
            src = os.path.relpath(path, root)
            for m in re.finditer(r'require\s*\(?\s*["\']([\w.]+)["\']', open(path, encoding='utf-8').read()):
                edges.setdefault((src, 'scripts/' + m.group(1).replace('.', '/') + '.lua'), 'require')
    return edges, count


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    build = sys.argv[1]
    root = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
    c, c_count = c_edges(build, root)
    lua, lua_count = lua_edges(root)
    if c_count == 0:
        sys.exit(f'mutual_calls.py: no objects under {build}: build first')
    pairs = []
    for edges in (c, lua):
        for (a, b), why in sorted(edges.items()):
            if a < b and (b, a) in edges:
                pairs.append(f'{a} <-> {b}: {a} uses {why}, {b} uses {edges[(b, a)]}')
    for p in pairs:
        print(p)
    print(f'{len(pairs)} file pairs call each other both ways ({c_count} objects, {lua_count} scripts read)')
    return 1 if pairs else 0


if __name__ == '__main__':
    sys.exit(main())
