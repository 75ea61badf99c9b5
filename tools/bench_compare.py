#!/usr/bin/env python3
"""Times this checkout against another revision in one run.

    tools/bench_compare.py REV [--case SCENE[:TECH[:NAME=VALUE,...]]] ... [options]
    (--set-this NAME=VALUE: an option for this checkout alone, one REV lacks)
    tools/bench_compare.py REV --motion [--orbit ...] [--time START:STOP --fps N --animation A] ...
    tools/bench_compare.py REV --walk [N1,N2] [--walk-keys KEYS] ...

Builds REV's `limn` in a scratch git worktree (under /tmp, removed at the end
unless --keep), then renders every case with both builds in turn, round after
round, the order swapped each round so that both see the same machine load.
Each run is `limn capture --frames F`; a pass's time is its median over the
rounds of the per-run medians, the frame time the median of the runs' sums.
Prints per case and pass both times and the ratio REV / this (above 1: this
checkout is faster), and the mean error between the two images (limn compare),
so that a speed-up that changes the picture shows. With --motion (or --orbit,
--time: passed to `limn bench`, which both revisions must have), each run is
`limn bench --motion --json` at the size instead, and the times compared are
its moving column (the camera on its path, the animation playing), with the
still frame's as one more row; no images, so no mean error. With --walk (for
revisions older than `bench --motion`), each run is the viewer flying through
the scene as a user would (`limn view --script-keys 1:hold=W --exit-after N`
under one Xvfb server started for the whole comparison), timed whole by the
wall clock (CLOCK_MONOTONIC) and in CPU time (getrusage: user + system of
all its threads, which load from other work stretches less); a moving frame
is (t(N2) - t(N1)) / (N2 - N1) of the same round, so start-up and loading
cancel out: frame times per case, no passes, no images. Standard library
only.
"""
import argparse
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_CASES = ["garage:isr+esm", "office:isr+esm", "outdoor:isr+esm"]
TIME_LINE = re.compile(r"^\s+(\S+)\s+(?:\S+\s+)?([0-9.]+) ms$")


def fail(msg):
    print(f"bench_compare: {msg}", file=sys.stderr)
    sys.exit(2)


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, **kw)


def build(src, build_dir, quiet):
    """Configures (once) and builds the limn command of the tree at src."""
    out = subprocess.DEVNULL if quiet else None
    if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
        run(["cmake", "-S", src, "-B", build_dir, "-DCMAKE_BUILD_TYPE=RelWithDebInfo"], stdout=out)
    run(["cmake", "--build", build_dir, "-j", str(os.cpu_count() or 1), "--target", "limn"], stdout=out)
    return os.path.join(build_dir, "limn")


def parse_case(text):
    parts = text.split(":", 2)
    scene = parts[0]
    if not scene:
        fail(f"--case '{text}': no scene")
    if not scene.endswith((".glb", ".gltf")) and os.path.exists(os.path.join(ROOT, "data/scenes", scene + ".glb")):
        scene = os.path.join(ROOT, "data/scenes", scene + ".glb")  # the same file for both revisions
    tech = parts[1] if len(parts) > 1 and parts[1] else None
    sets = [s for s in parts[2].split(",") if s] if len(parts) > 2 else []
    for s in sets:
        if "=" not in s:
            fail(f"--case '{text}': '{s}' is not NAME=VALUE")
    return {"label": text, "scene": scene, "tech": tech, "sets": sets}


def case_flags(case, sets):
    """A case's technique and --set flags, then the run's own sets."""
    flags = ["--tech", case["tech"]] if case["tech"] else []
    for s in case["sets"] + sets:
        flags += ["--set", s]
    return flags


def capture(limn, case, args, image, sets):
    cmd = [limn, "capture", "--scene", case["scene"], "--size", args.size, "--frames", str(args.frames),
           "--output", image] + case_flags(case, sets)
    p = subprocess.run(cmd, text=True, capture_output=True)
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr.strip()}")
    passes, in_table = {}, False
    for line in p.stdout.splitlines():
        if line.startswith("pass times"):
            in_table = True
            continue
        m = TIME_LINE.match(line) if in_table else None
        if m:
            passes[m.group(1)] = float(m.group(2))
    if "total" not in passes:
        fail(f"no pass times in the output of {' '.join(cmd)}")
    return passes


def motion_flags(args):
    """The flags of `limn bench` for the moving frame, [] without --motion."""
    flags = []
    for name in ("orbit", "time", "fps", "animation"):
        value = getattr(args, name)
        if value is not None:
            flags += ["--" + name, value]
    return ["--motion"] + flags if flags or args.motion else []


def bench_motion(limn, case, args, sets, who):
    """One `limn bench --motion` run: its moving column's pass medians, its
    moving frame as "total" and its still frame as "frame (still)"."""
    cmd = [limn, "bench", "--scene", case["scene"], "--sizes", args.size, "--frames", str(args.frames),
           "--json"] + motion_flags(args) + case_flags(case, sets)
    p = subprocess.run(cmd, text=True, capture_output=True)
    if p.returncode != 0:
        if "unknown flag '--" in p.stderr:
            fail(f"the {who} revision's limn bench lacks a motion flag ({p.stderr.strip().splitlines()[0]}); "
                 "a revision before `limn bench --motion` compares still frames only (leave the motion flags out)")
        fail(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr.strip()}")
    motion = json.loads(p.stdout)["motion"]
    passes = {q["name"]: q["moving"] for q in motion["passes"] if q["moving"] is not None}
    passes["frame (still)"] = motion["still"]["frame_ms"]
    cpu = motion.get("per_frame", {}).get("moving_cpu_ms")
    if cpu:  # the process's CPU time: what a loaded machine stretches far less than the wall clock
        passes["frame (cpu time)"] = statistics.median(cpu)
    passes["total"] = motion["moving"]["frame_ms"]
    return passes


def start_xvfb(size):
    """An Xvfb server on a free display for the whole comparison: (process, DISPLAY)."""
    if not shutil.which("Xvfb"):
        fail("--walk needs Xvfb (Debian's xvfb) for the viewer's window")
    read, write = os.pipe()
    w, h = size.split("x")
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", f"{int(w) + 64}x{int(h) + 64}x24",
                             "-nolisten", "tcp"], pass_fds=(write,), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as f:
        number = f.readline().strip()
    if not number:
        proc.kill()
        fail("Xvfb did not start")
    return proc, ":" + number


def walk_run(limn, case, args, sets, frames, display):
    """Seconds of one viewer run that flies for `frames` frames: (wall, CPU of
    all its threads: user + system, getrusage of the waited-for child)."""
    panel = "--panel" in subprocess.run([limn, "view", "--help"], text=True, capture_output=True).stdout
    cmd = [limn, "view", "--scene", case["scene"], "--size", args.size, "--overlay", "off",
           "--script-keys", args.walk_keys, "--exit-after", str(frames)] + (["--panel", "off"] if panel else [])
    cmd += case_flags(case, sets)
    r0, t0 = resource.getrusage(resource.RUSAGE_CHILDREN), time.monotonic()
    p = subprocess.run(cmd, text=True, capture_output=True, env=dict(os.environ, DISPLAY=display))
    t, r1 = time.monotonic() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr.strip()}")
    return t, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def walk_frame(limn, case, args, sets, display):
    """One round's moving frame in ms, the difference of two viewer runs: by
    the wall clock ("total") and in CPU time (a machine that other work loads
    stretches the first more than the second)."""
    n1, n2 = args.walk
    (w2, c2), (w1, c1) = walk_run(limn, case, args, sets, n2, display), walk_run(limn, case, args, sets, n1, display)
    return {"frame (cpu time)": 1000.0 * (c2 - c1) / (n2 - n1), "total": 1000.0 * (w2 - w1) / (n2 - n1)}


def mean_error(limn, a, b):
    p = subprocess.run([limn, "compare", a, b, "--json"], text=True, capture_output=True)
    try:
        return json.loads(p.stdout)["mean_error"]
    except (ValueError, KeyError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1], formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("rev", help="the other revision (anything git rev-parse takes)")
    ap.add_argument("--case", action="append", default=[],
                    help="SCENE[:TECH[:NAME=VALUE,...]]: a scene of data/scenes or a built-in, a technique and\n"
                         "options (repeatable; default: garage, office and outdoor with isr+esm)")
    ap.add_argument("--set", action="append", default=[], help="NAME=VALUE for every case (repeatable)")
    ap.add_argument("--set-this", action="append", default=[], metavar="NAME=VALUE",
                    help="for this checkout only, every case: an option REV lacks (repeatable)")
    ap.add_argument("--size", default="512x384")
    ap.add_argument("--frames", type=int, default=3, help="frames a run (the median is taken)")
    ap.add_argument("--rounds", type=int, default=3, help="runs of each revision per case, alternated")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="this checkout's build folder")
    ap.add_argument("--keep", metavar="DIR", help="keep REV's worktree and build in DIR (reused when it exists)")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    ap.add_argument("--motion", action="store_true",
                    help="time the moving frame (limn bench --motion: the moving column) instead of a still capture")
    ap.add_argument("--orbit", metavar="STEP[,RADIUS[,ELEVATION]]", help="limn bench --orbit (implies --motion)")
    ap.add_argument("--time", metavar="START:STOP", help="limn bench --time: the animation played (implies --motion)")
    ap.add_argument("--fps", help="limn bench --fps (with --time)")
    ap.add_argument("--animation", metavar="NAME|INDEX|all", help="limn bench --animation (with --time)")
    ap.add_argument("--walk", nargs="?", const="10,40", metavar="N1,N2",
                    help="time the viewer flying through the scene instead (limn view under Xvfb; a moving frame\n"
                         "= (wall time of N2 frames - of N1) / (N2 - N1); default 10,40): for revisions without\n"
                         "`bench --motion`")
    ap.add_argument("--walk-keys", default="1:hold=W",
                    help="the viewer's --script-keys for --walk (default 1:hold=W: forward, 1/60 s a frame)")
    args = ap.parse_args()
    if args.frames < 1 or args.rounds < 1:
        fail("--frames and --rounds want at least 1")
    cases = [parse_case(c) for c in (args.case or DEFAULT_CASES)]
    if (args.fps or args.animation) and not args.time:
        fail("--fps and --animation play an animation: they need --time START:STOP")
    moving = motion_flags(args) != []
    if args.walk is not None:
        try:
            args.walk = [int(v) for v in args.walk.split(",")]
        except ValueError:
            args.walk = []
        if len(args.walk) != 2 or not 0 < args.walk[0] < args.walk[1]:
            fail("--walk wants N1,N2 with 0 < N1 < N2")
        if moving:
            fail("--walk times the viewer: it does not go with --motion, --orbit or --time")
    xvfb, display = start_xvfb(args.size) if args.walk else (None, None)
    try:
        sha = run(["git", "-C", ROOT, "rev-parse", "--verify", args.rev + "^{commit}"],
                  capture_output=True).stdout.strip()
    except subprocess.CalledProcessError:
        fail(f"'{args.rev}' is not a revision of {ROOT}")
    here = run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True).stdout.strip()
    dirty = run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                capture_output=True).stdout.strip() != ""
    scratch = args.keep or tempfile.mkdtemp(prefix="limn-compare-")
    tree = os.path.join(scratch, "tree")
    images = tempfile.mkdtemp(prefix="limn-compare-images-")
    log = sys.stderr
    try:
        if not os.path.exists(os.path.join(tree, ".git")):
            run(["git", "-C", ROOT, "worktree", "add", "--detach", tree, sha], stdout=subprocess.DEVNULL)
        elif run(["git", "-C", tree, "rev-parse", "HEAD"], capture_output=True).stdout.strip() != sha:
            run(["git", "-C", tree, "checkout", "--detach", "-q", sha])
        print(f"building {args.rev} ({sha[:10]}) in {tree} ...", file=log)
        limn = {"base": build(tree, os.path.join(scratch, "build"), True),
                "this": build(ROOT, args.build, True)}
        results = []
        for case in cases:
            times = {"base": [], "this": []}
            for r in range(args.rounds):
                order = ("base", "this") if r % 2 == 0 else ("this", "base")
                for who in order:
                    print(f"  {case['label']}: round {r + 1}/{args.rounds}, {who}", file=log)
                    img = os.path.join(images, f"{len(results)}-{who}.exr")
                    sets = args.set + (args.set_this if who == "this" else [])
                    if args.walk:
                        times[who].append(walk_frame(limn[who], case, args, sets, display))
                    elif moving:
                        times[who].append(bench_motion(limn[who], case, args, sets, who))
                    else:
                        times[who].append(capture(limn[who], case, args, img, sets))
            err = None if moving or args.walk else mean_error(limn["this"], os.path.join(images, f"{len(results)}-base.exr"),
                                                 os.path.join(images, f"{len(results)}-this.exr"))
            names = [n for n in times["base"][0] if n != "total"]
            names += [n for n in times["this"][0] if n != "total" and n not in names]
            rows = []
            for n in names + ["total"]:
                row = {"pass": n if n != "total" else "frame"}
                for who in ("base", "this"):
                    v = [t[n] for t in times[who] if n in t]
                    row[who] = statistics.median(v) if v else None
                row["ratio"] = row["base"] / row["this"] if row["base"] and row["this"] else None
                rows.append(row)
            results.append({"case": case["label"], "passes": rows, "mean_error": err})
    finally:
        if xvfb:
            xvfb.terminate()
            xvfb.wait()
        shutil.rmtree(images, ignore_errors=True)
        if not args.keep:
            subprocess.run(["git", "-C", ROOT, "worktree", "remove", "--force", tree],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            shutil.rmtree(scratch, ignore_errors=True)
    label = here + (" (uncommitted changes)" if dirty else "")
    if args.json:
        print(json.dumps({"base": sha, "this": label, "size": args.size, "frames": args.frames,
                          "motion": motion_flags(args), "walk": args.walk, "walk_keys": args.walk_keys,
                          "rounds": args.rounds, "sets": args.set, "sets_this": args.set_this, "cases": results},
                         indent=1))
        return
    runs = "rounds of two viewer runs" if args.walk else f"runs of {args.frames} frames"
    print(f"base {args.rev} ({sha[:10]}) against this checkout {label}; {args.size}, medians of "
          f"{args.rounds} alternated {runs}; ratio = base / this (> 1: faster now)")
    if moving:
        print(f"moving frames: limn bench {' '.join(motion_flags(args))} (its moving column; 'frame' is the moving "
              "frame, 'frame (still)' the still one, 'frame (cpu time)' the moving frame in the process's CPU time, all "
              "threads)")
    if args.walk:
        print(f"moving frames: the viewer under Xvfb, --script-keys {args.walk_keys}, (wall time of {args.walk[1]} "
              f"frames - of {args.walk[0]}) / {args.walk[1] - args.walk[0]}, CLOCK_MONOTONIC; 'frame' is the moving frame, "
              "'frame (cpu time)' the same difference in the process's CPU time (user + system, all threads)")
    if args.set_this:
        print(f"this checkout only: {', '.join(args.set_this)}")
    fmt = "  {:<26} {:>10} {:>10} {:>8}"
    for res in results:
        err = res["mean_error"]
        print(f"{res['case']}  (mean error between the two images: {'-' if err is None else f'{err:.4g}'})")
        print(fmt.format("pass (ms)", "base", "this", "ratio"))
        for row in res["passes"]:
            cell = lambda v, f: "-" if v is None else f.format(v)
            print(fmt.format(row["pass"], cell(row["base"], "{:.2f}"), cell(row["this"], "{:.2f}"),
                             cell(row["ratio"], "{:.2f}x")))
    frames = [row["ratio"] for res in results for row in res["passes"] if row["pass"] == "frame" and row["ratio"]]
    if frames:
        print(f"frame ratio: geometric mean {statistics.geometric_mean(frames):.2f}x over {len(frames)} case(s)")


if __name__ == "__main__":
    main()
