#!/usr/bin/env python3
"""Issue 30's first target, one table: Limn's dl+esm against Cycles' direct
light on every test scene.

    tools/cycles_direct.py [--size 96x72] [--samples 64] [--scenes cornell,garage,x.glb]
                           [--refs out/cycles-direct/refs] [--out out/cycles-direct]
                           [--limn build/limn] [--blender blender]

A benchmark, not a test: it prints the figures and PASS or FAIL and exits 0
when the run completes. For each scene of data/scenes with a camera list (the
scenes test_scenes renders), its first camera: Cycles' direct-only render
(`limn reference --renderer cycles --bounces 0`, seeds 0 and 1, cached under
--refs) against `limn capture --tech dl+esm --set ambient=0`, both linear
EXR, under materials=phong (Limn's default) and materials=pbr. Per row:

  ratio   the two seeds' mean over Limn's (the target: within 1%), and half
          the seeds' difference in it: how well the reference knows its mean
  error   mean |seed 0 - Limn| over Limn's mean
  noise   mean |seed 0 - seed 1| over Limn's mean, the reference's own noise
          (the target: error at most twice this)
  masked  the ratio and error over the pixels where Limn's shadows do not
          depend on ESM's filtering: pixels whose dl+esm value differs from
          shadow.technique=hard (one depth compare) by more than 2%, and their
          neighbours, are left out; kept: the share of pixels left in
  model-matched  the ratio against Limn with the one line of its model that
          no Cycles material gives changed to what the export renders
          (MATCHED: phong's specular times n.l, as a BSDF's; pbr's diffuse
          times 1 - F0, not 1 - F(v.h)), Limn run from a copy of the engine's
          root made under --out

The verdict names why a row cannot be held to the target (docs/cycles.md):
a scene whose image that line changes by over 0.5% does not map exactly; a row
whose mean passes only with ESM's filtering masked says so; a reference whose
two seeds' means differ by over 1% cannot decide 1% (more samples); a
reference without noise (delta lights only: Cycles' direct light at each
pixel's centre is exact) cannot meet "error within twice the noise".

The means and masks are computed by this same file run inside Blender (its
numpy reads the EXRs), started once for all scenes. Standard library only
outside Blender.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fail(msg):
    print(f"cycles_direct: {msg}", file=sys.stderr)
    sys.exit(2)


def child_env(**extra):
    """The environment for limn and Blender: without the folder of a Python
    other than Debian's (pyenv and venvs put theirs first in PATH), from which
    Debian's Blender would take its Python's library and miss numpy."""
    env = dict(os.environ, **extra)
    own = os.path.dirname(sys.executable)
    if os.path.realpath(sys.prefix) != "/usr":
        env["PATH"] = os.pathsep.join(d for d in env.get("PATH", "").split(os.pathsep) if d != own)
    return env


def run(cmd):
    p = subprocess.run(cmd, text=True, capture_output=True, env=child_env())
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} failed:\n{(p.stderr or p.stdout).strip()[-2000:]}")
    return p.stdout


def test_scenes(only):
    """{name: .glb path}: data/scenes' scenes with a camera list, or those of
    ONLY, each a test scene's name or a .glb path with its .cams beside."""
    folder = os.path.join(ROOT, "data/scenes")
    scenes = {f[:-4]: os.path.join(folder, f) for f in sorted(os.listdir(folder))
              if f.endswith(".glb") and os.path.exists(os.path.join(folder, f[:-4] + ".cams"))}
    if not only:
        return scenes
    chosen = {}
    for s in only:
        path = os.path.abspath(s) if s.endswith(".glb") else scenes.get(s)
        if not path or not os.path.exists(path[:-4] + ".cams"):
            fail(f"{s}: not a test scene ({', '.join(scenes)}) nor a .glb with its .cams beside it")
        chosen[os.path.basename(path)[:-4]] = path
    return chosen


def first_camera(path):
    with open(path[:-4] + ".cams") as f:
        for line in f:
            if line.strip() and not line.lstrip().startswith("#"):
                return line
    fail(f"{path[:-4]}.cams lists no camera")


def reference(args, job, materials, seed):
    """The Cycles direct-only reference of the job's one view (rendered or
    cached): the file limn reference names in its progress line."""
    out = run([args.limn, "reference", "--job", job, "--renderer", "cycles", "--bounces", "0", "--samples",
               str(args.samples), "--seed", str(seed), "--materials", materials, "--blender", args.blender,
               "--refs", os.path.join(args.refs, f"{materials}-seed{seed}")])
    for line in out.splitlines():
        m = re.match(r"\[1/1\] (\S+\.exr)", line)
        if m and os.path.exists(m.group(1)):
            return m.group(1)
    fail(f"limn reference named no reference for {job}:\n{out}")


# What Limn's model gives that no Cycles material can (docs/cycles.md), and the
# line of shaders/lighting.glsl that, changed, gives what Cycles renders:
# Phong's specular weighed by n.l as a BSDF's is (phong_reflect); glTF's
# diffuse weighed by 1 - F0 rather than 1 - F(v.h), as the Cycles export's
# nodes, which do not see the light's direction, weigh it (pbr_reflect).
MATCHED = {
    "phong": ("return m.k.y * m.albedo * ndl + m.k.z * spec;", "return (m.k.y * m.albedo + m.k.z * spec) * ndl;"),
    "pbr": ("return ndl * ((1.0 - f) * m.albedo", "return ndl * ((1.0 - m.f0) * m.albedo"),
}


def matched_root(out, materials):
    """A copy of the engine's root (links, shaders/ copied) whose
    shaders/lighting.glsl has MATCHED's line for the materials."""
    old, new = MATCHED[materials]
    root = os.path.join(out, "matched-" + materials)
    shutil.rmtree(root, ignore_errors=True)
    os.makedirs(root)
    for entry in os.listdir(ROOT):
        if entry != "shaders":
            os.symlink(os.path.join(ROOT, entry), os.path.join(root, entry))
    shutil.copytree(os.path.join(ROOT, "shaders"), os.path.join(root, "shaders"))
    path = os.path.join(root, "shaders/lighting.glsl")
    text = open(path).read()
    if text.count(old) != 1:
        fail(f"shaders/lighting.glsl no longer has '{old}': update MATCHED in {__file__}")
    with open(path, "w") as f:
        f.write(text.replace(old, new))
    return root


def capture(args, scene, cams, out, sets, root=None):
    """Limn's dl+esm (ambient 0) of the scene's view into OUT (EXR) through a one-view job."""
    job = out[:-4] + ".lua"
    with open(job, "w") as f:
        f.write('return { scenes = { { scene = "%s", cameras = "%s" } }, sizes = { "%s" },\n'
                '  techniques = { "dl+esm" }, set = { ambient = 0%s }, output = "%s" }\n'
                % (scene, cams, args.size,
                   "".join(', ["%s"] = "%s"' % tuple(s.split("=", 1)) for s in sets), out))
    env = child_env(LIMN_ROOT=root) if root else child_env()
    p = subprocess.run([args.limn, "capture", "--job", job, "--force", "--quiet"], text=True,
                       capture_output=True, env=env)
    if p.returncode != 0 or not os.path.exists(out):
        fail(f"limn capture --job {job} failed:\n{(p.stderr or p.stdout).strip()[-2000:]}")
    return out


def mean_verdict(ratio, ratio_noise):
    if ratio_noise > 0.005:
        return "?"  # the reference does not know its own mean to 1%
    return "PASS" if abs(ratio - 1) <= 0.01 else "FAIL"


def notes(r):
    """Why a row misses the target, where that is known (docs/cycles.md)."""
    why = []
    if abs(r["matched_share"]) > 0.005:
        why.append("materials do not map exactly: %s is %.1f%% of Limn's image (matched: mean %s, masked %s)" % (
                       "Phong's specular without n.l" if r["materials"] == "phong" else "the diffuse's 1 - F(v.h)",
                       100 * r["matched_share"], mean_verdict(r["matched_ratio"], r["ratio_noise"]),
                       mean_verdict(r["matched_masked_ratio"], r["ratio_noise"])))
    if mean_verdict(r["ratio"], r["ratio_noise"]) == "FAIL" and \
            mean_verdict(r["masked_ratio"], r["ratio_noise"]) == "PASS":
        why.append("mean PASS with ESM's filtering masked")
    if r["ratio_noise"] > 0.005:
        why.append("the reference's mean is uncertain by %.1f%%: more samples" % (100 * r["ratio_noise"]))
    if r["noise"] < 1e-3 and r["error"] > 2 * r["noise"]:
        why.append("the reference is noise-free (delta lights, each pixel's centre): the error is Limn's own")
    return "; ".join(why)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", default="96x72")
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--scenes", default="",
                    help="comma-separated test scene names or .glb files with .cams beside (default: every test scene)")
    ap.add_argument("--refs", default=os.path.join(ROOT, "out/cycles-direct/refs"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out/cycles-direct"))
    ap.add_argument("--limn", default=os.path.join(ROOT, "build/limn"))
    ap.add_argument("--blender", default="blender")
    args = ap.parse_args()
    args.refs, args.out, args.limn = (os.path.abspath(x) for x in (args.refs, args.out, args.limn))
    os.makedirs(args.out, exist_ok=True)
    roots = {m: matched_root(args.out, m) for m in MATCHED}
    pairs = []
    for name, scene in test_scenes([s for s in args.scenes.split(",") if s]).items():
        cams = os.path.join(args.out, name + ".cams")
        with open(cams, "w") as f:
            f.write(first_camera(scene))
        job = os.path.join(args.out, name + ".lua")
        with open(job, "w") as f:
            f.write('return { scenes = { { scene = "%s", cameras = "%s" } }, sizes = { "%s" },\n'
                    '  techniques = { "dl+esm" }, set = { ambient = 0 }, output = "%s/{scene}.png" }\n'
                    % (scene, cams, args.size, args.out))
        base = os.path.join(args.out, name)
        for materials in ("phong", "pbr"):
            print(f"cycles_direct: {name} {materials}", file=sys.stderr)
            m = ["materials=" + materials]
            limn = capture(args, scene, cams, f"{base}-{materials}.exr", m)
            pairs.append({
                "scene": name, "materials": materials, "limn": limn,
                "hard": capture(args, scene, cams, f"{base}-{materials}-hard.exr", m + ["shadow.technique=hard"]),
                "matched": capture(args, scene, cams, f"{base}-{materials}-matched.exr", m, roots[materials]),
                "cycles": [reference(args, job, materials, seed) for seed in (0, 1)]})
    with open(os.path.join(args.out, "pairs.json"), "w") as f:
        json.dump(pairs, f)
    stats = run([args.blender, "-b", "--factory-startup", "-noaudio", "--python-exit-code", "1",
                 "--python", os.path.abspath(__file__), "--", "--stats", os.path.join(args.out, "pairs.json")])
    rows = [json.loads(line[6:]) for line in stats.splitlines() if line.startswith("STATS ")]
    print(f"Limn dl+esm (ambient 0) against Cycles' direct light (bounces 0), {args.size}, {args.samples} "
          "samples, seeds 0 and 1, each scene's first camera. Ratio: Cycles' mean / Limn's; error and noise: "
          "mean |difference| over Limn's mean (noise: the two seeds'); masked: ESM-filtered pixels left out "
          "(kept: the share left in); model-matched: against Limn with the line of its model that no Cycles "
          "material gives changed to what Cycles renders (phong: specular times n.l; pbr: diffuse times 1 - F0)")
    print("| scene | materials | ratio | error | noise | masked ratio | masked error | kept | model-matched ratio "
          "| masked | mean within 1% | error within 2x noise | notes |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        matched = "%.3f | %.3f" % (r["matched_ratio"], r["matched_masked_ratio"])
        print("| %s | %s | %.3f ± %.3f | %.1f%% | %.1f%% | %.3f | %.1f%% | %.0f%% | %s | %s | %s | %s |" % (
            r["scene"], r["materials"], r["ratio"], r["ratio_noise"], 100 * r["error"], 100 * r["noise"],
            r["masked_ratio"], 100 * r["masked_error"], 100 * r["kept"], matched,
            mean_verdict(r["ratio"], r["ratio_noise"]), "PASS" if r["error"] <= 2 * r["noise"] else "FAIL",
            notes(r)))


# ---------------------------------------------------------------- inside Blender


def stats(pairs_path):
    import bpy
    import numpy

    def load(path):
        img = bpy.data.images.load(path)
        px = numpy.empty(len(img.pixels), dtype=numpy.float32)
        img.pixels.foreach_get(px)
        w, h = img.size
        bpy.data.images.remove(img)
        return px.reshape(h, w, 4)[:, :, :3].astype(numpy.float64)

    for p in json.load(open(pairs_path)):
        limn, hard, matched, c0, c1 = (load(x) for x in (p["limn"], p["hard"], p["matched"], *p["cycles"]))
        # ESM's filtering: pixels where the filtered shadow differs from one depth compare by over 2%,
        # and their neighbours.
        lum, lum_hard = limn.mean(axis=2), hard.mean(axis=2)
        moved = numpy.abs(lum - lum_hard) > 0.02 * numpy.maximum(numpy.maximum(lum, lum_hard), 1e-6)
        grown = moved.copy()
        grown[1:, :] |= moved[:-1, :]
        grown[:-1, :] |= moved[1:, :]
        grown[:, 1:] |= moved[:, :-1]
        grown[:, :-1] |= moved[:, 1:]
        keep = ~grown

        def figures(a, b, mask):  # the seeds' mean over Limn's, mean |seed 0 - Limn| over Limn's mean
            if not mask.any():
                return 0.0, 1.0
            mean = max(b[mask].mean(), 1e-12)
            return (a[mask].mean() + c1[mask].mean()) / 2 / mean, numpy.abs(a - b)[mask].mean() / mean

        everywhere = numpy.ones(keep.shape, dtype=bool)
        noise = numpy.abs(c0 - c1)  # the reference's own: two seeds' difference
        row = {"scene": p["scene"], "materials": p["materials"], "kept": keep.mean(),
               "noise": noise.mean() / max(limn.mean(), 1e-12),
               "masked_noise": noise[keep].mean() / max(limn[keep].mean(), 1e-12) if keep.any() else 0.0,
               "ratio_noise": abs(c0.mean() - c1.mean()) / 2 / max(limn.mean(), 1e-12),
               "matched_share": (limn.mean() - matched.mean()) / max(limn.mean(), 1e-12)}
        row["ratio"], row["error"] = figures(c0, limn, everywhere)
        row["masked_ratio"], row["masked_error"] = figures(c0, limn, keep)
        row["matched_ratio"], row["matched_error"] = figures(c0, matched, everywhere)
        row["matched_masked_ratio"], row["matched_masked_error"] = figures(c0, matched, keep)
        print("STATS " + json.dumps({k: float(v) if not isinstance(v, str) else v for k, v in row.items()}))


if __name__ == "__main__":
    if "--stats" in sys.argv:
        stats(sys.argv[sys.argv.index("--stats") + 1])
    else:
        main()
