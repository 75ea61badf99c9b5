#!/usr/bin/env bash
# A Blender export that moves, against Blender's own evaluation of it (issue 29).
#   tools/blender_motion_check.sh [--no-render] [--unsampled] [OUT_DIR]
# A developer check, not a ctest test: it needs Blender (Debian's `blender`
# and `python3-numpy`, which its glTF exporter imports; `python3-pil` reads
# the frames), which CI does not install. tools/blender_motion_scene.py
# builds the scene in Blender, exports it with Blender's glTF exporter
# (defaults: animation sampled each frame) and writes each object's world
# matrix at TIMES; build/gltf_pose poses the exported file in Limn at the
# same times. Prints, per node and time, the position (scene units),
# rotation (degrees) and scale differences against Blender's curves, the
# largest on a frame and between frames (where the file holds Blender's
# per-frame samples, interpolated linearly, and not its curves), the largest
# against those samples (Blender's pose at the frames either side,
# interpolated as the file says), and the camera's field of view and aspect;
# exits 1 when a node differs by more than 1e-4 (1e-3 degrees) from the
# curves on a frame or from the samples at any time, or the camera does.
# Unless --no-render, Blender (Workbench, flat object colours, no
# anti-aliasing) and `limn capture` (dl, the exported materials emitting
# those colours) render each time at SIZE through the file's camera; it
# prints the frames' mean absolute error (sRGB, 0..1) and, for each box's
# silhouette (the pixels of its colour's hue), the distance between the two
# centroids in pixels and the share of their union the two do not have in
# common; more than a pixel between centroids fails.
# BUILD_DIR (default build), BLENDER (default blender), TIMES (seconds,
# comma-separated) and SIZE (the frames' WxH, default 160x120: the camera's
# aspect is Blender's output's) pass through.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
blender=${BLENDER:-blender}
times=${TIMES:-0,0.5,0.8125,1,1.37,2}
size=${SIZE:-160x120}
render=--render
unsampled=
while [ $# -gt 0 ]; do
  case $1 in
    --no-render) render= ;;
    --unsampled) unsampled=--unsampled ;;
    *) break ;;
  esac
  shift
done
out=${1:-$(mktemp -d /tmp/limn_blender_motion.XXXXXX)}
command -v "$blender" >/dev/null || { echo "blender_motion_check: no '$blender' (apt-get install blender python3-numpy python3-pil)" >&2; exit 2; }
for exe in gltf_pose limn; do
  [ -x "$build/$exe" ] || { echo "blender_motion_check: build $build/$exe first (cmake --build $build -j2)" >&2; exit 2; }
done
mkdir -p "$out"

"$blender" -b --factory-startup -P tools/blender_motion_scene.py -- --out "$out" --times "$times" --size "$size" $render $unsampled \
  >"$out/blender.log" 2>&1 || { tail -20 "$out/blender.log" >&2; exit 1; }
[ -s "$out/poses.json" ] || { echo "blender_motion_check: Blender wrote no poses (see $out/blender.log)" >&2; exit 1; }
"$build/gltf_pose" "$out/motion.glb" --animation all ${times//,/ } >"$out/limn_poses.json"

status=0
# Debian's python3 (the one with python3-numpy and python3-pil), not another on PATH.
/usr/bin/python3 - "$out/poses.json" "$out/limn_poses.json" <<'POSES' || status=1
import json, math, sys

blender = json.load(open(sys.argv[1]))
limn = json.load(open(sys.argv[2]))


def columns(m):  # the 3x3 part's columns and the translation of a column-major 4x4
    return [m[0:3], m[4:7], m[8:11]], m[12:15]


def differences(a, b):
    ca, ta = columns(a)
    cb, tb = columns(b)
    position = math.dist(ta, tb)
    sa, sb = [math.hypot(*c) for c in ca], [math.hypot(*c) for c in cb]
    scale = max(abs(x - y) for x, y in zip(sa, sb))
    ra = [[v / max(s, 1e-12) for v in c] for c, s in zip(ca, sa)]
    rb = [[v / max(s, 1e-12) for v in c] for c, s in zip(cb, sb)]
    # The angle of ra^T rb: trace = sum of the column dot products.
    trace = sum(sum(x * y for x, y in zip(u, v)) for u, v in zip(ra, rb))
    rotation = math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1) / 2))))
    return position, rotation, scale


fps = blender["fps"]
print(f"Blender {blender['blender']}, {fps} fps, times {blender['times']}")
on_frame = [abs(t * fps - round(t * fps)) < 1e-6 for t in blender["times"]]
# Largest position, rotation, scale difference against Blender's curves on a
# frame, against them between frames, and against the export's samples
# (none with --unsampled).
worst = {"curve, on a frame": [0.0] * 3, "curve, between frames": [0.0] * 3}
if blender["sampled"]:
    worst["samples"] = [0.0] * 3


def widen(key, diff):
    worst[key] = [max(w, x) for w, x in zip(worst[key], diff)]


for name, mats in blender["nodes"].items():
    if name not in limn["nodes"]:
        sys.exit(f"blender_motion_check: no node '{name}' in Limn's scene")
    row = []
    for i, t in enumerate(blender["times"]):
        ours = limn["nodes"][name][i]
        d = differences(mats[i], ours)
        row.append(f"{t:g}s {d[0]:.2e} {d[1]:.3f}deg {d[2]:.1e}")
        widen(f"curve, {'on a frame' if on_frame[i] else 'between frames'}", d)
        if blender["sampled"]:
            widen("samples", differences(blender["sampled"][name][i], ours))
    print(f"  {name:12s} " + " | ".join(row))
for key, (p, r, s) in worst.items():
    print(f"largest difference from Blender's {key}: position {p:.3g}, rotation {r:.3g} deg, scale {s:.3g}")
if blender["sampled"]:
    bad = [key for key in ("curve, on a frame", "samples") if max(worst[key][0], worst[key][2]) > 1e-4 or worst[key][1] > 1e-3]
else:  # the file's rotation splines are not Blender's curves between keys: positions and scales only
    bad = [key for key in worst if max(worst[key][0], worst[key][2]) > 1e-4]

cam = next((c for c in limn["cameras"] if c["node"] == blender["camera"]["name"]), None)
if cam is None:
    sys.exit("blender_motion_check: no camera on the camera's node in Limn's scene")
fov = math.degrees(abs(cam["fov_y"] - blender["camera"]["fov_y"]))
aspect = abs(cam["aspect"] - blender["camera"]["aspect"])
print(f"camera: vertical fov {math.degrees(cam['fov_y']):.4f} deg (Blender {math.degrees(blender['camera']['fov_y']):.4f}),"
      f" aspect {cam['aspect']:.4f} (Blender {blender['camera']['aspect']:.4f})")
if bad or fov > 1e-3 or aspect > 1e-4:
    sys.exit(f"blender_motion_check: Limn differs from Blender ({', '.join(bad) or 'camera'})")
POSES
if [ -n "$render" ]; then
  i=0
  for t in ${times//,/ }; do
    "$build/limn" capture --scene "$out/motion.glb" --tech dl --set materials=pbr --size "$size" --camera 0 \
      --time "$t" --quiet --output "$out/limn_$i.png"
    i=$((i + 1))
  done
  /usr/bin/python3 - "$out" "$times" <<'FRAMES' || status=1
import sys
import numpy as np
from PIL import Image

out, times = sys.argv[1], sys.argv[2].split(",")


def silhouette(rgb, channel):
    """Pixels whose colour is mostly `channel` (0 red: box_bezier, 1 green: box_quat, 2 blue: box_linear)."""
    others = [c for c in range(3) if c != channel]
    c = rgb[..., channel]
    return (c > 0.08) & (c > 1.5 * rgb[..., others[0]]) & (c > 1.5 * rgb[..., others[1]])


worst_centroid = worst_xor = worst_mean = 0.0
for i, t in enumerate(times):
    pair = [np.asarray(Image.open(f"{out}/{who}_{i}.png").convert("RGB"), dtype=np.float64) / 255
            for who in ("blender", "limn")]
    mean = float(np.abs(pair[0] - pair[1]).mean())
    worst_mean = max(worst_mean, mean)
    row = [f"mean error {mean:.4f}"]
    for name, channel in (("box_bezier", 0), ("box_quat", 1), ("box_linear", 2)):
        b, l = silhouette(pair[0], channel), silhouette(pair[1], channel)
        if not b.any() or not l.any():
            row.append(f"{name} {b.sum()} / {l.sum()} px")
            worst_centroid = float("inf")
            continue
        cb, cl = np.argwhere(b).mean(axis=0), np.argwhere(l).mean(axis=0)
        centroid = float(np.hypot(*(cb - cl)))
        xor = float((b ^ l).sum() / (b | l).sum())
        worst_centroid, worst_xor = max(worst_centroid, centroid), max(worst_xor, xor)
        row.append(f"{name} {b.sum()}/{l.sum()} px, centroid {centroid:.2f} px, not shared {xor:.3f}")
    print(f"  {t}s: " + "; ".join(row))
print(f"frames: largest mean error {worst_mean:.3g}; silhouettes: largest centroid distance {worst_centroid:.3g} px,"
      f" largest share not in common {worst_xor:.3g}")
if worst_centroid > 1.0:
    sys.exit("blender_motion_check: a silhouette lies more than a pixel from Blender's")
FRAMES
fi
echo "blender_motion_check: files in $out"
exit $status
