#!/usr/bin/env python3
"""docs/commands.md is each command's full reference: its section for a command
("## limn capture", "## limn farm slurm") names every flag that the command's
--help prints, and no flag that --help lacks. Prints each difference naming
the command and exits 1 when there is one. LIMN may be a folder of help texts
that --save wrote (one file a command: "help", "capture", "farm slurm"), so
that the test's checks of the checker do not run limn again.

usage: check_doc_flags.py LIMN [ROOT] [--save DIR]"""
import os
import re
import subprocess
import sys

FLAG = re.compile(r'(?<![\w-])--[a-z][a-z0-9-]*')
# Flags of other programs that the page and the help quote (sbatch's).
FOREIGN = {'--array', '--qos'}


def sections(page):
    """{command words: section text} of the page's "## limn ..." headings."""
    parts = re.split(r'^## limn (.+)$', open(page, encoding='utf-8').read(), flags=re.M)
    return {tuple(parts[i].split()): parts[i + 1] for i in range(1, len(parts), 2)}


def help_text(limn, words, save):
    """What `limn WORDS --help` prints (`limn help` for no words), or None
    when it fails."""
    name = ' '.join(words) or 'help'
    if os.path.isdir(limn):
        path = os.path.join(limn, name)
        return open(path, encoding='utf-8').read() if os.path.exists(path) else None
    run = subprocess.run([limn, *words, '--help'] if words else [limn, 'help'],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return None
    if save:
        with open(os.path.join(save, name), 'w', encoding='utf-8') as f:
            f.write(run.stdout)
    return run.stdout


def main():
    args = sys.argv[1:]
    save = None
    if '--save' in args:
        i = args.index('--save')
        save = args[i + 1]
        del args[i:i + 2]
    if not args:
        print(__doc__.strip().splitlines()[-1])
        return 2
    limn = args[0]
    root = args[1] if len(args) > 1 else os.path.join(os.path.dirname(__file__), '..')
    page = os.path.join(root, 'docs', 'commands.md')
    docs = sections(page)
    problems = []
    # Every command `limn help` lists has a section ("farm" and "manifest" as
    # their subcommands: "limn farm slurm").
    listed = help_text(limn, (), save) or ''
    for name in re.findall(r'^  ([a-z][a-z-]*)  ', listed, flags=re.M):
        if name != 'help' and not any(words[0] == name for words in docs):
            problems.append('limn %s: no "## limn %s" section in docs/commands.md' % (name, name))
    for words, text in sorted(docs.items()):
        text_help = help_text(limn, words, save)
        if text_help is None:
            problems.append('limn %s --help: failed' % ' '.join(words))
            continue
        in_help = set(FLAG.findall(text_help)) - FOREIGN - {'--help'}
        in_doc = set(FLAG.findall(text)) - FOREIGN - {'--help'}
        cmd = 'limn ' + ' '.join(words)
        for flag in sorted(in_help - in_doc):
            problems.append('%s: %s is in --help but not in docs/commands.md' % (cmd, flag))
        for flag in sorted(in_doc - in_help):
            problems.append('%s: %s is in docs/commands.md but not in --help' % (cmd, flag))
    for p in problems:
        print(p)
    if problems:
        return 1
    print('%d commands: docs/commands.md and --help name the same flags' % len(docs))
    return 0


if __name__ == '__main__':
    sys.exit(main())
