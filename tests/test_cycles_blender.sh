#!/usr/bin/env bash
# limn reference --renderer cycles end to end, with the real Blender and
# cli/cycles_render.py, on one small view (data/scenes/pov_ball.gltf at
# 32x24, 16 samples): the reference is written under its hash at the view's
# size (limn compare reads it beside Limn's own image), a second run is a
# cache hit, and the direct-only render (0 bounces) differs from the one
# with indirect light. Skipped (77) without blender (tools/dev.sh installs
# it) or without the script.
set -u
limn=$1
root=$2
. "$(dirname "$0")/shell_test.sh"
needs blender "tools/dev.sh installs it"
[ -f "$root/cli/cycles_render.py" ] || { echo "no cli/cycles_render.py: skipped"; exit 77; }
scratch blender
cd "$tmp" || exit 1
cp "$root/data/scenes/pov_ball.gltf" ball.gltf
printf '# name eye target fov\nfront 0 1.5 3  0 0.3 0  45\n' > ball.cams
printf 'return { scenes = { { scene = "ball.gltf", cameras = "ball.cams" } }, sizes = { "32x24" },\n  set = { ambient = 0 }, output = "out/{camera}_{technique}.png" }\n' > job.lua
cy=(--renderer cycles --samples 16 --refs refs)
"$limn" reference --job job.lua "${cy[@]}" --bounces 2 >log 2>&1 || { cat log; fail "Cycles reference"; }
grep -q "1 rendered, 0 cached" log || { cat log; fail "the view was not rendered"; }
full=$(ls refs/ball/front_32x24-cycles-*.exr) || fail "no reference: $(ls -R refs)"
"$limn" reference --job job.lua "${cy[@]}" --bounces 2 >log 2>&1 && grep -q "0 rendered, 1 cached" log \
  || { cat log; fail "the second run was no cache hit"; }
"$limn" reference --job job.lua "${cy[@]}" --bounces 0 >log 2>&1 || { cat log; fail "direct-only reference"; }
direct=$(ls refs/ball/front_32x24-cycles-*.exr | grep -v "$full")
"$limn" compare "$full" "$direct" --json >m.json || fail "compare the two references"
mean=$(grep -o '"mean_error": [-0-9.e+]*' m.json | awk '{print $2}')
awk -v m="$mean" 'BEGIN { exit !(m > 0) }' || { cat m.json; fail "indirect light changed nothing ($mean)"; }
"$limn" capture --scene ball.gltf --tech dl --size 32x24 --output dl.exr --quiet || fail "capture"
"$limn" compare dl.exr "$direct" --json >d.json || fail "Limn's image and Cycles' do not compare (size?)"
cat m.json d.json
# Stopped mid-view with the real Blender: a render of a million samples, stopped by SIGTERM once Blender
# says it is sampling, leaves no reference, no partial file and no Blender.
"$limn" reference --job job.lua "${cy[@]}" --samples 1000000 --refs refs-kill >log 2>&1 &
pid=$!
sampling() { grep -qs "Sample " refs-kill/ball/*.log; }
wait_until 60 sampling || { kill "$pid"; cat log; fail "the render did not start in 60 s"; }
kill -TERM "$pid"
{ wait "$pid"; } 2>/dev/null
left() { pgrep -f "blender .*$tmp/refs-kill"; }
gone() { ! left >/dev/null; }
wait_until 5 gone
blender_pid=$(left) && { kill $blender_pid; fail "Blender outlived limn"; }
[ -z "$(find refs-kill -name "*.exr" -o -name "*tmp*" -o -name ".cycles*")" ] ||
  fail "a stopped render left files: $(find refs-kill)"
echo "Cycles end to end passed"
