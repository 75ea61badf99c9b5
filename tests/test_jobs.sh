#!/usr/bin/env bash
# Capture jobs as a user meets them: skipping what exists, --force, shards,
# merging shard manifests, --shard auto, limn farm slurm's script (its tasks
# run here without Slurm), the manifest, a killed job completed by a rerun,
# and bad job files and camera lists (a message naming the file and entry or
# line, exit non-zero). Each case is its file and its checks, written out:
# cases read alike.
set -u
limn=$1
root=$2
. "$(dirname "$0")/shell_test.sh"
scratch jobs
cd "$tmp"

run() { # run EXPECTED_RC ARGS... : output in out.txt, err.txt
  local want=$1; shift
  "$limn" "$@" >out.txt 2>err.txt; rc=$?
  [ "$rc" -eq "$want" ] || { echo "  '$*' exited $rc, wanted $want"; sed 's/^/  | /' err.txt | head -5; return 1; }
}
err_has() { grep -qF -- "$1" err.txt || { echo "  stderr lacks '$1':"; sed 's/^/  | /' err.txt | head -5; return 1; }; }
out_has() { grep -qF -- "$1" out.txt || { echo "  stdout lacks '$1':"; sed 's/^/  | /' out.txt | tail -3; return 1; }; }
count_is() { [ "$1" -eq "$2" ] || { echo "  counted $1, wanted $2"; return 1; }; }
whole_pngs() { # every PNG ends in its IEND chunk
  local f
  for f in "$@"; do tail -c 12 "$f" | grep -q IEND || { echo "  $f is cut short"; return 1; }; done
}
entries() { grep -c '{"file": ' "$1"; }
run_entries() { grep -c "\"run\": $2, \"scene\"" "$1"; }

scenes=$root/data/scenes
cat > job.lua <<LUA
-- two scenes, two sizes: 2 * (4 + 4) = 16 views
return {
  scenes = { "$scenes/cornell.glb", { scene = "$scenes/garage.glb", cameras = "$scenes/garage.cams" } },
  sizes = { "48x36", "64x48" },
  techniques = { "dl" },
  set = { ambient = 0.05 },
  output = "out/{scene}/{camera}-{technique}-{size}.png",
}
LUA

# A whole run: every view written, a manifest with hashes, strings and times.
check "job runs" run 0 capture --job job.lua
check "job writes 16 images" count_is "$(ls out/*/*.png | wc -l)" 16
check "images are whole" whole_pngs out/*/*.png
check "plain lines when not a tty" out_has "[16/16] out/garage/low-dl-64x48.png"
check "manifest lists every image" count_is "$(entries out/manifest.json)" 16
for key in '"job_hash": "' '"script_hash": "' '"shader_hash": "' '"scene_hash": "' '"renderer": "' \
           '"gl_version": "' '"width": 64, "height": 48' '"passes": [{"name": "gbuffer", "kind": "scene", "ms": ' \
           '"options": ["ambient=0.05"]'; do
  check "manifest has $key" grep -qF -- "$key" out/manifest.json
done

# A rerun skips everything; deleting one image redoes that one only.
check "rerun" run 0 capture --job job.lua
check "rerun skips all" out_has "0 rendered, 16 skipped"
rm out/cornell/high-dl-48x36.png
check "rerun after a delete" run 0 capture --job job.lua
check "only the deleted image is redone" out_has "1 rendered, 15 skipped"
check "manifest keeps every image" count_is "$(entries out/manifest.json)" 16
check "manifest: one image from run 3" count_is "$(run_entries out/manifest.json 3)" 1
check "manifest: it is the deleted one" grep -q '"file": "out/cornell/high-dl-48x36.png", "view": 2, "run": 3' out/manifest.json
check "--force redoes all" run 0 capture --job job.lua --force
check "--force count" out_has "16 rendered, 0 skipped"

# Shards split the views between them, each with its own manifest.
rm -rf out
check "shard 0/3" run 0 capture --job job.lua --shard 0/3
check "shard 0/3 renders views 0, 3, ..." count_is "$(ls out/*/*.png | wc -l)" 6
check "shard 2/3" run 0 capture --job job.lua --shard 2/3
check "shard 1/3" run 0 capture --job job.lua --shard 1/3
check "shards together render all" count_is "$(ls out/*/*.png | wc -l)" 16
check "shard manifests" count_is "$(( $(entries out/manifest.shard-0-of-3.json) + $(entries out/manifest.shard-1-of-3.json) + $(entries out/manifest.shard-2-of-3.json) ))" 16
# Merging the shards' manifests: every view once, the same hashes, else nothing written.
check "merge" run 0 manifest merge --job job.lua --shards 3
check "merge says so" out_has "job.lua: 16 views from 3 shards, each rendered once; 0 references there; out/manifest.json"
check "merged manifest lists every image" count_is "$(entries out/manifest.json)" 16
check "merged manifest in view order" test "$(grep -o '"view": [0-9]*' out/manifest.json | awk '{ printf "%s ", $2 }')" = "0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 "
check "merged manifest says its shards" grep -qF '"shards": 3,' out/manifest.json
rm out/manifest.json out/garage/low-dl-48x36.png
check "merge with an image missing" run 1 manifest merge --job job.lua --shards 3
check "the missing image is named with its shard" err_has "view 11 (garage, camera 'low', dl, 48x36) out/garage/low-dl-48x36.png: missing (in the manifest, not on disk) (shard 2/3)"
check "the shard to rerun is named" err_has "1 of 16 views missing, 0 duplicated, 0 of 0 references missing: nothing written. Rerun shards 2 "
check "a failed merge writes nothing" test ! -e out/manifest.json
check "shard 2 rerun" run 0 capture --job job.lua --shard 2/3
check "shard 2 rerun renders the missing image only" out_has "1 rendered, 4 skipped"
cp out/manifest.shard-1-of-3.json shard1.json
view0=$(grep '"view": 0,' out/manifest.shard-0-of-3.json | sed 's/,$//')
awk -v l="$view0" '{ print } /"images": \[/ { print "    " l "," }' shard1.json > out/manifest.shard-1-of-3.json
check "merge with a view in two manifests" run 1 manifest merge --job job.lua --shards 3
check "the duplicate is named" err_has "view 0 (cornell, camera 'front', dl, 48x36) out/cornell/front-dl-48x36.png: rendered 2 times, in out/manifest.shard-0-of-3.json and out/manifest.shard-1-of-3.json"
sed 's/"shader_hash": "[0-9a-f]*"/"shader_hash": "0123456789abcdef"/' shard1.json > out/manifest.shard-1-of-3.json
check "merge of shards with other shaders" run 1 manifest merge --job job.lua --shards 3
check "the differing hash is named" err_has "shard 1/3: out/manifest.shard-1-of-3.json has shader_hash 0123456789abcdef, out/manifest.shard-0-of-3.json has "
cp shard1.json out/manifest.shard-1-of-3.json
check "merge with other --set flags" run 1 manifest merge --job job.lua --shards 3 --set ambient=0.2
check "another job hash is named" err_has "shard 0/3: out/manifest.shard-0-of-3.json has job_hash "
check "merge with a shard not run" run 1 manifest merge --job job.lua --shards 4
check "the shard not run is named" err_has "shard 3/4: no manifest out/manifest.shard-3-of-4.json"
check "merge needs --shards" run 2 manifest merge --job job.lua
check "merge: only merge" run 2 manifest join --job job.lua

# --shard auto: the shard from a scheduler's environment, said on stderr.
shard_env() { # shard_env RC MESSAGE SHARD ENV...: capture --job with --shard SHARD under ENV
  local want=$1 msg=$2 shard=$3; shift 3
  env -u SLURM_ARRAY_TASK_ID -u SLURM_ARRAY_TASK_MIN -u SLURM_ARRAY_TASK_MAX -u SLURM_ARRAY_TASK_COUNT \
    -u JOB_COMPLETION_INDEX "$@" "$limn" capture --job job.lua --shard "$shard" >out.txt 2>err.txt
  [ $? = "$want" ] || { echo "  exited $?, wanted $want"; cat err.txt; return 1; }
  err_has "$msg"
}
check "auto: Slurm's id, min and count" shard_env 0 "shard 1/3 from SLURM_ARRAY_TASK_ID=1 less SLURM_ARRAY_TASK_MIN=0, of SLURM_ARRAY_TASK_COUNT=3" \
  auto SLURM_ARRAY_TASK_ID=1 SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_COUNT=3
check "auto renders shard 1/3's views" out_has "16 views (5 in shard 1/3)"
check "auto: Slurm's min and max" shard_env 0 "shard 2/3 from SLURM_ARRAY_TASK_ID=6 less SLURM_ARRAY_TASK_MIN=4, of MAX - MIN + 1 = 3" \
  auto SLURM_ARRAY_TASK_ID=6 SLURM_ARRAY_TASK_MIN=4 SLURM_ARRAY_TASK_MAX=6
check "auto: an array with steps" shard_env 2 "the array's indices are not a range 0-4 (SLURM_ARRAY_TASK_COUNT=3)" \
  auto SLURM_ARRAY_TASK_ID=2 SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_MAX=4 SLURM_ARRAY_TASK_COUNT=3
check "auto/N: Slurm's id as it is" shard_env 0 "shard 1/3 from SLURM_ARRAY_TASK_ID=1, count 3 given" \
  auto/3 SLURM_ARRAY_TASK_ID=1 SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_COUNT=1
check "auto/N: Kubernetes' index" shard_env 0 "shard 2/3 from JOB_COMPLETION_INDEX=2, count 3 given" auto/3 JOB_COMPLETION_INDEX=2
check "auto: Kubernetes without a count" shard_env 2 "JOB_COMPLETION_INDEX=2 (a Kubernetes Indexed Job) gives no count" auto JOB_COMPLETION_INDEX=2
check "auto: an index past the count" shard_env 2 "shard 3 is not in 0 .. 2 (SLURM_ARRAY_TASK_ID=3, count 3 given)" auto/3 SLURM_ARRAY_TASK_ID=3
check "auto: no scheduler" shard_env 2 "neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor JOB_COMPLETION_INDEX" auto
check "auto: not a number" shard_env 2 "SLURM_ARRAY_TASK_ID='x' is not a whole number" auto SLURM_ARRAY_TASK_ID=x

# limn farm slurm: the array script (its tasks run here as Slurm would run them).
check "farm" run 0 farm slurm --job job.lua --shards 3 --partition debug --mem 2G --time 10 \
  --sbatch=--qos=low --set ambient=0.05 --dir jobfarm
check "farm says what it wrote" out_has "job.lua: 16 views in 3 shards (at most 6 views a task); wrote jobfarm/limn-job.sbatch"
for line in '#SBATCH --array=0-2' '#SBATCH --partition=debug' '#SBATCH --mem=2G' '#SBATCH --time=10' \
            '#SBATCH --qos=low' "#SBATCH --chdir=$tmp" '#SBATCH --output=jobfarm/logs/limn-job-%A_%a.log' \
            "capture --job 'job.lua' --shard auto/3 --set 'ambient=0.05'" \
            "manifest merge --job 'job.lua' --shards 3 --set 'ambient=0.05'"; do
  check "farm script has $line" grep -qF -- "$line" jobfarm/limn-job.sbatch
done
check "farm makes the log folder" test -d jobfarm/logs
rm out/cornell/*-48x36.png
for i in 0 1 2; do SLURM_ARRAY_TASK_ID=$i bash jobfarm/limn-job.sbatch >>tasks.txt 2>&1; done
check "farm tasks render every image" count_is "$(ls out/*/*.png | wc -l)" 16
check "farm tasks render only the 4 missing" test "$(grep -o '[0-9]* rendered' tasks.txt | awk '{ s += $1 } END { print s }')" = 4
LIMN_FARM_STEP=merge SLURM_ARRAY_TASK_ID=0 bash jobfarm/limn-job.sbatch >out.txt 2>err.txt
check "farm merge task" out_has "job.lua: 16 views from 3 shards, each rendered once"
printf 'return { scenes = { "%s" }, techniques = { "nosuch" }, output = "o/{camera}.png" }\n' "$scenes/cornell.glb" > badtech.lua
check "farm checks the job first" run 2 farm slurm --job badtech.lua --shards 2 --dir badfarm
check "farm: the bad entry named" err_has "badtech.lua: techniques[1]: "
check "farm: no script for a bad job" test ! -e badfarm/limn-badtech.sbatch
check "farm: --shards required" run 2 farm slurm --job job.lua
check "farm: a bad name" run 2 farm slurm --job job.lua --shards 2 --name 'a b'
check "farm: a value on two lines" run 2 farm slurm --job job.lua --shards 2 --partition "$(printf 'a\nb')"
check "farm: only slurm" run 2 farm pbs --job job.lua --shards 2
# sbatch's --time, --mem and --cpus-per-task checked here, not by sbatch on the cluster at submit time
for t in 1h 1:2:3:4 2- -5; do
  check "farm: --time $t refused" run 2 farm slurm --job job.lua --shards 2 --dir badfarm --time "$t"
  check "farm: --time $t named" err_has "--time wants sbatch's MINUTES, MINUTES:SECONDS, HOURS:MINUTES:SECONDS or DAYS-HOURS[:MINUTES[:SECONDS]], not '$t'"
done
for m in lots 1.5G 8GiB; do
  check "farm: --mem $m refused" run 2 farm slurm --job job.lua --shards 2 --dir badfarm --mem "$m"
  check "farm: --mem $m named" err_has "--mem wants sbatch's megabytes, or a number with K, M, G or T (8G), not '$m'"
done
check "farm: --cpus-per-task 0 refused" run 2 farm slurm --job job.lua --shards 2 --dir badfarm --cpus-per-task 0
check "farm: nothing written for bad sbatch values" test ! -e badfarm/limn-job.sbatch
check "farm: sbatch's other time forms" run 0 farm slurm --job job.lua --shards 2 --dir timefarm --time 2-12:30 --mem 8000
check "farm: days-hours:minutes passed on" grep -qxF -- "#SBATCH --time=2-12:30" timefarm/limn-job.sbatch
check "bad shard" run 2 capture --job job.lua --shard 3/3
check "bad shard message" err_has "--shard wants I/N"
check "--force needs --job" run 2 capture --force
check "--job with --size" run 2 capture --job job.lua --size 8x8
check "--job with --size message" err_has "'--size' does not go with it"

# Killed midway, then rerun: finished images are kept, the rest completed.
# First at a known point (LIMN_JOB_KILL_AFTER: SIGKILL after N images) ...
rm -rf out
(LIMN_JOB_KILL_AFTER=5 "$limn" capture --job job.lua >/dev/null 2>&1) 2>/dev/null
check "killed by SIGKILL" test $? -eq 137
check "5 images before the kill" count_is "$(ls out/*/*.png | wc -l)" 5
check "rerun after the kill at 5" run 0 capture --job job.lua
check "rerun completes the other 11" out_has "11 rendered, 5 skipped"
check "manifest: 5 from run 1, 11 from run 2" test "$(run_entries out/manifest.json 1)" -eq 5 -a "$(run_entries out/manifest.json 2)" -eq 11
# ... then at whatever moment a timed kill lands (maybe mid-write).
rm -rf out
cat > slow.lua <<LUA
return {
  scenes = { "$scenes/outdoor.glb" },
  sizes = { "64x48", "72x54", "80x60", "88x66" },
  frames = 4,
  output = "out/{scene}/{camera}-{size}.png",
}
LUA
"$limn" capture --job slow.lua >slow.txt 2>&1 &
pid=$!
for _ in $(seq 1 300); do [ -n "$(ls out/outdoor/*.png 2>/dev/null)" ] && break; sleep 0.02; done
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
before=$(ls out/outdoor/*.png 2>/dev/null | wc -l)
echo "killed after $before of 16 images"
check "the kill came after an image" test "$before" -ge 1
check "images left by the kill are whole" whole_pngs out/outdoor/*.png
check "rerun after the kill" run 0 capture --job slow.lua
check "rerun renders only what was missing" out_has "$((16 - before)) rendered, $before skipped"
check "all images now" count_is "$(ls out/outdoor/*.png | wc -l)" 16
check "no temporary files left" count_is "$(ls out/outdoor | grep -c tmp)" 0
check "images are whole after the rerun" whole_pngs out/outdoor/*.png

# Bad input: the job file and the entry, or the camera list and its line; exit 2 (bad usage) as on
# the command line.
bad() { # bad NAME RC MESSAGE JOB_BODY
  printf '%s\n' "$4" > bad.lua
  check "$1" run "$2" capture --job bad.lua
  check "$1: message" err_has "$3"
}
bad "unknown scene file" 2 "bad.lua: scenes[2]: $tmp/nosuch.glb" \
  "return { scenes = { '$scenes/cornell.glb', '$tmp/nosuch.glb' }, output = 'o/{camera}.png' }"
bad "scene that is not glTF" 2 "bad.lua: scenes[1]: 'cornell' is not a .gltf or .glb file" \
  "return { scenes = { 'cornell' }, output = 'o/{camera}.png' }"
bad "unknown technique" 2 "bad.lua: techniques[2]: " \
  "return { scenes = { '$scenes/cornell.glb' }, techniques = { 'dl', 'nosuch' }, output = 'o/{camera}.png' }"
bad "unknown option" 2 "bad.lua: set.nosuch: " \
  "return { scenes = { '$scenes/cornell.glb' }, set = { nosuch = 1 }, output = 'o/{camera}.png' }"
bad "unknown field" 2 "bad.lua: unknown field 'outputs'" \
  "return { scenes = { '$scenes/cornell.glb' }, outputs = 'o/{camera}.png' }"
bad "misspelt scene field" 2 "bad.lua: scenes[1]: unknown field 'camera' (known: scene, cameras)" \
  "return { scenes = { { scene = '$scenes/cornell.glb', camera = 'x.cams' } }, output = 'o/{camera}.png' }"
bad "named entry in a list" 2 "bad.lua: sizes: unknown field 'big' (known: none: a list of 1)" \
  "return { scenes = { '$scenes/cornell.glb' }, sizes = { '8x8', big = '16x16' }, output = 'o/{camera}.png' }"
bad "size past the GL's largest texture" 2 "bad.lua: sizes[2]: 8x65536; this GL's textures are at most " \
  "return { scenes = { '$scenes/cornell.glb' }, sizes = { '8x8', '8x65536' }, output = 'o/{camera}-{size}.png' }"
bad "bad size" 2 "bad.lua: sizes[1]: want \"WxH\"" \
  "return { scenes = { '$scenes/cornell.glb' }, sizes = { '0x3' }, output = 'o/{camera}.png' }"
bad "unknown placeholder" 2 "bad.lua: output: unknown placeholder '{cam}'" \
  "return { scenes = { '$scenes/cornell.glb' }, output = 'o/{cam}.png' }"
bad "outputs that collide" 2 "bad.lua: output: views 0 and 1 both write o/x.png (add {camera} to the pattern)" \
  "return { scenes = { '$scenes/cornell.glb' }, output = 'o/x.png' }"
bad "a scene listed twice" 2 "bad.lua: output: views 3 and 7 both write o/cornell-boxes.png (add {view} to the pattern)" \
  "return { scenes = { '$scenes/cornell.glb', '$scenes/cornell.glb' }, output = 'o/{scene}-{camera}.png' }"
bad "no scenes" 2 "bad.lua: scenes: the job names no scene" "return { output = 'o/{camera}.png' }"
bad "syntax error" 2 "bad.lua:2:" "return {
  scenes = { 'a.glb' } output = 'x.png' }"
bad "not a table" 2 "bad.lua: the job file must return a table" "return 42"
bad "runs forever" 2 "the job file runs too long" "while true do end"
bad "no functions in a job" 2 "bad.lua:1:" "return { scenes = io.open('x') }"
# math's functions are there (the error is the next field's, after math.floor ran), math.random is not.
bad "math in a job" 2 "bad.lua: scenes[1]: 'cornell3' is not a .gltf or .glb file" \
  "return { scenes = { 'cornell' .. math.floor(math.pi) }, output = 'o/{camera}.png' }"
bad "no math.random in a job" 2 "bad.lua:1:" "return { scenes = { 'a' .. math.random() } }"
check "missing job file" run 2 capture --job nosuch.lua
check "missing job file message" err_has "nosuch.lua"

printf 'front 0 1 3.4  0 1 0  45\nside 0 1 x  0 1 0  45\n' > bad.cams
bad "camera list: a number that does not parse" 2 "bad.cams:2: view 'side': eye_z 'x' is not a number within +-1e9" \
  "return { scenes = { { scene = '$scenes/cornell.glb', cameras = '$tmp/bad.cams' } }, output = 'o/{camera}.png' }"
check "camera list message names the job entry" err_has "bad.lua: scenes[1]: "
printf 'front 1e30 1 3.4  0 1 0  45\n' > bad.cams
check "camera list: a number far out" run 2 capture --job bad.lua
check "a number far out: named as out of range, not as not finite" err_has "bad.cams:1: view 'front': eye_x '1e30' is not a number within +-1e9"
printf '# views\n\nfront 0 1 3.4  0 1 0\n' > bad.cams
check "camera list: too few fields" run 2 capture --job bad.lua
check "too few fields message" err_has "bad.cams:3: 7 fields"
printf 'front 0 1 3.4  0 1 3.4  45\n' > bad.cams
check "camera list: eye at the target" run 2 capture --job bad.lua
check "eye at the target message" err_has "bad.cams:1: view 'front': the eye is at the target"
printf 'front 0 1 3.4  0 1 0  200\n' > bad.cams
check "camera list: fov" run 2 capture --job bad.lua
check "fov message" err_has "bad.cams:1: view 'front': fov_y_degrees 200 is outside"
printf '# nothing\n' > bad.cams
check "camera list: empty" run 2 capture --job bad.lua
check "empty message" err_has "bad.cams: no views"
check "no image from a failed job" test ! -e o

# Sequences: time = { start, stop, fps } renders frames 0 .. floor((stop - start) fps) as
# consecutive views, {frame} in their names; resumable, sharded in contiguous runs.
mean_error() { "$limn" compare "$1" "$2" --json | grep -o '"mean_error": [-0-9.e+]*' | awk '{ print $2 }'; }
error_above() { # error_above A B X: mean error of A against B above X
  local m; m=$(mean_error "$1" "$2")
  awk -v m="$m" -v x="$3" 'BEGIN { exit !(m > x) }' || { echo "  $1 vs $2: mean error $m, not above $3"; return 1; }
}
error_below() {
  local m; m=$(mean_error "$1" "$2")
  awk -v m="$m" -v x="$3" 'BEGIN { exit !(m < x) }' || { echo "  $1 vs $2: mean error $m, not below $3"; return 1; }
}
frames_of() { ls "$@" 2>/dev/null | frames_of_list; }
frames_of_list() { grep -o '[0-9]\{4\}\.png' | tr '\n' ' '; }
printf 'front 0 1 3.4  0 1 0  45\n' > one.cams
cat > seq.lua <<LUA
return {
  scenes = { { scene = "$scenes/cornell.glb", cameras = "$tmp/one.cams" } },
  sizes = { "48x36" }, techniques = { "dl" },
  time = { 0, 1, 4 },
  output = "seq/{camera}-{frame}.png",
}
LUA
rm -rf seq
check "sequence job" run 0 capture --job seq.lua
check "a 5-frame sequence writes 5 numbered files" test "$(frames_of seq/front-*.png)" = "0000.png 0001.png 0002.png 0003.png 0004.png "
check "sequence manifest: frame and time" grep -qF '"file": "seq/front-0003.png", "view": 3, "run": 1, "scene": "'"$scenes"'/cornell.glb", "scene_hash": ' seq/manifest.json
check "sequence manifest: frame 3 at 0.75 s" grep -qF '"frame": 3, "time": 0.750000' seq/manifest.json
sed -e 's|time = .*|time = 1.5,|' -e 's|seq/{camera}-{frame}|still/{camera}-{time}|' seq.lua > still.lua
check "a still at a time" run 0 capture --job still.lua
check "one image, named by its time" test "$(ls still | grep png)" = "front-1.500.png"
check "its manifest entry: frame 0 at 1.5 s" grep -qF '"frame": 0, "time": 1.500000' still/manifest.json
rm -rf seq
(LIMN_JOB_KILL_AFTER=2 "$limn" capture --job seq.lua >/dev/null 2>&1) 2>/dev/null
check "sequence killed by SIGKILL" test $? -eq 137
check "2 frames before the kill" test "$(frames_of seq/front-*.png)" = "0000.png 0001.png "
check "the killed sequence's manifest: 2 images of its 5 views" \
  test "$(grep -c '"views": 5,' seq/manifest.json) $(entries seq/manifest.json)" = "1 2"
check "rerun the killed sequence" run 0 capture --job seq.lua
check "the rerun renders only the 3 missing frames" out_has "3 rendered, 2 skipped"
check "all 5 frames after the rerun" test "$(frames_of seq/front-*.png)" = "0000.png 0001.png 0002.png 0003.png 0004.png "
check "the rerun's manifest: 5 images of 5 views" test "$(grep -c '"views": 5,' seq/manifest.json) $(entries seq/manifest.json)" = "1 5"
rm -rf seq
# A frame that fails (frame 3's name is taken by a folder): the job stops there naming it, exit 1; the
# frames before it whole and in the manifest, which says they are 3 of the sequence's 5.
mkdir -p seq/front-0003.png
check "a failing frame" run 1 capture --job seq.lua
check "a failing frame named" err_has "seq.lua: view 3 (cornell, camera 'front', dl, 48x36, frame 3 at 0.750 s): "
check "the frames before it only" test "$(find seq -type f -name 'front-*' | sort | frames_of_list)" = "0000.png 0001.png 0002.png "
check "its manifest: 3 images of 5 views" test "$(grep -c '"views": 5,' seq/manifest.json) $(entries seq/manifest.json)" = "1 3"
rm -rf seq
# A script that fails on frame 5 (its sixth OnRender): the job stops there naming the view and script:line,
# exit 1; frames 0-4 whole and in the manifest, 5 of the sequence's 9.
late_script late.lua
sed -e 's|time = .*|time = { 0, 2, 4 }, script = "late.lua",|' -e 's|techniques = { "dl" }|techniques = { "gbuffer" }|' seq.lua > lateseq.lua
check "a script failing on frame 5" run 1 capture --job lateseq.lua
check "a script failing on frame 5: named" err_has "lateseq.lua: view 5 (cornell, camera 'front', gbuffer, 48x36, frame 5 at 1.250 s): ./late.lua:6: frame 5 fails"
check "the frames before it only" test "$(find seq -type f -name 'front-*' | sort | frames_of_list)" = "0000.png 0001.png 0002.png 0003.png 0004.png "
check "its manifest: 5 images of 9 views" test "$(grep -c '"views": 9,' seq/manifest.json) $(entries seq/manifest.json)" = "1 5"
rm -rf seq
check "sequence shard 0/2" run 0 capture --job seq.lua --shard 0/2
check "shard 0/2 renders frames 0-2 (a contiguous run)" test "$(frames_of seq/front-*.png)" = "0000.png 0001.png 0002.png "
check "sequence shard 1/2" run 0 capture --job seq.lua --shard 1/2
check "shard 1/2 renders the 2 others" out_has "2 rendered, 0 skipped"
check "shards 0/2 and 1/2 cover every frame once" test "$(frames_of seq/front-*.png)" = "0000.png 0001.png 0002.png 0003.png 0004.png "
check "sequence shards merge" run 0 manifest merge --job seq.lua --shards 2
check "sequence merge: each frame once" out_has "seq.lua: 5 views from 2 shards, each rendered once"
check "shard manifests count their own views, the merged one the job's" \
  test "$(grep -h '"views": ' seq/manifest.shard-0-of-2.json seq/manifest.shard-1-of-2.json seq/manifest.json | tr -d ' \n')" = '"views":3,"views":2,"views":5,'
rm -rf seq
check "farm a sequence" run 0 farm slurm --job seq.lua --shards 2 --dir seqfarm
: > seqtasks.txt
for i in 0 1; do SLURM_ARRAY_TASK_ID=$i bash seqfarm/limn-seq.sbatch >>seqtasks.txt 2>&1; done
check "farm tasks render every frame" test "$(frames_of seq/front-*.png)" = "0000.png 0001.png 0002.png 0003.png 0004.png "
check "farm tasks render each frame once (3 + 2)" test "$(grep -o '[0-9]* rendered' seqtasks.txt | tr '\n' ' ')" = "3 rendered 2 rendered "
# References of a sequence: one per frame (named and hashed with it), cached, sharded
# (a stand-in POV-Ray writes its output file; test_reference.sh runs the real one).
printf '#!/bin/sh\nfor a; do case "$a" in +O*) printf x > "${a#+O}";; esac; done\n' > fakepov
chmod +x fakepov
check "references of a sequence, shard 1/2" run 0 reference --job seq.lua --povray "$tmp/fakepov" --refs seqrefs --shard 1/2
check "shard 1/2 exports frames 3 and 4" test "$(ls seqrefs/cornell | grep -c '\.exr$')" = 2
check "their names carry frame and time" test -n "$(ls seqrefs/cornell/front_48x36-0003-0.750-*.exr)"
check "references of a sequence" run 0 reference --job seq.lua --povray "$tmp/fakepov" --refs seqrefs
check "one reference a frame, the shard's cached" out_has "3 rendered, 2 cached"

# A camera path: frames differ, the first is the still view at the first key.
cat > path.lua <<LUA
return {
  scenes = { "$scenes/cornell.glb" },
  sizes = { "48x36" }, techniques = { "dl" },
  time = { 0, 1, 3 },
  path = { { t = 0, eye = { 0, 1, 3.4 }, target = { 0, 1, 0 }, fov = 45 },
           { t = 0.4, eye = { 0.6, 1.3, 2.8 }, target = { 0, 0.9, 0 } },
           { t = 1, eye = { -0.6, 1.2, 2.6 }, target = { 0.1, 0.8, 0 }, fov = 50 } },
  output = "path/{camera}-{frame}.png",
}
LUA
check "camera path job" run 0 capture --job path.lua
check "a path writes its 4 frames" test "$(frames_of path/path-*.png)" = "0000.png 0001.png 0002.png 0003.png "
check "still of the first key" run 0 capture --job seq.lua --force
check "path frame 0 is the first key's view" error_below path/path-0000.png seq/front-0000.png 0.000001
check "path frames 0 and 1 differ" error_above path/path-0000.png path/path-0001.png 0.01
check "path frames 2 and 3 differ" error_above path/path-0002.png path/path-0003.png 0.01
# The keys of a camera list, evenly over the time: the last frame is the list's last view.
printf 'a 0 1 3.4  0 1 0  45\nb -0.6 1.2 2.6  0.1 0.8 0  50\n' > keys.cams
printf 'b -0.6 1.2 2.6  0.1 0.8 0  50\n' > last.cams
sed -e 's|path = {.*|path = "keys.cams",|' -e '/^           { t = /d' -e 's|path/{camera}|listpath/{camera}|' path.lua > listpath.lua
sed -e "s|$tmp/one.cams|$tmp/last.cams|" -e 's|time = .*||' -e 's|seq/{camera}-{frame}|last/{camera}|' seq.lua > last.lua
check "path from a camera list" run 0 capture --job listpath.lua
check "still of the list's last view" run 0 capture --job last.lua
check "its last frame is the list's last view" error_below listpath/path-0003.png last/b.png 0.002
check "its first frame is the list's first" error_below listpath/path-0000.png path/path-0000.png 0.002
# A turntable: one turn over the time, so frame 0 and the last (a full turn) agree.
cat > turn.lua <<LUA
return {
  scenes = { "$scenes/cornell.glb" },
  sizes = { "48x36" }, techniques = { "dl" },
  time = { 0, 1, 4 },
  turntable = { turns = 1, elevation = 20 },
  output = "turn/{scene}-{frame}.png",
}
LUA
check "turntable job" run 0 capture --job turn.lua
check "turntable frames 0 and 1 differ" error_above turn/cornell-0000.png turn/cornell-0001.png 0.01
check "turntable frames 1 and 2 differ" error_above turn/cornell-0001.png turn/cornell-0002.png 0.01
check "a full turn comes back to frame 0" error_below turn/cornell-0000.png turn/cornell-0004.png 0.002

# Bad sequences and paths: named by field (and key), exit 2, nothing written.
job_with() { # job_with FIELDS: a cornell job with those fields
  printf 'return { scenes = { "%s" }, sizes = { "8x8" }, output = "o/{camera}-{frame}.png", %s }\n' "$scenes/cornell.glb" "$1" > bad.lua
}
badseq() { # badseq NAME RC MESSAGE FIELDS
  job_with "$4"
  check "$1" run "$2" capture --job bad.lua
  check "$1: message" err_has "$3"
}
k0='{ t = 0, eye = { 0, 1, 3 }, target = { 0, 1, 0 } }'
bad "sequence without {frame}" 2 "bad.lua: output: a sequence of 5 frames needs {frame} in the pattern" \
  "return { scenes = { '$scenes/cornell.glb' }, time = { 0, 1, 4 }, output = 'o/{camera}.png' }"
badseq "negative fps" 2 "bad.lua: time.fps: -4 frames a second; want a number above 0" 'time = { 0, 1, -4 }'
badseq "stop before start" 2 "bad.lua: time.stop: 0 is before time.start 1" 'time = { start = 1, stop = 0, fps = 4 }'
badseq "time of no number" 2 "bad.lua: time.start: a number, not a string" 'time = { "0", 1, 4 }'
badseq "NaN time" 2 "nan is not a finite number" 'time = 0/0'
badseq "path without time" 2 "bad.lua: path: needs time = { start, stop, fps }" "path = { $k0 }"
badseq "path eye of 2 numbers" 2 "bad.lua: path[2].eye: needs 3 numbers" \
  "time = { 0, 1, 4 }, path = { $k0, { t = 1, eye = { 1, 2 }, target = { 0, 1, 0 } } }"
badseq "path times not increasing" 2 "bad.lua: path[2].t: 0 is not after path[1].t (0)" \
  "time = { 0, 1, 4 }, path = { $k0, $k0 }"
badseq "path key without t" 2 "bad.lua: path[1].t: missing" \
  "time = { 0, 1, 4 }, path = { { eye = { 0, 1, 3 }, target = { 0, 1, 0 } } }"
badseq "path key time far out" 2 "bad.lua: path[1].t: -1e+308 s is not within +-1e9" \
  "time = { 0, 1, 4 }, path = { { t = -1e308, eye = { 0, 1, 3 }, target = { 0, 1, 0 } }, { t = 1e308, eye = { 1, 1, 3 }, target = { 0, 1, 0 } } }"
badseq "path fov" 2 "bad.lua: path[1].fov: 200 degrees is outside (0.1, 179)" \
  "time = { 0, 1, 4 }, path = { { t = 0, eye = { 0, 1, 3 }, target = { 0, 1, 0 }, fov = 200 } }"
badseq "path eye at target" 2 "bad.lua: path[1]: the eye is at the target" \
  "time = { 0, 1, 4 }, path = { { t = 0, eye = { 0, 1, 0 }, target = { 0, 1, 0 } } }"
badseq "misspelt path key field" 2 "bad.lua: path[2]: unknown field 'fvo' (known: t, eye, target, fov)" \
  "time = { 0, 1, 4 }, path = { $k0, { t = 1, eye = { 1, 1, 3 }, target = { 0, 1, 0 }, fvo = 30 } }"
badseq "path eye far out" 2 "bad.lua: path[1].eye[2]: 1e+30 is not within +-1e9" \
  "time = { 0, 1, 4 }, path = { { t = 0, eye = { 0, 1e30, 3 }, target = { 0, 1, 0 } } }"
badseq "misspelt time field" 2 "bad.lua: time: unknown field 'fsp' (known: start, stop, fps, or 3 in a list)" \
  "time = { start = 0, stop = 1, fsp = 8 }"
badseq "time of four numbers" 2 "bad.lua: time: unknown field '4' (known: start, stop, fps, or 3 in a list)" \
  "time = { 0, 1, 4, 8 }"
badseq "misspelt path list field" 2 "bad.lua: path: unknown field 'time' (known: cameras, times)" \
  "time = { 0, 1, 4 }, path = { cameras = '$tmp/keys.cams', time = { 0, 1 } }"
badseq "misspelt turntable field" 2 "bad.lua: turntable: unknown field 'turn' (known: turns, elevation, distance)" \
  "time = { 0, 1, 4 }, turntable = { turn = 2 }"
badseq "path through its target" 2 "bad.lua: path: frame 2 at 0.500 s: the eye reaches the target between path[1] and path[2]" \
  "time = { 0, 1, 4 }, path = { $k0, { t = 1, eye = { 0, 1, -3 }, target = { 0, 1, 0 } } }"
badseq "path list times" 2 "bad.lua: path.times: a list of 2 times (one for each view of $tmp/keys.cams)" \
  "time = { 0, 1, 4 }, path = { cameras = '$tmp/keys.cams', times = { 0 } }"
badseq "path keys all after the time" 2 "bad.lua: path: its keys' times 24 .. 48 s are all outside the job's time 0 .. 1 s (the camera would hold path[1] throughout)" \
  "time = { 0, 1, 4 }, path = { { t = 24, eye = { 0, 1, 3 }, target = { 0, 1, 0 } }, { t = 48, eye = { 1, 1, 3 }, target = { 0, 1, 0 } } }"
badseq "path keys all before the time" 2 "bad.lua: path: its keys' times 0 .. 0.5 s are all outside the job's time 1 .. 2 s (the camera would hold path[2] throughout)" \
  "time = { 1, 2, 4 }, path = { $k0, { t = 0.5, eye = { 1, 1, 3 }, target = { 0, 1, 0 } } }"
badseq "path list missing" 2 "bad.lua: path: " "time = { 0, 1, 4 }, path = '$tmp/nosuch.cams'"
badseq "path and turntable" 2 "bad.lua: path and turntable: one camera motion at a time" \
  "time = { 0, 1, 4 }, path = { $k0 }, turntable = {}"
badseq "turntable elevation" 2 "bad.lua: turntable.elevation: 95 degrees; want one within (-89, 89)" \
  "time = { 0, 1, 4 }, turntable = { elevation = 95 }"
badseq "turntable distance" 2 "bad.lua: turntable.distance: -1; want \"auto\" or a distance in (0, 1e9)" \
  "time = { 0, 1, 4 }, turntable = { distance = -1 }"
badseq "too many views" 2 "bad.lua: 360004 views (scenes' cameras x sizes x techniques x frames); at most 200000" \
  "time = { 0, 3000, 30 }"
badseq "unknown animation" 2 "bad.lua: scenes[1]: animation: scene " "time = 0, animation = 'walk'"
bad "an animation index with a space" 2 "bad.lua: scenes[1]: animation: scene 'door.glb' has no animation ' 0' (it has 0 'open'; or 'all')" \
  "return { scenes = { '$scenes/door.glb' }, time = 0, animation = ' 0', output = 'o/{camera}.png' }"
check "no image from a bad sequence" test ! -e o

finish
