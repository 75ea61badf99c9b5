#!/usr/bin/env bash
# limn reference and limn report on one small view (data/scenes/pov_ball.gltf
# at 48x36, POV-Ray radiosity with a low count so a run takes a second):
# - references are cached by the export's hash: a second run renders
#   nothing; a changed scene renders a new reference;
# - a failing POV-Ray run names the view, shows POV-Ray's error lines, exits
#   1 and leaves no reference or temporary file;
# - the reference set (data/jobs/reference.lua) has at least four scenes and
#   twelve views, each exported to POV-Ray exactly;
# - a two-setting sweep writes the CSV, the JSON, the SVG (it parses as XML)
#   and the Markdown summary, with consistent numbers; it renders (once) the
#   direct-only reference of the view, whose error against the baseline is
#   the floor of the share of indirect error removed;
# - each setting starts from the job's options, inheriting none from the one before; a still place's
#   warm-up carries into its timed frames; a sweep that fails half-way leaves no report (the last run's
#   is removed with it: its images are being overwritten).
# - --require-refs and --cached-refs render nothing: the first names the command, the second
#   leaves out (and names) the views without cached references.
# Skipped (77) where povray is not installed (tools/dev.sh installs it).
# Its job file is written out whole, as the other job tests' are, so they read alike.
set -u
limn=$1
root=$2
. "$(dirname "$0")/shell_test.sh"
needs povray "tools/dev.sh installs it"
scratch ref
cd "$tmp" || exit 1
cp "$root/data/scenes/pov_ball.gltf" ball.gltf
printf '# name eye target fov\nfront 0 1.5 3  0 0.3 0  45\n' > ball.cams
cat > job.lua <<'JOB'
return {
  scenes = { { scene = "ball.gltf", cameras = "ball.cams" } },
  sizes = { "48x36" },
  set = { ambient = 0 },
  output = "out/{camera}_{technique}.png",
}
JOB
fast=(--count 10 --pretrace-start 0.2 --pretrace-end 0.1 --refs refs --jobs 2)

# 1. caching
"$limn" reference --job job.lua "${fast[@]}" >log1 2>&1 || { cat log1; fail "first reference run"; }
cat log1
grep -q "1 rendered, 0 cached" log1 || fail "the first run did not render the view"
first=$(ls refs/ball/front_48x36-*.exr) || fail "no reference file"
[ "$(echo "$first" | wc -l)" = 1 ] || fail "more than one reference: $first"
ls refs/ball | grep -q "tmp" && fail "a temporary file was left: $(ls refs/ball)"
"$limn" reference --job job.lua "${fast[@]}" >log2 2>&1 || { cat log2; fail "second reference run"; }
grep -q "0 rendered, 1 cached" log2 || { cat log2; fail "the second run rendered again"; }
# A changed scene (the sun's intensity) is a new export: rendered again.
sed -i 's/"intensity": 4291.327/"intensity": 3000/' ball.gltf
grep -q '"intensity": 3000' ball.gltf || fail "could not change the scene"
"$limn" reference --job job.lua "${fast[@]}" >log3 2>&1 || { cat log3; fail "third reference run"; }
grep -q "1 rendered, 0 cached" log3 || { cat log3; fail "a changed scene was not rendered again"; }
[ "$(ls refs/ball/front_48x36-*.exr | wc -l)" = 2 ] || fail "the changed scene did not get its own reference"
# The new reference is darker (less sun): its mean error against the old one is not 0.
second=$(ls refs/ball/front_48x36-*.exr | grep -v "$first")
"$limn" compare "$first" "$second" --json >m.json || fail "compare references"
mean=$(grep -o '"mean_error": [-0-9.e+]*' m.json | awk '{print $2}')
awk -v m="$mean" 'BEGIN { exit !(m > 0.005) }' || { cat m.json; fail "references equal (mean error $mean)"; }

# A sequence along a camera path: one reference a frame, each posed at its time (the two differ), cached.
cat > path.lua <<'JOB'
return {
  scenes = { "ball.gltf" }, sizes = { "48x36" }, time = { 0, 1, 1 },
  path = { { t = 0, eye = { 0, 1.5, 3 }, target = { 0, 0.3, 0 } }, { t = 1, eye = { 2, 1.2, 2 }, target = { 0, 0.3, 0 } } },
  output = "out/{camera}_{frame}.png",
}
JOB
"$limn" reference --job path.lua "${fast[@]}" --refs refs-seq >log6 2>&1 || { cat log6; fail "references of a sequence"; }
grep -q "2 rendered, 0 cached" log6 || { cat log6; fail "a 2-frame sequence did not render 2 references"; }
f0=$(ls refs-seq/ball/path_48x36-0000-0.000-*.exr) && f1=$(ls refs-seq/ball/path_48x36-0001-1.000-*.exr) \
  || fail "no reference named by frame: $(ls refs-seq/ball)"
"$limn" compare "$f0" "$f1" --json >m.json || fail "compare frame references"
mean=$(grep -o '"mean_error": [-0-9.e+]*' m.json | awk '{print $2}')
awk -v m="$mean" 'BEGIN { exit !(m > 0.005) }' || { cat m.json; fail "the frames' references are equal (mean error $mean)"; }
"$limn" reference --job path.lua "${fast[@]}" --refs refs-seq >log7 2>&1 || { cat log7; fail "references of a sequence again"; }
grep -q "0 rendered, 2 cached" log7 || { cat log7; fail "a sequence's references were not cached per frame"; }
# Report over it: flicker, and the lag after the job's event against the settled still frame.
sed 's/output = /events = { 1 }, output = /' path.lua >events.lua
"$limn" report --job events.lua "${fast[@]}" --refs refs-seq --out rep-seq --sweep dl >log8 2>&1 \
  || { cat log8; fail "report over a sequence"; }
grep -qE "^dl over ball/path/48x36 \(2 frames\): mean error [0-9.]+, flicker [0-9.]+, lag 1: 0$" log8 \
  || { cat log8; fail "no sequence line with a lag of 0 for dl"; }
grep -q '"settled_error": ' rep-seq/report.json || fail "report.json has no settled error"
[ -e rep-seq/images/ball_path_48x36_0_0001_settled.exr ] || { ls rep-seq/images; fail "no settled frame"; }
# A camera that stands still over a still scene: both frames alike, reference and Limn, flicker exactly 0.
sed -e 's/t = 1, eye = { 2, 1.2, 2 }/t = 1, eye = { 0, 1.5, 3 }/' path.lua >still.lua
"$limn" reference --job still.lua "${fast[@]}" --refs refs-still >/dev/null 2>&1 || fail "references of a still sequence"
"$limn" report --job still.lua "${fast[@]}" --refs refs-still --out rep-still --sweep dl >log8 2>&1 \
  || { cat log8; fail "report over a still sequence"; }
grep -qE "^dl over ball/path/48x36 \(2 frames\): mean error [0-9.]+, flicker 0.000000, lag -$" log8 \
  || { cat log8; fail "a still sequence flickers"; }
# An event past the frames, or not a frame number, is refused naming it.
sed 's/output = /events = { 2 }, output = /' path.lua >bad-events.lua
"$limn" report --job bad-events.lua "${fast[@]}" --refs refs-seq --out rep-bad --sweep dl >log8 2>&1
[ $? = 2 ] && grep -q "events\[1\]" log8 || { cat log8; fail "an event past the frames was not refused by name"; }
sed 's/output = /events = { 0.5 }, output = /' path.lua >bad-events.lua
"$limn" report --job bad-events.lua "${fast[@]}" --refs refs-seq --out rep-bad --sweep dl >log8 2>&1
[ $? != 0 ] && grep -q "events\[1\]: 0.5 is not a frame number" log8 || { cat log8; fail "a fractional event was not refused"; }

# 2. a failing POV-Ray run: named by view, its error lines shown, exit 1
cat > fakepov <<'FAKE'
#!/bin/sh
echo "Persistence of Vision(tm) Ray Tracer"
echo "File 'x.pov' line 3: Parse Error: Expected 'object', undeclared identifier 'oops' found instead"
echo "Fatal error in parser: Cannot parse input."
exit 1
FAKE
chmod +x fakepov
"$limn" reference --job job.lua "${fast[@]}" --refs refs-bad --povray "$tmp/fakepov" >log4 2>&1
rc=$?
cat log4
[ $rc = 1 ] || fail "a failing POV-Ray run exited $rc, not 1"
grep -q "view 0 (ball, camera 'front', 48x36): POV-Ray failed" log4 || fail "the failure does not name the view"
grep -q "Parse Error: Expected 'object'" log4 || fail "POV-Ray's error line is not shown"
ls refs-bad/ball/*.exr 2>/dev/null && fail "a failed run left an image"
# A program that is not there is a failure too.
"$limn" reference --job job.lua "${fast[@]}" --refs refs-bad --povray "$tmp/nothere" >log5 2>&1
[ $? = 1 ] || fail "a missing POV-Ray program did not fail"
grep -q "cannot run" log5 || { cat log5; fail "a missing program is not said"; }

# Lights POV-Ray cannot match (a glTF point light whose range ends inside the scene) are refused by
# name, before POV-Ray runs.
sed 's/"type": "directional",/"type": "point", "range": 0.5,/' ball.gltf > near.gltf
grep -q '"range": 0.5' near.gltf || fail "could not write near.gltf"
printf 'return { scenes = { { scene = "near.gltf", cameras = "ball.cams" } }, sizes = { "32x24" }, output = "o/{camera}.png" }\n' \
  > near.lua
"$limn" reference --job near.lua "${fast[@]}" --refs refs-near >log8 2>&1
[ $? = 1 ] || { cat log8; fail "an unmatchable light was not refused"; }
grep -q "view 0 (near, camera 'front', 32x24): .*light 'sun': range 0.5: the KHR_lights_punctual window" log8 \
  || { cat log8; fail "the refusal does not name the view and the light"; }
ls refs-near/near/*.exr 2>/dev/null && fail "a refused view was rendered"

# The reference set (data/jobs/reference.lua): at least four scenes and twelve views, every one exported
# strictly (a light or material POV-Ray cannot match would be refused); a stand-in POV-Ray writes the images.
cat > povstub <<'STUB'
#!/bin/sh
for a; do case $a in +O*) : > "${a#+O}" ;; esac; done
STUB
chmod +x povstub
"$limn" reference --job "$root/data/jobs/reference.lua" --refs refs-set --povray "$tmp/povstub" >log10 2>&1 \
  || { cat log10; fail "the reference set does not export"; }
grep -qi "warn" log10 && { cat log10; fail "the reference set's export warns"; }
views=$(sed -n 's/.*: \([0-9]*\) rendered, 0 cached.*/\1/p' log10)
scenes=$(ls refs-set | wc -l)
echo "reference set: $views views of $scenes scenes"
[ "${views:-0}" -ge 12 ] && [ "$scenes" -ge 4 ] || fail "the reference set has $views views of $scenes scenes"

# POV-Ray gets the cores this process may run on, not the machine's: under taskset -c 0, one thread.
cat > povargs <<'STUB'
#!/bin/sh
echo "$@" >> "$(dirname "$0")/povargs.log"
for a; do case $a in +O*) : > "${a#+O}" ;; esac; done
STUB
chmod +x povargs
if command -v taskset >/dev/null; then
  taskset -c 0 "$limn" reference --job job.lua --refs refs-one --jobs 1 --povray "$tmp/povargs" >log12 2>&1 \
    || { cat log12; fail "reference under taskset"; }
  grep -qw -- "+WT1" povargs.log || { cat povargs.log; fail "POV-Ray was not given the one core of the affinity mask"; }
fi

# 3. a two-setting sweep on the one view: the reference is cached
"$limn" report --job job.lua "${fast[@]}" --out rep --frames 2 --warmup 1 --sweep "isr:isr.samples=8,16" \
  >log6 2>&1 || { cat log6; fail "report"; }
cat log6
grep -q "0 rendered, 1 cached" log6 || fail "the report rendered a cached reference again"
# ... and rendered the direct-only one (no radiosity block) beside it
[ "$(ls refs/ball/front_48x36-*.exr | wc -l)" = 3 ] || fail "no direct-only reference beside the two"
[ "$(grep -L "radiosity {" refs/ball/*.pov | wc -l)" = 1 ] || fail "not one export without radiosity"
for f in report.csv report.json report.svg report.md; do [ -s rep/$f ] || fail "no rep/$f"; done
cat rep/report.csv rep/report.md
# CSV: a header and three rows: the baseline dl and the two settings
[ "$(wc -l < rep/report.csv)" = 4 ] || fail "the CSV has not 1 + 3 lines"
grep -q '^"dl","dl","ball/front/48x36"' rep/report.csv || fail "no baseline row"
grep -q '^"isr","isr samples=8",' rep/report.csv || fail "no samples=8 row"
grep -q '^"isr","isr samples=16",' rep/report.csv || fail "no samples=16 row"
grep -q "isr.transport=" rep/report.csv || fail "no per-pass times"
# every error finite and in range, every total time above 0
awk -F, 'NR > 1 { if (!($8 > 0 && $8 < 1 && $14 > 0)) bad = 1 } END { exit bad }' rep/report.csv \
  || fail "an error or time out of range"
grep -q '"clock": "' rep/report.json || fail "the JSON does not name the clock"
[ "$(grep -c '"technique": ' rep/report.json)" = 3 ] || fail "the JSON has not three rows"
if command -v python3 >/dev/null; then python3 -m json.tool rep/report.json >/dev/null || fail "JSON does not parse"; fi
# SVG: XML that parses, one point per setting, the Pareto front marked
if command -v xmllint >/dev/null; then
  xmllint --noout rep/report.svg || fail "the SVG is not XML"
elif command -v python3 >/dev/null; then
  python3 -c 'import sys, xml.dom.minidom; xml.dom.minidom.parse(sys.argv[1])' rep/report.svg || fail "the SVG is not XML"
else
  fail "neither xmllint (libxml2-utils, tools/dev.sh) nor python3 to parse the SVG"
fi
[ "$(grep -c '<circle class="point' rep/report.svg)" = 3 ] || fail "the SVG has not three points"
grep -q 'class="point pareto"' rep/report.svg || fail "no point on the Pareto front"
# Markdown: the gain of each setting is 100 (e_dl - e) / e_dl from the CSV's errors
grep -q "| dl (baseline) |" rep/report.md || fail "no baseline line in the summary"
e_dl=$(awk -F, 'NR == 2 { print $8 }' rep/report.csv)
e_8=$(awk -F, 'NR == 3 { print $8 }' rep/report.csv)
gain=$(awk -v b="$e_dl" -v e="$e_8" 'BEGIN { printf "%.2f", 100 * (b - e) / b }')
grep -q "| isr samples=8 | [0-9.]* | [0-9.]* | $gain | $gain | " rep/report.md \
  || fail "the summary's gain for samples=8 is not $gain"
# The direct-only floor: one value for the view on every row; the share of
# indirect error removed is 100 (e_dl - e) / (e_dl - floor), n/a for the baseline.
floor=$(awk -F, 'NR == 2 { print $16 }' rep/report.csv)
awk -F, -v f="$floor" 'NR > 1 && $16 != f { bad = 1 } END { exit bad }' rep/report.csv \
  || fail "the floor differs between rows of one view"
awk -v f="$floor" -v b="$e_dl" 'BEGIN { exit !(f > 0 && f < b) }' \
  || fail "the floor $floor is not between 0 and the baseline's error $e_dl"
awk -F, 'NR == 2 { exit $17 != "n/a" }' rep/report.csv || fail "the baseline has a share of indirect error removed"
share=$(awk -F, 'NR == 3 { print $17 }' rep/report.csv)
awk -v s="$share" -v b="$e_dl" -v e="$e_8" -v f="$floor" 'BEGIN { w = 100 * (b - e) / (b - f); exit !(s - w < 0.01 && w - s < 0.01) }' \
  || fail "indirect error removed $share is not 100 ($e_dl - $e_8) / ($e_dl - $floor)"
grep -q '"direct_floor": ' rep/report.json || fail "the JSON has no direct_floor"
grep -q '"indirect_removed": null' rep/report.json || fail "the JSON's baseline share is not null"
grep -q "^Direct-only floor, mean over the views: " rep/report.md || fail "the summary does not give the floor"
grep -q "| indirect error removed % |" rep/report.md || fail "the summary has no indirect share column"
# The SVG draws the floor and zooms its error axis to the data: the lowest tick is above 0.
[ "$(grep -c '<line class="floor"' rep/report.svg)" = 1 ] || fail "the SVG has no floor line"
low=$(grep -o 'text-anchor="end">[-0-9.e+]*<' rep/report.svg | head -1 | tr -dc '0-9.e+-')
awk -v l="$low" 'BEGIN { exit !(l > 0) }' || fail "the error axis starts at $low, not at the data"
# The images are there to look at.
[ "$(ls rep/images/*.exr | wc -l)" = 3 ] || fail "not three images"

# A sweep whose second setting fails as it renders (isr.sky_bounce with one bounce): exit 1 naming the
# setting and what it lacks; the report of the run before in the same --out is gone, since this run's
# images (setting 1's already rendered) no longer match it.
"$limn" report --job job.lua "${fast[@]}" --out rep --frames 1 --warmup 0 \
  --sweep "isr:isr.bounces=2,1;isr.sky_bounce=true" >log15 2>&1
[ $? = 1 ] || { cat log15; fail "a sweep whose setting fails did not exit 1"; }
grep -q "isr bounces=1 sky_bounce=true: .*isr.bounces above 1 (it is 1)" log15 \
  || { cat log15; fail "the failing setting and the option it lacks are not named"; }
for f in report.csv report.json report.svg report.md; do [ -e rep/$f ] && fail "a failed report left rep/$f"; done

# Every setting starts from the job's options: "isr" after "isr:isr.mode=seed" renders the default
# mode, not the seed's it would inherit.
"$limn" report --job job.lua "${fast[@]}" --out rep4 --frames 1 --warmup 0 \
  --sweep "isr:isr.mode=seed" --sweep isr >log11 2>&1 || { cat log11; fail "report seed then default"; }
sed -e 's/sizes = /techniques = { "isr" }, sizes = /' -e 's|out/{camera}_{technique}.png|isr/{camera}.exr|' job.lua >isr.lua
"$limn" capture --job isr.lua >/dev/null 2>&1 || fail "capture isr"
"$limn" compare rep4/images/ball_front_48x36_2.exr isr/front.exr --json >c2.json || fail "compare setting 2"
grep -q '"mean_error": 0[,}]' c2.json || { cat c2.json; fail "isr after isr.mode=seed is not isr's default"; }
"$limn" compare rep4/images/ball_front_48x36_1.exr isr/front.exr --json >c1.json || fail "compare setting 1"
grep -q '"mean_error": 0[,}]' c1.json && fail "isr.mode=seed rendered the default"

# A still place's warm-up carries into its timed frames: with a pattern that turns every frame, the report's
# image after 4 warm-up frames is a capture's fifth frame (and not its first, which it was when the report
# set the view again between them).
turn=(isr.temporal.enabled=true isr.temporal.turn=always)
"$limn" report --job job.lua "${fast[@]}" --out rep7 --frames 1 --warmup 4 --sweep "isr:${turn[0]};${turn[1]}" >log14 2>&1 \
  || { cat log14; fail "report with a warm-up"; }
for n in 5 1; do
  sed "s/sizes = /frames = $n, sizes = /" isr.lua >isr$n.lua
  "$limn" capture --job isr$n.lua --set "${turn[0]}" --set "${turn[1]}" --force >/dev/null 2>&1 || fail "capture of $n frames"
  "$limn" compare rep7/images/ball_front_48x36_1.exr isr/front.exr --json >c$n.json || fail "compare with $n frames"
done
grep -q '"mean_error": 0[,}]' c5.json || { cat c5.json; fail "the report's warm-up did not carry into its timed frame"; }
grep -q '"mean_error": 0[,}]' c1.json && fail "the warm-up changed nothing (the check above proves nothing)"

# A baseline the script lacks is named as --baseline (it was named as a --sweep), exit 2, before any reference.
"$limn" report --job job.lua "${fast[@]}" --out rep8 --baseline nope --sweep dl >log16 2>&1
[ $? = 2 ] || { cat log16; fail "an unknown baseline did not exit 2"; }
grep -q "limn: error: --baseline nope: unknown technique 'nope'" log16 || { cat log16; fail "the baseline is not named"; }

# 4. --require-refs names the command when a reference is missing
"$limn" report --job job.lua "${fast[@]}" --refs refs-none --require-refs --out rep2 --sweep dl >log7 2>&1
[ $? = 1 ] || { cat log7; fail "--require-refs without references did not fail"; }
grep -q "limn reference --job job.lua --refs refs-none" log7 || { cat log7; fail "the command is not named"; }
[ -e rep2/report.csv ] && fail "a failed report wrote its CSV"
# ... and names the direct-only one's command when only that is missing
mkdir -p refs-rad/ball && cp $(grep -l "radiosity {" refs/ball/*.pov | sed 's/pov$/exr/') refs-rad/ball/
"$limn" report --job job.lua "${fast[@]}" --refs refs-rad --require-refs --out rep3 --sweep dl >log9 2>&1
[ $? = 1 ] || { cat log9; fail "--require-refs without direct-only references did not fail"; }
grep -q "limn reference --job job.lua --refs refs-rad --radiosity off" log9 || { cat log9; fail "the direct-only command is not named"; }
# 5. --cached-refs renders nothing: a view whose references are not cached is left out and named,
# the others reported; with none cached it fails naming the command
printf '# name eye target fov\nfront 0 1.5 3  0 0.3 0  45\nside 3 1.5 0  0 0.3 0  45\n' > two.cams
sed 's/ball.cams/two.cams/' job.lua > two.lua
"$limn" report --job two.lua "${fast[@]}" --cached-refs --out rep5 --sweep dl --frames 1 --warmup 0 >log12 2>&1 \
  || { cat log12; fail "--cached-refs with one of two views cached"; }
grep -q "ball/side/48x36 left out: no cached reference" log12 || { cat log12; fail "the view left out is not named"; }
[ "$(wc -l < rep5/report.csv)" = 2 ] && grep -q '"ball/front/48x36"' rep5/report.csv || fail "not the cached view alone"
ls refs/ball | grep -q "^side" && fail "--cached-refs rendered a reference"
"$limn" report --job job.lua "${fast[@]}" --refs refs-rad --cached-refs --out rep6 --sweep dl >log13 2>&1
[ $? = 1 ] || { cat log13; fail "--cached-refs without a direct-only reference did not fail"; }
grep -q "no view has its references cached in refs-rad (make them with: limn reference --job job.lua --refs refs-rad" \
  log13 || { cat log13; fail "--cached-refs with none cached does not name the command"; }
echo "passed"
