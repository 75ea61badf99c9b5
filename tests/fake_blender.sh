#!/usr/bin/env bash
# A stand-in for Blender in tests of Cycles references (tests/test_cycles_reference.sh).
# It takes the command line limn reference gives Blender:
#   fake_blender.sh -b --factory-startup -noaudio --threads T --python-exit-code 1 --python SCRIPT -- SPEC OUT
# checks it and the spec's keys, logs "threads=T SPEC" to $FAKE_BLENDER_LOG, and writes OUT by
# rendering the built-in Cornell box with `$FAKE_BLENDER_LIMN capture` at the spec's size (under a
# temporary name, then renamed, as the real script does; once a size when $FAKE_BLENDER_CACHE names a
# folder). --version prints
# "Blender $FAKE_BLENDER_VERSION" (default 0.0). On demand:
#   FAKE_BLENDER_FAIL=1    prints an error naming the view and exits 1, writing nothing
#   FAKE_BLENDER_SLEEP=S   writes half a file to OUT and a temporary beside it, then sleeps S seconds
#                          (to be killed)
set -u
if [ "${1:-}" = --version ]; then
  echo "Blender ${FAKE_BLENDER_VERSION:-0.0} (limn test double)"
  echo "	build date: never"
  exit 0
fi
[ $# = 12 ] && [ "$1 $2 $3 $4" = "-b --factory-startup -noaudio --threads" ] && [ "$5" -ge 1 ] &&
  [ "$6 $7 $8" = "--python-exit-code 1 --python" ] && [ -f "$9" ] && [ "${10}" = -- ] \
  || { echo "fake blender: not the contract's command line: $*"; exit 3; }
threads=$5
spec=${11} out=${12}
echo "threads=$threads $spec" >> "${FAKE_BLENDER_LOG:-/dev/null}"
# The spec: exactly the contract's keys, each of its type; prints "VIEW WIDTH HEIGHT".
read -r view width height < <(python3 - "$spec" <<'PY'
import json, numbers, sys
s = json.load(open(sys.argv[1]))
keys = {"scene", "camera", "width", "height", "samples", "bounces", "seed", "materials", "view", "sky"}
assert set(s) == keys, "keys %s" % sorted(set(s) ^ keys)
assert s["scene"].startswith("/") and s["scene"].endswith((".glb", ".gltf")), s["scene"]
assert set(s["camera"]) == {"eye", "target", "up", "fov_y"}, s["camera"]
for k in ("eye", "target", "up"):
    assert len(s["camera"][k]) == 3 and all(isinstance(x, numbers.Real) for x in s["camera"][k]), k
assert 0 < s["camera"]["fov_y"] < 180
for k in ("width", "height", "samples", "bounces", "seed"):
    assert isinstance(s[k], int) and s[k] >= 0, k
assert s["materials"] in ("phong", "pbr")
assert s["sky"] is None or set(s["sky"]) == {"zenith", "horizon", "intensity"}, s["sky"]
print(s["view"].replace(" ", "_"), s["width"], s["height"])
PY
) || { echo "fake blender: a bad spec $spec"; exit 3; }
if [ -n "${FAKE_BLENDER_FAIL:-}" ]; then
  echo "Error: cycles_render: view $view: cannot import the scene (a test double's failure)"
  exit 1
fi
if [ -n "${FAKE_BLENDER_SLEEP:-}" ]; then # half an output, and a temporary of its own beside it
  head -c 100 /dev/zero > "$out"
  head -c 100 /dev/zero > "$(dirname "$out")/.cycles-render.exr"
  sleep "$FAKE_BLENDER_SLEEP"
fi
# One capture a size (kept in $FAKE_BLENDER_CACHE when set): the image itself matters less than its size.
part=${out%.exr}.part.exr cache=${FAKE_BLENDER_CACHE:-}/${width}x${height}.exr
if [ -n "${FAKE_BLENDER_CACHE:-}" ] && [ -f "$cache" ]; then
  cp "$cache" "$part"
else
  "$FAKE_BLENDER_LIMN" capture --scene cornell --tech dl --size "${width}x${height}" --output "$part" --quiet || exit 1
  [ -z "${FAKE_BLENDER_CACHE:-}" ] || cp "$part" "$cache"
fi
mv "$part" "$out"
