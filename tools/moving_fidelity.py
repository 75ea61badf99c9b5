#!/usr/bin/env python3
"""Error against Cycles on the frame of a moving camera (temporal reuse judged as it runs).

    tools/moving_fidelity.py [--spec TECH[:NAME=VALUE;...]] ... [--speed M] [--refs DIR] [--out DIR]
                             [--size WxH] [--scene PATH ...] [--samples N] [--materials M] [--sky]

`limn report` judges a still view: a history that settles on a still camera (or a
pattern that turns only while the view moves, isr.temporal's default) says
nothing of a moving one, and Cycles' references exist for the still poses
alone. So each view of the reference set (or of --scene's) whose Cycles
references are cached (8 bounces at --samples, default 1024, and 0 bounces,
seed 0, --materials, at --size, default 160x120; with --sky those rendered
under a sky, whose zenith, horizon and intensity the technique is given as
sky.* options, else those without) becomes a sequence
job: the camera trucks sideways through the view's pose at SPEED metres a
second (keys at t = 0, 1, 2, 24 fps; `limn capture`'s path, every cache and
history carried from frame to frame), and the frame at t = 1, the reference's
pose exactly, is compared with the references (`limn compare`'s mean error,
eq 19): the share of dl+esm's indirect error removed, 100 (e_base - e) /
(e_base - floor), dl+esm's frame at that pose against both references as
`limn report` does. Prints each view and the mean per spec. A benchmark, not
a test; standard library only.
"""
import argparse
import glob
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ("reference/room.glb", "reference/street.glb", "reference/blocks.glb", "cornell.glb")


def references(refs, size, scenes, samples, materials, sky):
    """view name -> (scene, camera, 8-bounce reference, direct-only reference, sky or None)."""
    found = {}
    for meta in sorted(glob.glob(os.path.join(refs, "*", "*_%s-cycles-*.json" % size))):
        with open(meta) as f:
            m = json.load(f)
        scene = m["scene"]  # the checkout that rendered it: this one's copy of the scene
        scene = os.path.join(ROOT, scene[scene.rfind("data/scenes/"):]) if "data/scenes/" in scene else scene
        if m["samples"] != samples or m["seed"] != 0 or m["materials"] != materials or bool(m["sky"]) != sky:
            continue
        if not scene.endswith(scenes):
            continue
        name = m["view"].split()[0]
        entry = found.setdefault(name, [scene, m["camera"], None, None, m["sky"] or None])
        if m["bounces"] == 8:
            entry[2] = meta[:-len(".json")] + ".exr"
        elif m["bounces"] == 0:
            entry[3] = meta[:-len(".json")] + ".exr"
    return {k: v for k, v in found.items() if v[2] and v[3]}


def path_keys(camera, speed):
    """Three keys a second apart along the camera's right: the pose at t = 1."""
    e, t, u = camera["eye"], camera["target"], camera["up"]
    f = [t[i] - e[i] for i in range(3)]
    r = [f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2], f[0] * u[1] - f[1] * u[0]]
    n = sum(x * x for x in r) ** 0.5
    if n < 1e-9:
        sys.exit("moving_fidelity: a reference camera looks along its up vector")
    r = [x / n for x in r]
    keys = []
    for k in (-1, 0, 1):
        eye = ", ".join("%.7f" % (e[i] + k * speed * r[i]) for i in range(3))
        tgt = ", ".join("%.7f" % (t[i] + k * speed * r[i]) for i in range(3))
        keys.append("{ t = %d, eye = { %s }, target = { %s }, fov = %.6f }" % (k + 1, eye, tgt, camera["fov_y"]))
    return ",\n           ".join(keys)


def sky_set(sky):
    """The reference's sky as the pipeline's sky.* options (scripts/sky.lua)."""
    if not sky:
        return ""
    rgb = lambda c: '"%s"' % ",".join("%.9g" % x for x in c)
    return ', ["sky.enabled"] = true, ["sky.zenith"] = %s, ["sky.horizon"] = %s, ["sky.intensity"] = %.9g' % (
        rgb(sky["zenith"]), rgb(sky["horizon"]), sky["intensity"])


def lua_set(spec):
    tech, _, opts = spec.partition(":")
    sets = ["ambient = 0"]
    for o in filter(None, opts.split(";")):
        name, _, value = o.partition("=")
        if value not in ("true", "false"):
            try:
                float(value)
            except ValueError:
                value = json.dumps(value)
        sets.append('["%s"] = %s' % (name, value))
    return tech, ", ".join(sets)


def mean_error(limn, a, b):
    out = subprocess.run([limn, "compare", a, b, "--json"], capture_output=True, text=True, check=True).stdout
    return float(json.loads(out)["mean_error"])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--spec", action="append", help="TECH[:NAME=VALUE;...] (repeatable)")
    p.add_argument("--speed", type=float, default=0.5, help="metres a second, 24 frames a second (default 0.5)")
    p.add_argument("--refs", default=os.path.join(ROOT, "out", "reference"))
    p.add_argument("--out", default=os.path.join(ROOT, "out", "moving_fidelity"))
    p.add_argument("--size", default="160x120", help="the references' size (default 160x120)")
    p.add_argument("--scene", action="append", help="a scene path ending (repeatable; default the reference set's)")
    p.add_argument("--samples", type=int, default=1024, help="the 8-bounce references' samples (default 1024)")
    p.add_argument("--materials", default="phong", help="the references' materials (default phong)")
    p.add_argument("--sky", action="store_true", help="views whose references have a sky (the technique gets it)")
    p.add_argument("--build", default=os.path.join(ROOT, os.environ.get("BUILD_DIR", "build")))
    a = p.parse_args()
    limn = os.path.join(a.build, "limn")
    if not os.access(limn, os.X_OK):
        sys.exit("moving_fidelity: no %s (build first: tools/dev.sh build)" % limn)
    views = references(a.refs, a.size, tuple(a.scene or SCENES), a.samples, a.materials, a.sky)
    if not views:
        sys.exit("moving_fidelity: no cached Cycles references (8 and 0 bounces, %d samples, %s, %s) at %s under %s"
                 % (a.samples, a.materials, "a sky" if a.sky else "no sky", a.size, a.refs))
    specs = ["dl+esm"] + (a.spec or ["isr+rsm+esm"])
    removed = {s: [] for s in specs[1:]}
    gains = {s: [] for s in specs[1:]}
    for name, (scene, camera, ref, floor_ref, sky) in sorted(views.items()):
        base = None
        for i, spec in enumerate(specs):
            tech, sets = lua_set(spec)
            sets += sky_set(sky)
            folder = os.path.join(a.out, name.replace("/", "_"), str(i))
            os.makedirs(folder, exist_ok=True)
            job = os.path.join(folder, "job.lua")
            with open(job, "w") as f:
                f.write('return {\n  scenes = { "%s" },\n  techniques = { "%s" },\n  sizes = { "%s" },\n'
                        '  set = { %s },\n  time = { 0, 1, 24 },\n  path = { %s },\n'
                        '  output = "%s/{frame}.exr",\n}\n' % (scene, tech, a.size, sets, path_keys(camera, a.speed), folder))
            subprocess.run([limn, "capture", "--job", job, "--force"], check=True, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            image = os.path.join(folder, "0024.exr")
            e = mean_error(limn, image, ref)
            if i == 0:
                base = (e, mean_error(limn, image, floor_ref))
                print("%-16s dl+esm %.5f (floor %.5f)" % (name, base[0], base[1]))
                continue
            # as limn report: the share of indirect error removed where the
            # floor lies below the baseline (n/a where a sky's light is in
            # both), the gain over the baseline always
            gain = 100 * (base[0] - e) / base[0] if base[0] > 0 else float("nan")
            gains[spec].append(gain)
            if base[0] > base[1]:
                share = 100 * (base[0] - e) / (base[0] - base[1])
                removed[spec].append(share)
                print("%-16s %s: %.5f, %.2f%% removed, gain %.2f%%" % (name, spec, e, share, gain), flush=True)
            else:
                print("%-16s %s: %.5f, removed n/a (floor above), gain %.2f%%" % (name, spec, e, gain), flush=True)
    print("speed %g m/s (%.1f cm a frame), the frame at the reference pose; mean indirect error removed, gain:" %
          (a.speed, 100 * a.speed / 24))
    mean = lambda xs: "%6.2f%%" % (sum(xs) / len(xs)) if xs else "   n/a "
    for spec in specs[1:]:
        print("  %s (%d views)  %s (%d views)  %s" % (mean(removed[spec]), len(removed[spec]),
                                                      mean(gains[spec]), len(gains[spec]), spec))


if __name__ == "__main__":
    main()
