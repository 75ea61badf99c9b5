#!/usr/bin/env bash
# A stand-in for Blender in tests of Cycles references (tests/test_cycles_reference.sh).
# It takes the command line limn reference gives Blender:
#   fake_blender.sh -b --factory-startup -noaudio --threads T --python-exit-code 1 --python SCRIPT -- \
#                   SPEC OUT [SPEC OUT ...]
# checks it and each spec's keys, logs "threads=T SPEC run=PID" a view to $FAKE_BLENDER_LOG, and
# writes each OUT by rendering the built-in Cornell box with `$FAKE_BLENDER_LIMN capture` at the spec's
# size (under a temporary name, then renamed, as the real script does; once a size when
# $FAKE_BLENDER_CACHE names a folder), then writes the pair's index to $LIMN_PROGRESS_FD, as the
# real script does. --version prints "Blender $FAKE_BLENDER_VERSION" (default 0.0). On demand:
#   FAKE_BLENDER_FAIL=PATTERN    a view whose name matches the glob prints an error naming it and
#                                writes nothing; the others render, and the run exits 1
#   FAKE_BLENDER_SLEEP=S[:PATTERN]  at each view (matching PATTERN), writes half a file to OUT and a
#                                temporary beside it, then sleeps S seconds (to be killed)
set -u
if [ "${1:-}" = --version ]; then
  echo "Blender ${FAKE_BLENDER_VERSION:-0.0} (limn test double)"
  echo "	build date: never"
  exit 0
fi
[ $# -ge 12 ] && [ $(($# % 2)) = 0 ] && [ "$1 $2 $3 $4" = "-b --factory-startup -noaudio --threads" ] && [ "$5" -ge 1 ] &&
  [ "$6 $7 $8" = "--python-exit-code 1 --python" ] && [ -f "$9" ] && [ "${10}" = -- ] \
  || { echo "fake blender: not the contract's command line: $*"; exit 3; }
threads=$5
render() { # SPEC OUT
  local spec=$1 out=$2 view width height
  echo "threads=$threads $spec run=$$" >> "${FAKE_BLENDER_LOG:-/dev/null}"
  # The spec: exactly the contract's keys, each of its type; prints "WIDTH HEIGHT VIEW".
  read -r width height view < <(python3 - "$spec" <<'PY'
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
print(s["width"], s["height"], s["view"])
PY
  ) || { echo "fake blender: a bad spec $spec"; exit 3; }
  # shellcheck disable=SC2053
  if [ -n "${FAKE_BLENDER_FAIL:-}" ] && [[ $view == ${FAKE_BLENDER_FAIL} ]]; then
    echo "limn cycles: view '$view': scene: cannot import it (a test double's failure)" >&2
    return 1
  fi
  local pause=${FAKE_BLENDER_SLEEP:-} at='*'
  [[ $pause == *:* ]] && at=${pause#*:} pause=${pause%%:*}
  # shellcheck disable=SC2053
  if [ -n "$pause" ] && [[ $view == $at ]]; then # half an output, and a temporary of its own beside it
    head -c 100 /dev/zero > "$out"
    head -c 100 /dev/zero > "$(dirname "$out")/.cycles-render.exr"
    sleep "$pause"
  fi
  # One capture a size (kept in $FAKE_BLENDER_CACHE when set): the image itself matters less than its size.
  local part=${out%.exr}.part.exr cache=${FAKE_BLENDER_CACHE:-}/${width}x${height}.exr
  if [ -n "${FAKE_BLENDER_CACHE:-}" ] && [ -f "$cache" ]; then
    cp "$cache" "$part"
  else
    "$FAKE_BLENDER_LIMN" capture --scene cornell --tech dl --size "${width}x${height}" --output "$part" --quiet || return 1
    [ -z "${FAKE_BLENDER_CACHE:-}" ] || cp "$part" "$cache"
  fi
  mv "$part" "$out"
}
shift 10
failed=0 index=0
while [ $# -gt 0 ]; do
  if render "$1" "$2"; then
    [ -z "${LIMN_PROGRESS_FD:-}" ] || echo "$index" >&"$LIMN_PROGRESS_FD"
  else
    failed=1
  fi
  index=$((index + 1))
  shift 2
done
exit $failed
