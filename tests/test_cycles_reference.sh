#!/usr/bin/env bash
# Cycles references (limn reference --renderer cycles) through a stand-in for
# Blender (tests/fake_blender.sh, which checks the command line and the spec's
# keys, logs each call and writes an EXR), so that it runs without Blender:
# - the file name carries the hash (-cycles-<16 hex>) and the hash changes
#   with samples, bounces, seed, size, Blender's version and the script; a
#   second run is a cache hit that starts no render;
# - Blender gets every core when one view renders at a time;
# - a failing render names the view, shows Blender's error line, exits 1 and
#   leaves no file; a scene's views go to one Blender run (two with --jobs
#   2), a failed view among them fails alone and a rerun renders only it; a run stopped by SIGTERM leaves no file and no Blender;
#   one killed by SIGKILL takes its render with it, and the next run removes
#   its partial file;
# - a missing Blender names the Debian package and the install command;
# - --shard splits the views; the job's renderer field selects Cycles, its
#   references table sets the sky (a sky-lit job without one is refused);
# - limn report against Cycles: every row says so, and the direct-only
#   floor is the same render with 0 bounces; limn farm passes the flags on;
# - an animated scene at a time is given to Blender posed, one file a frame.
set -u
limn=$1
root=$2
. "$(dirname "$0")/shell_test.sh"
needs python3 "tools/dev.sh installs it"
scratch cycles
cd "$tmp" || exit 1
mkdir cache
export FAKE_BLENDER_LOG=$tmp/calls FAKE_BLENDER_LIMN=$limn FAKE_BLENDER_CACHE=$tmp/cache
calls() { [ -f calls ] && wc -l < calls || echo 0; }
cp "$root/data/scenes/pov_ball.gltf" ball.gltf
printf '# name eye target fov\nfront 0 1.5 3  0 0.3 0  45\nside 2 1.2 2  0 0.3 0  40\n' > ball.cams
head -2 ball.cams > one.cams
cat > job.lua <<'JOB'
return {
  scenes = { { scene = "ball.gltf", cameras = "one.cams" } },
  sizes = { "32x24" },
  set = { ambient = 0 },
  output = "out/{camera}_{technique}.png",
}
JOB
echo "# stands in for cli/cycles_render.py" > script.py
cy=(--renderer cycles --blender "$root/tests/fake_blender.sh" --cycles-script script.py --samples 16 --refs refs)

# Blender missing: the package and the command, exit 1, nothing written.
"$limn" reference --job job.lua "${cy[@]}" --blender /nonexistent/blender >log 2>&1
rc=$?
[ $rc = 1 ] || { cat log; fail "a missing Blender exited $rc, not 1"; }
grep -q "cannot run '/nonexistent/blender'.*apt-get install blender (Debian package blender)" log \
  || { cat log; fail "a missing Blender does not name the package and the command"; }
[ -e refs ] && fail "a missing Blender left files: $(find refs)"
# A missing script is named too.
"$limn" reference --job job.lua "${cy[@]}" --cycles-script nothere.py >log 2>&1
[ $? = 1 ] && grep -q "nothere.py" log || { cat log; fail "a missing script is not named"; }

# 1. The first run renders; the name carries the hash; the spec is left beside it; nothing else is.
"$limn" reference --job job.lua "${cy[@]}" >log 2>&1 || { cat log; fail "first Cycles reference run"; }
grep -q "1 rendered, 0 cached" log || { cat log; fail "the first run did not render the view"; }
grep -q "Cycles (16 samples, 8 bounces, seed 0, materials phong)" log || { cat log; fail "the run does not say what it renders"; }
first=$(ls refs/ball/) || fail "no reference folder"
echo "$first" | grep -qxE "front_32x24-cycles-[0-9a-f]{16}\.(exr|json)" || fail "names in refs/ball: $first"
[ "$(ls refs/ball | wc -l)" = 2 ] || fail "not just the reference and its spec: $first"
ref=$(ls refs/ball/*.exr)
[ "$(calls)" = 1 ] || fail "$(calls) renders for one view"
# One view at a time gets every core (as many as this process may use).
grep -q "^threads=$(nproc) " calls || fail "Blender did not get $(nproc) threads: $(cat calls)"
python3 - refs/ball/*.json "$tmp/ball.gltf" <<'PY' || fail "the spec does not hold the view's settings"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["scene"] == sys.argv[2], s["scene"]
assert (s["width"], s["height"], s["samples"], s["bounces"], s["seed"]) == (32, 24, 16, 8, 0), s
assert s["materials"] == "phong" and s["sky"] is None and s["view"] == "ball/front 32x24", s
c = s["camera"]
assert [round(x, 5) for x in c["eye"]] == [0, 1.5, 3] and abs(c["fov_y"] - 45) < 1e-4, c
# target: one unit from the eye toward (0, 0.3, 0)
d = [t - e for t, e in zip(c["target"], c["eye"])]
assert abs(sum(x * x for x in d) - 1) < 1e-5 and abs(d[0]) < 1e-6 and d[1] < 0 and d[2] < 0, d
PY

# 2. A second run is a cache hit: no render started.
"$limn" reference --job job.lua "${cy[@]}" >log 2>&1 || { cat log; fail "second run"; }
grep -q "0 rendered, 1 cached" log || { cat log; fail "the second run rendered again"; }
[ "$(calls)" = 1 ] || fail "a cached view started a render"

# 3. The hash follows what decides the image: each change a new file, the old one kept.
names=$ref
for change in "--samples 32" "--seed 7" "--bounces 2" "--materials pbr" "--sky 1,1,1:0.5"; do
  # shellcheck disable=SC2086
  "$limn" reference --job job.lua "${cy[@]}" $change >log 2>&1 || { cat log; fail "run with $change"; }
  grep -q "1 rendered, 0 cached" log || { cat log; fail "$change did not render a new reference"; }
  new=$(ls -t refs/ball/*.exr | head -1)
  echo "$names" | grep -qx "$new" && fail "$change kept the name $new"
  names=$(printf '%s\n%s' "$names" "$new")
done
sed 's/"32x24"/"40x30"/' job.lua > size.lua
"$limn" reference --job size.lua "${cy[@]}" >log 2>&1 && grep -q "1 rendered" log || { cat log; fail "a new size"; }
ls refs/ball/front_40x30-cycles-*.exr >/dev/null || fail "no reference at the new size"
FAKE_BLENDER_VERSION=9.9 "$limn" reference --job job.lua "${cy[@]}" >log 2>&1
grep -q "1 rendered, 0 cached" log || { cat log; fail "another Blender version did not render anew"; }
echo "# changed" >> script.py
"$limn" reference --job job.lua "${cy[@]}" >log 2>&1
grep -q "1 rendered, 0 cached" log || { cat log; fail "a changed script did not render anew"; }
[ "$(ls refs/ball/front_32x24-*.exr | wc -l)" = 8 ] || fail "not 8 distinct references: $(ls refs/ball)"
# Back to the first settings: the first file, cached.
sed -i '$d' script.py
"$limn" reference --job job.lua "${cy[@]}" >log 2>&1
grep -q "0 rendered, 1 cached" log && grep -q "$ref" log || { cat log; fail "the first settings are not a hit on $ref"; }
ls refs/ball | grep -q tmp && fail "a temporary file was left: $(ls refs/ball)"

# 4. A failing render: named by view, Blender's line shown, exit 1, no file.
FAKE_BLENDER_FAIL='*' "$limn" reference --job job.lua "${cy[@]}" --refs refs-fail >log 2>&1
rc=$?
cat log
[ $rc = 1 ] || fail "a failing render exited $rc, not 1"
grep -q "view 0 (ball, camera 'front', 32x24): Cycles failed (exit status 1)" log || fail "the failure does not name the view"
grep -q "  | limn cycles: view 'ball/front 32x24': scene: cannot import it" log || fail "Blender's error line is not shown"
find refs-fail -name "*.exr" | grep -q . && fail "a failed render left an image: $(find refs-fail)"

# 5. Stopped mid-view: SIGTERM leaves no file and no Blender; SIGKILL takes the render with it and the
# next run clears what it left.
rendering() { [ -n "$(ls -A "$1"/ball/*.tmp-*/.cycles-render.exr 2>/dev/null)" ]; } # REFS: a view's render begun
gone() { ! kill -0 "$1" 2>/dev/null; }
stop_mid_view() { # signal
  rm -f calls
  FAKE_BLENDER_SLEEP=30 "$limn" reference --job job.lua "${cy[@]}" --refs refs-kill >log 2>&1 &
  local pid=$!
  wait_until 10 rendering refs-kill
  [ -s calls ] && [ -n "$(ls -A refs-kill/ball/*.tmp-*/)" ] || fail "the render did not start"
  fake=$(pgrep -f "fake_blender.sh .*refs-kill" | head -1)
  [ -n "$fake" ] || fail "no Blender running"
  kill -"$1" "$pid"
  { wait "$pid"; } 2>/dev/null
  wait_until 5 gone "$fake"
  kill -0 "$fake" 2>/dev/null && { kill "$fake"; fail "Blender outlived a limn stopped by SIG$1"; }
  ls refs-kill/ball/*.exr 2>/dev/null | grep -v '\.tmp-' && fail "SIG$1 left a reference"
  return 0
}
stop_mid_view TERM
[ -z "$(find refs-kill -name "*tmp*" -o -name ".cycles*")" ] || fail "SIGTERM left partial files: $(find refs-kill)"
grep -q "stopped by signal 15; no partial reference left" log || { cat log; fail "SIGTERM is not said"; }
stop_mid_view KILL
[ -n "$(ls -A refs-kill/ball/*.tmp-*/ 2>/dev/null)" ] || fail "the partial files of a SIGKILLed run are not there to clear"
"$limn" reference --job job.lua "${cy[@]}" --refs refs-kill >log 2>&1 || { cat log; fail "run after a kill"; }
[ "$(ls -A refs-kill/ball/)" = "$(basename "${ref%.exr}").exr
$(basename "${ref%.exr}").json" ] || fail "after a kill and a rerun: $(ls -A refs-kill/ball)"

# 5b. A scene's views go to one Blender run, each view's time in its progress line; a failed view is
# named, leaves no file and fails the command while the others are kept; the rerun renders only it.
# --jobs 2 splits the scene's views over two runs.
sed 's/one.cams/ball.cams/; s/"32x24"/"32x24", "16x12"/' job.lua > four.lua
views_of() { awk '{print $3}' calls | sort | uniq -c | awk '{print $1}' | sort -n | tr '\n' ' '; }
rm -f calls
FAKE_BLENDER_FAIL='ball/side 32x24' "$limn" reference --job four.lua "${cy[@]}" --refs refs-batch >log 2>&1
rc=$?
[ $rc = 1 ] || { cat log; fail "a failed view in a batch exited $rc, not 1"; }
[ "$(views_of)" = "4 " ] || fail "four views did not go to one Blender run: $(cat calls)"
grep -q "view 1 (ball, camera 'side', 32x24): Cycles failed (exit status 1)" log \
  && grep -q "  | limn cycles: view 'ball/side 32x24': scene: cannot import it" log || { cat log; fail "the failed view is not named"; }
[ "$(grep -c "^\[[0-9]/4\] refs-batch/ball/.*-cycles-[0-9a-f]*\.exr ([0-9.]* s)$" log)" = 3 ] \
  || { cat log; fail "not three views' progress lines, each with its time"; }
[ "$(ls refs-batch/ball/*.exr | wc -l)" = 3 ] && ! ls refs-batch/ball/side_32x24-*.exr 2>/dev/null \
  || fail "not the three good views' references alone: $(ls refs-batch/ball)"
[ -z "$(find refs-batch -name "*tmp*" -o -name ".cycles*")" ] || fail "a failed batch left temporaries: $(find refs-batch)"
rm -f calls
"$limn" reference --job four.lua "${cy[@]}" --refs refs-batch >log 2>&1 && grep -q "1 rendered, 3 cached" log \
  || { cat log; fail "the rerun after a failed view"; }
grep -q "side_32x24" calls && [ "$(calls)" = 1 ] || fail "the rerun rendered more than the missing view: $(cat calls)"
[ -z "$(find refs-batch -name "*.log")" ] || fail "a successful run left its log"
rm -f calls
"$limn" reference --job four.lua "${cy[@]}" --refs refs-jobs --jobs 2 >log 2>&1 && grep -q "4 rendered" log \
  || { cat log; fail "--jobs 2"; }
[ "$(views_of)" = "2 2 " ] || fail "--jobs 2 did not split the four views over two runs: $(cat calls)"
# Stopped in a batch's second view: the first view's reference is kept, the second leaves nothing.
rm -f calls
FAKE_BLENDER_SLEEP="30:ball/side 32x24" "$limn" reference --job four.lua "${cy[@]}" --refs refs-stop >log 2>&1 &
pid=$!
wait_until 10 rendering refs-stop
ls refs-stop/ball/front_32x24-cycles-*.exr >/dev/null 2>&1 || { kill $pid; fail "the first view is not in place before the second ends"; }
kill -TERM $pid
{ wait $pid; } 2>/dev/null
[ "$(ls refs-stop/ball/*.exr | wc -l)" = 1 ] && [ -z "$(find refs-stop -name "*tmp*" -o -name ".cycles*")" ] \
  || fail "a batch stopped in its second view: $(find refs-stop)"

# 5c. A file camera whose aspectRatio (1) is not the output's (2:1): the spec keeps its yfov (0.75 rad),
# as Limn's frame does (test_gltf), and Blender's vertical sensor fit widens x.
python3 - "$root/data/scenes/pov_ball.gltf" square.gltf <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["cameras"][0]["perspective"]["aspectRatio"] = 1.0
json.dump(d, open(sys.argv[2], "w"))
PY
sed -n 's#"ball.gltf", cameras = "one.cams"#"square.gltf"#; s/"32x24"/"32x16"/; p' job.lua > square.lua
"$limn" reference --job square.lua "${cy[@]}" --refs refs-square >log 2>&1 || { cat log; fail "a square camera"; }
python3 - refs-square/square/*.json <<'PY' || fail "the spec does not keep the camera's yfov on a wider output"
import json, math, sys
s = json.load(open(sys.argv[1]))
assert (s["width"], s["height"]) == (32, 16), s
assert abs(s["camera"]["fov_y"] - math.degrees(0.75)) < 1e-4, s["camera"]
PY

# 6. Shards split the views: 0/2 renders the first camera, 1/2 the second, then both are cached.
sed 's/one.cams/ball.cams/' job.lua > two.lua
rm -f calls
"$limn" reference --job two.lua "${cy[@]}" --refs refs-shard --shard 0/2 >log 2>&1 && grep -q "(1 in shard 0/2)" log \
  && grep -q "1 rendered" log || { cat log; fail "shard 0/2"; }
"$limn" reference --job two.lua "${cy[@]}" --refs refs-shard --shard 1/2 >log 2>&1 && grep -q "1 rendered" log \
  || { cat log; fail "shard 1/2"; }
[ "$(grep -c front calls) $(grep -c side calls)" = "1 1" ] || fail "the shards did not render one camera each: $(cat calls)"
"$limn" reference --job two.lua "${cy[@]}" --refs refs-shard >log 2>&1 && grep -q "0 rendered, 2 cached" log \
  || { cat log; fail "the shards' references are not the whole job's"; }

# 7. The job's renderer field: Cycles without --renderer; a bad one refused by name.
sed 's/sizes = /renderer = "cycles", sizes = /' job.lua > field.lua
"$limn" reference --job field.lua "${cy[@]:2}" >log 2>&1 && grep -q "0 rendered, 1 cached" log \
  || { cat log; fail "the job's renderer = \"cycles\" did not select Cycles"; }
sed 's/sizes = /renderer = "mitsuba", sizes = /' job.lua > badfield.lua
"$limn" reference --job badfield.lua "${cy[@]:2}" >log 2>&1
[ $? = 2 ] && grep -q 'field.lua: renderer: "pov" or "cycles", not "mitsuba"' log || { cat log; fail "a bad renderer field"; }
# The job's references table: its sky finds the reference --sky made; a bad one is refused by name; a
# sky-lit job (sky.enabled) without a reference sky is refused rather than judged against a sky-less one.
sed 's/sizes = /references = { sky = "1,1,1:0.5" }, sizes = /' job.lua > refsky.lua
"$limn" reference --job refsky.lua "${cy[@]}" >log 2>&1 && grep -q "0 rendered, 1 cached" log \
  || { cat log; fail "the job's references.sky did not find the reference --sky 1,1,1:0.5 made"; }
sed 's/sizes = /references = { sky = "0.1,0.2" }, sizes = /' job.lua > badsky.lua
"$limn" reference --job badsky.lua "${cy[@]}" >log 2>&1
[ $? = 2 ] && grep -q 'badsky.lua: references.sky: "ZENITH:HORIZON' log || { cat log; fail "a bad references.sky"; }
sed 's/ambient = 0/ambient = 0, ["sky.enabled"] = true/' job.lua > skylit.lua
"$limn" reference --job skylit.lua "${cy[@]}" >log 2>&1
[ $? = 1 ] && grep -q "skylit.lua: its views are lit by the sky" log || { cat log; fail "a sky-lit job without a reference sky"; }
"$limn" report --job skylit.lua "${cy[@]}" --out rep-sky --sweep dl --frames 1 --warmup 0 >log 2>&1
[ $? != 0 ] && grep -q "references would have none" log && [ ! -e rep-sky ] || { cat log; fail "report on a sky-lit job without a reference sky"; }
"$limn" reference --job skylit.lua "${cy[@]}" --sky 1,1,1:0.5 >log 2>&1 && grep -q "0 rendered, 1 cached" log \
  || { cat log; fail "--sky did not serve a sky-lit job"; }
"$limn" reference --job job.lua --renderer mitsuba >log 2>&1
[ $? = 2 ] && grep -q "renderer wants pov or cycles" log || { cat log; fail "a bad --renderer"; }
# What only POV-Ray has is refused for Cycles.
"$limn" reference --job job.lua "${cy[@]}" --shadows off >log 2>&1
[ $? = 1 ] && grep -q "Cycles' lights always cast shadows" log || { cat log; fail "--shadows off with Cycles"; }

# 8. limn report against Cycles: the floor is the 0-bounce render; every row says Cycles.
rm -f calls
"$limn" report --job job.lua "${cy[@]}" --out rep --sweep dl --frames 1 --warmup 0 >log 2>&1 \
  || { cat log; fail "report against Cycles"; }
grep -q "error [0-9.]* against Cycles" log || { cat log; fail "the progress does not say Cycles"; }
[ "$(calls)" = 2 ] || fail "report rendered $(calls) references, not the direct-only one and the next seed's"
python3 - calls <<'PY' || fail "the floor is not the same render with 0 bounces, or the noise not the next seed's"
import json, sys
direct, second = (json.load(open(line.split()[1])) for line in open(sys.argv[1]))
assert (direct["bounces"], direct["seed"], direct["samples"]) == (0, 0, 16), direct
assert (second["bounces"], second["seed"], second["samples"]) == (8, 1, 16), second
PY
# The stand-in renders the same image at every seed: no noise.
awk -F, 'NR > 1 && $19 != 0 { bad = 1 } END { exit bad }' rep/report.csv || fail "the reference's noise is not 0"
grep -q "^Reference noise (the mean error between the references at seeds 0 and 1), mean over the views: 0.00000," \
  rep/report.md || fail "the summary does not give the reference's noise"
# With the next seed's reference gone and none rendered (--cached-refs), the noise is n/a, not a number.
rm -rf refs-noseed && cp -r refs refs-noseed
for f in refs-noseed/ball/*-cycles-*.json; do
  python3 -c 'import json, sys; sys.exit(json.load(open(sys.argv[1]))["seed"] != 1)' "$f" && rm "${f%.json}.exr"
done
"$limn" report --job job.lua "${cy[@]}" --refs refs-noseed --cached-refs --out rep-noseed --sweep dl --frames 1 \
  --warmup 0 >log 2>&1 || { cat log; fail "report without the next seed's reference"; }
grep -q "^Reference noise (.*), mean over the views: n/a (no view's second seed is cached)" rep-noseed/report.md \
  || { grep Reference rep-noseed/report.md; fail "a missing second seed's noise is not n/a"; }
awk -F, 'NR == 1 { ok = $18 == "reference" } NR > 1 && $18 != "\"Cycles\"" { ok = 0 } END { exit !ok }' rep/report.csv \
  || { cat rep/report.csv; fail "the CSV does not name Cycles on each row"; }
grep -q '"reference": "Cycles"' rep/report.json || fail "the JSON does not name Cycles"
grep -q "^# Error against Cycles" rep/report.md && grep -q "direct light only (--renderer cycles --bounces 0)" rep/report.md \
  || fail "the summary does not say Cycles and its floor"
"$limn" report --job job.lua "${cy[@]}" --out rep2 --sweep dl --require-refs --refs refs-none >log 2>&1
[ $? = 1 ] && grep -q "make them with: limn reference --job job.lua --refs refs-none --renderer cycles" log \
  || { cat log; fail "--require-refs does not name the Cycles command"; }

# 9. An animated scene at a time: Blender gets the scene as Limn poses it, one posed file a frame, each
# named by its hash and read back by Limn as that pose (the door moves between the frames).
cat > door.lua <<JOB
return { scenes = { "$root/data/scenes/door.glb" }, sizes = { "32x24" }, time = { 0, 1, 1 },
         output = "out/{camera}_{frame}.png" }
JOB
rm -f calls
"$limn" reference --job door.lua "${cy[@]}" >log 2>&1 && grep -q "2 rendered" log || { cat log; fail "a door sequence"; }
posed=$(for f in $(awk '{print $2}' calls); do python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["scene"])' "$f"; done)
[ "$(echo "$posed" | sort -u | wc -l)" = 2 ] || fail "not one posed scene a frame: $posed"
for f in $posed; do
  case $f in "$tmp"/refs/door/door-posed-*.glb) ;; *) fail "the posed scene $f is not in the references' folder";; esac
  "$limn" export-gltf --scene "$f" --output "again.glb" >/dev/null 2>&1 || fail "Limn does not read $f back"
done
cmp -s $posed && fail "the two frames' posed scenes are the same"
"$limn" reference --job door.lua "${cy[@]}" >log 2>&1 && grep -q "0 rendered, 2 cached" log || { cat log; fail "the posed frames are not cached"; }

# 10. limn farm slurm passes the renderer and its flags to the reference step and the merge.
"$limn" farm slurm --job job.lua --shards 2 --references "${cy[@]}" --dir farm >log 2>&1 || { cat log; fail "farm"; }
grep -q "reference --job 'job.lua' --shard auto/2 --refs 'refs'.* --renderer 'cycles' .*--samples '16'" farm/*.sbatch \
  && grep -q "manifest merge .* --renderer 'cycles'" farm/*.sbatch || { cat farm/*.sbatch; fail "farm does not pass Cycles on"; }
echo "all Cycles reference checks passed"
