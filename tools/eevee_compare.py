#!/usr/bin/env python3
"""Limn's Cornell box against Blender EEVEE's, alternated in one run.

    tools/eevee_compare.py [--size 512x384] [--rounds 3] [--frames 3] [--blender blender]
                           [--tech isr+esm] [--set NAME=VALUE ...] [--motion]

A benchmark, not a test. Each round renders, in turn (the order swapped each
round, so both see the same machine load):
  - Limn: `limn bench` on the built-in Cornell box with the technique (isr+esm:
    ISR's indirect light and shadows) and hdr, bloom and dof on; its frame
    time is the wall clock around a frame, glFinish before and after; with
    --motion the moving frame of `limn bench --motion` (the camera orbiting
    the box, every cache on, as a user walking through it gets: issue 33's
    figure) and that stream's pass medians;
  - EEVEE: `blender -b` running tools/eevee_cornell.py, the same box with
    GTAO, soft shadows, bloom and depth of field at 1 sample; its frame time
    is the wall clock around bpy.ops.render.render (shader compilation falls
    in the warm-up render).
Prints the medians, the ratio EEVEE / Limn, and Limn's passes as calibrated
texture fetches a pixel (the fetches its time would allow, limn bench).
Blender runs headless as it is (`blender -b`: without a display it draws
through EGL, no X server), EEVEE's world probe at 64 px and 1 sample: the
fair set-up on a machine without a GPU. Standard library only.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print(f"eevee_compare: {msg}", file=sys.stderr)
    sys.exit(2)


def limn_frames(args):
    cmd = [args.limn, "bench", "--scene", "cornell", "--tech", args.tech, "--sizes", args.size,
           "--frames", str(args.frames), "--warmup", "1", "--json"] + (["--motion"] if args.motion else [])
    for s in ["hdr=true", "bloom=true", "dof=true"] + args.set:
        cmd += ["--set", s]
    p = subprocess.run(cmd, text=True, capture_output=True)
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} failed:\n{p.stderr.strip()}")
    out = json.loads(p.stdout)
    if args.motion:
        m = out["motion"]
        return m["moving"]["frame_ms"], [(p["name"], p["moving"]) for p in m["passes"]], out
    return out["sizes"][0]["frame_ms"], [(p["name"], p["ms"][0]) for p in out["passes"]], out


def eevee_frames(args):
    cmd = [args.blender, "-b", "--factory-startup", "-noaudio", "-P", os.path.join(ROOT, "tools/eevee_cornell.py"),
           "--", "--size", args.size, "--frames", str(args.frames), "--warmup", "1"]
    p = subprocess.run(cmd, text=True, capture_output=True)
    times = [float(l.split()[1]) for l in p.stdout.splitlines() if l.startswith("eevee_frame_ms ")]
    if p.returncode != 0 or not times:
        fail(f"{' '.join(cmd)} failed ({p.returncode}):\n{(p.stdout + p.stderr).strip()[-2000:]}")
    return statistics.median(times)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--size", default="512x384")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=3, help="timed frames a run (median), after one warm-up")
    ap.add_argument("--tech", default="isr+esm")
    ap.add_argument("--set", action="append", default=[], help="another Limn option (repeatable)")
    ap.add_argument("--motion", action="store_true", help="Limn's moving frame (limn bench --motion)")
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--limn", default=os.path.join(ROOT, "build/limn"))
    args = ap.parse_args()
    if not shutil.which(args.blender):
        fail(f"no '{args.blender}' (Debian: apt-get install blender)")
    if not os.access(args.limn, os.X_OK):
        fail(f"no {args.limn}: build first (tools/dev.sh build)")
    limn, eevee, last = [], [], None
    for r in range(args.rounds):
        for who in (("limn", "eevee") if r % 2 == 0 else ("eevee", "limn")):
            print(f"round {r + 1}/{args.rounds}: {who}", file=sys.stderr)
            if who == "limn":
                ms, passes, last = limn_frames(args)
                limn.append(ms)
            else:
                eevee.append(eevee_frames(args))
    lm, ee = statistics.median(limn), statistics.median(eevee)
    print(f"Cornell box at {args.size}, medians of {args.rounds} alternated runs of {args.frames} frames"
          f" (clock: wall, {last['clock']} per pass)")
    print(f"  limn ({args.tech}, hdr, bloom, dof{', moving' if args.motion else ''}){'' if args.motion else ' ' * 8}"
          f"      {lm:9.2f} ms a frame  (runs: "
          + ", ".join(f"{v:.1f}" for v in limn) + ")")
    print(f"  eevee (GTAO, soft shadows, bloom, dof, 1 sample) {ee:9.2f} ms a frame  (runs: "
          + ", ".join(f"{v:.1f}" for v in eevee) + ")")
    print(f"  ratio eevee / limn: {ee / lm:.2f}x")
    cal = last.get("calibration")
    fetches = {p["name"]: p.get("fetches_per_pixel_equivalent") for p in last["passes"]}
    timed = [(name, ms) for name, ms in passes if ms is not None]
    total = sum(ms for _, ms in timed) or 1.0
    print(f"limn passes, last run{', moving' if args.motion else ''}"
          + (f" (calibration {cal['ns_per_fetch']:.3f} ns a fetch; fetches/pixel of the still frame)" if cal else "")
          + ": ms, share of the passes' sum")
    for name, ms in timed:
        eq = fetches.get(name)
        print(f"  {name:<22} {ms:9.2f} ms {100 * ms / total:5.1f}%  "
              + ("" if eq is None else f"{eq:9.1f} fetches/pixel"))


if __name__ == "__main__":
    main()
