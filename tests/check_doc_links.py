#!/usr/bin/env python3
"""Every relative link of the docs resolves: README.md, docs/*.md and
scripts/README.md under ROOT (default: this checkout). A link names a file
that exists; a #anchor names a heading of its page (GitHub's slugs); and
README.md links every docs/*.md page. Prints each broken link as file:line
(and each page README.md does not link) and exits 1 when there is one.

usage: check_doc_links.py [ROOT]"""
import glob
import os
import re
import sys

# [text](target) and ![alt](target), the target up to a space or ')';
# reference definitions "[label]: target".
INLINE = re.compile(r'!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+"[^"]*")?\s*\)')
REFDEF = re.compile(r'^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+"[^"]*")?\s*$')
CODE_SPAN = re.compile(r'(`+).*?\1')


def outside_fences(path):
    """(line number, text without its newline) of the lines outside fenced code blocks."""
    fence = None
    with open(path, encoding='utf-8') as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip('\n')
            stripped = line.strip()
            if fence:
                if stripped.startswith(fence):
                    fence = None
                continue
            if stripped.startswith('```') or stripped.startswith('~~~'):
                fence = stripped[:3]
                continue
            yield n, line


def prose_lines(path):
    """(line number, text) of the lines outside code blocks, code spans blanked."""
    prev_blank = True
    for n, line in outside_fences(path):
        # An indented code block starts after a blank line (a list item's
        # continuation lines are indented too, but follow text).
        if line.startswith('    ') and prev_blank:
            continue
        prev_blank = not line.strip()
        yield n, CODE_SPAN.sub('', line)


def slug(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped,
    spaces to hyphens."""
    text = CODE_SPAN.sub(lambda m: m.group(0).strip('`'), heading)
    text = re.sub(r'\[([^\]]*)\]\([^)]*\)', r'\1', text)  # a link's text
    text = text.strip().lower()
    text = re.sub(r'[^\w\- ]', '', text)
    return text.replace(' ', '-')


def anchors(path, cache={}):
    if path not in cache:
        seen = {}
        found = set()
        for _, line in outside_fences(path):
            m = re.match(r'^#{1,6}\s+(.*?)\s*#*\s*$', line)
            if not m:
                continue
            s = slug(m.group(1))
            # A repeated heading gets -1, -2, ... as on GitHub.
            k = seen.get(s, 0)
            seen[s] = k + 1
            found.add(s if k == 0 else '%s-%d' % (s, k))
        cache[path] = found
    return cache[path]


def check(root):
    pages = [os.path.join(root, 'README.md')]
    pages += sorted(glob.glob(os.path.join(root, 'docs', '*.md')))
    scripts_readme = os.path.join(root, 'scripts', 'README.md')
    if os.path.exists(scripts_readme):
        pages.append(scripts_readme)
    broken = []
    links = 0
    linked = set()  # the files README.md links
    for page in pages:
        if not os.path.exists(page):
            broken.append('%s: missing' % os.path.relpath(page, root))
            continue
        for n, text in prose_lines(page):
            targets = INLINE.findall(text)
            m = REFDEF.match(text)
            if m:
                targets.append(m.group(1))
            for target in targets:
                if re.match(r'^[a-z][a-z0-9+.-]*:', target):  # http:, mailto:
                    continue
                links += 1
                where = '%s:%d' % (os.path.relpath(page, root), n)
                file_part, _, anchor = target.partition('#')
                dest = page if not file_part else os.path.normpath(
                    os.path.join(os.path.dirname(page), file_part))
                if page == pages[0]:
                    linked.add(dest)
                if os.path.relpath(dest, root).startswith('..'):
                    broken.append('%s: %s: outside the checkout' % (where, target))
                elif not os.path.exists(dest):
                    broken.append('%s: %s: no such file' % (where, target))
                elif anchor and dest.endswith('.md') and anchor not in anchors(dest):
                    broken.append('%s: %s: no heading #%s in %s'
                                  % (where, target, anchor, os.path.relpath(dest, root)))
    for page in pages[1:]:
        if page.startswith(os.path.join(root, 'docs', '')) and page not in linked:
            broken.append('%s: not linked from README.md' % os.path.relpath(page, root))
    return links, broken


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..')
    links, broken = check(os.path.abspath(root))
    for b in broken:
        print(b)
    if broken:
        print('%d problems; %d relative links checked' % (len(broken), links))
        return 1
    print('%d relative links resolve' % links)
    return 0


if __name__ == '__main__':
    sys.exit(main())
