#!/usr/bin/env bash
# The limn command as a user meets it: help, bad flags (exit 2), broken
# scripts (exit 1 with script:line or the pass), and whole files or none.
# Each case is its script and its checks, written out: cases read alike.
set -u
limn=$1
root=$2
. "$(dirname "$0")/shell_test.sh"
scratch cli

run() { # run EXPECTED_RC ARGS... : output in $tmp/out, $tmp/err, rc in $rc
  local want=$1; shift
  "$limn" "$@" >"$tmp/out" 2>"$tmp/err"; rc=$?
  [ "$rc" -eq "$want" ] || { echo "  '$*' exited $rc, wanted $want"; sed 's/^/  | /' "$tmp/err" | head -5; return 1; }
}
err_has() { grep -qF -- "$1" "$tmp/err" || { echo "  stderr lacks '$1':"; sed 's/^/  | /' "$tmp/err" | head -5; return 1; }; }
out_has() { grep -qF -- "$1" "$tmp/out" || { echo "  stdout lacks '$1'"; return 1; }; }
first_error_has() { grep -m1 'error:' "$tmp/err" | grep -qF -- "$1" || { echo "  first error line lacks '$1':"; sed 's/^/  | /' "$tmp/err" | head -3; return 1; }; }
no_files() { [ -z "$(ls -A "$tmp/img")" ] || { echo "  left files: $(ls "$tmp/img")"; return 1; }; }
mkdir -p "$tmp/img"

# help and usage
check "no command" run 2
check "help" run 0 --help
check "help lists capture" out_has "capture"
check "capture help" run 0 capture --help
for flag in --scene --script --tech --set --size --frames --warmup --camera --output --clock --egl --list-options \
            --time --fps --animation; do
  check "capture help names $flag" out_has "$flag"
done
check "unknown command" run 2 frobnicate
check "unknown flag" run 2 capture --bogus
check "unknown flag message" err_has "unknown flag '--bogus'"
check "bad size" run 2 capture --size 0x5
check "bad size message" err_has "--size wants WxH"
check "a size past the GL's largest texture" run 2 capture --size 65536x8 --output "$tmp/img/big.png"
check "a size past the GL's largest texture: the flag named" first_error_has "--size 65536x8: this GL's textures are at most "
check "missing value" run 2 capture --size
# A glTF file that requires an extension the engine lacks: refused by name, before its data is read.
sed 's/"extensionsUsed": \[/"extensionsRequired": ["EXT_mesh_features"], "extensionsUsed": [/' \
  "$root/data/scenes/pov_ball.gltf" > "$tmp/features.gltf"
check "required extension" run 2 capture --scene "$tmp/features.gltf" --size 32x24 --output "$tmp/img/d.png"
check "required extension named" first_error_has "features.gltf: extensionsRequired names 'EXT_mesh_features'"
check "required extension: no image" no_files
# --camera auto frames the scene at the output's aspect; an orthographic glTF camera is refused by name.
check "camera auto" run 0 capture --scene "$root/data/scenes/pov_ball.gltf" --camera auto --size 24x48 --output "$tmp/auto.png"
check "camera auto wrote" test -s "$tmp/auto.png"
sed -e 's/"type": "perspective",/"type": "orthographic",/' -e 's/"perspective": {/"orthographic": { "xmag": 2, "ymag": 1.5,/' \
  "$root/data/scenes/pov_ball.gltf" > "$tmp/ortho.gltf"
check "orthographic camera" run 1 capture --scene "$tmp/ortho.gltf" --size 32x24 --output "$tmp/img/o.png"
check "orthographic camera named" first_error_has "camera 'view' (0) is orthographic"
check "orthographic: no image" no_files
check "orthographic export" run 1 export-pov --scene "$tmp/ortho.gltf" --size 32x24 --output "$tmp/img/o.pov"
check "orthographic export named" first_error_has "camera 'view' (0) is orthographic"
check "bad output type" run 2 capture --output "$tmp/img/x.bmp"
check "bad frames" run 2 capture --frames -3
check "bad set" run 2 capture --set novalue
check "unknown option" run 2 capture --set nope=1
check "unknown option lists known" err_has "known: ambient="
check "unknown technique" run 2 capture --tech nope
check "unknown technique lists known" err_has "known: isr+rsm+esm, isr+esm, isr, dl+esm, dl"
check "unknown scene" run 2 capture --scene nope
check "bad option value" run 2 capture --set ambient=bright
check "list options" run 0 capture --list-options
check "list options shows techniques" out_has "techniques: isr+rsm+esm isr+esm isr dl+esm dl"
rows=$(sed -n 's/^technique{ "\([^"]*\)".*/\1/p' "$root/scripts/pp.lua" | tr '\n' ' ')
check "list options lists pp.lua's rows, no more" grep -qxF "techniques: ${rows% }" "$tmp/out"

# a good capture: both files, per-pass times with the clock named
check "capture" run 0 capture --scene cornell --script scripts/pp.lua --tech dl --size 64x48 --frames 2 \
  --set ambient=0.05 --output "$tmp/img/a.png" --output "$tmp/img/a.exr"
check "png written" test -s "$tmp/img/a.png"
check "png is a png" bash -c "head -c 4 '$tmp/img/a.png' | od -c | grep -q 'P   N   G'"
check "exr written" test -s "$tmp/img/a.exr"
check "exr is an exr" bash -c "head -c 4 '$tmp/img/a.exr' | od -An -tx1 | grep -q '76 2f 31 01'"
check "times name the clock" out_has "clock: "
check "times list the gbuffer pass" out_has "gbuffer"
check "times list the direct pass" out_has "direct"
check "times are medians of 2" out_has "median of 2 frames"
check "the process clock" run 0 capture --scene cornell --tech dl --size 64x48 --frames 2 --clock process
check "the process clock is named" out_has "clock: process (glFinish + CLOCK_PROCESS_CPUTIME_ID"
check "the process clock counts the direct pass's work" \
  awk '$1 == "direct" { found = 1; if ($3 + 0 <= 0) exit 1 } END { exit !found }' "$tmp/out"
check "a bad clock" run 2 capture --clock sundial
check "a bad clock names the choices" err_has "auto, gpu, cpu or process, not 'sundial'"
rm -f "$tmp/img/"*

# time: a still at --time SECONDS, a sequence at --time START:STOP --fps N, one file a frame
check "sequence capture" run 0 capture --size 32x24 --tech dl --time 0:1 --fps 4 --output "$tmp/img/s{frame}_{time}.png"
check "a 5-frame sequence writes 5 numbered files" \
  test "$(ls "$tmp/img" | tr '\n' ' ')" = "s0000_0.000.png s0001_0.250.png s0002_0.500.png s0003_0.750.png s0004_1.000.png "
check "the sequence is said" out_has "5 frames, 0.000 s to 1.000 s at 4 fps"
check "frames of a still scene are equal" cmp "$tmp/img/s0000_0.000.png" "$tmp/img/s0004_1.000.png"
rm -f "$tmp/img/"*
check "a stop on no frame" run 0 capture --size 16x12 --tech dl --time 0.5:0.9 --fps 4 --output "$tmp/img/s{frame}.png"
check "frames up to the stop only" test "$(ls "$tmp/img" | tr '\n' ' ')" = "s0000.png s0001.png "
rm -f "$tmp/img/"*
check "still at a time" run 0 capture --size 16x12 --tech dl --time 1.5 --animation all --output "$tmp/img/t{time}.png"
check "still at a time named" test -s "$tmp/img/t1.500.png"
rm -f "$tmp/img/"*
check "sequence without {frame}" run 2 capture --time 0:1 --fps 4 --output "$tmp/img/s.png"
check "sequence without {frame} names the flag" err_has "--output '$tmp/img/s.png': a sequence of 5 frames (--time 0:1 --fps 4) needs {frame} in the name"
check "a misspelt placeholder" run 2 capture --time 0:1 --fps 4 --output "$tmp/img/s{frame}_{tiem}.png"
check "a misspelt placeholder named" err_has "--output '$tmp/img/s{frame}_{tiem}.png': unknown placeholder '{tiem}' (capture fills {frame} and {time})"
check "an output given twice" run 2 capture --output "$tmp/img/s.png" --output "$tmp/img/s.png"
check "an output given twice named" err_has "--output '$tmp/img/s.png' is given twice"
check "an output into no folder" run 2 capture --time 0:100 --fps 4 --output "$tmp/nosuch/s{frame}.png"
check "an output into no folder named, before a frame" err_has "--output '$tmp/nosuch/s{frame}.png': no folder '$tmp/nosuch' (capture makes none)"
check "nothing of a refused command line" no_files
check "sequence without --fps" run 2 capture --time 0:1 --output "$tmp/img/s{frame}.png"
check "sequence without --fps message" err_has "--time 0:1: a sequence needs --fps N"
check "negative fps" run 2 capture --time 0:1 --fps -4 --output "$tmp/img/s{frame}.png"
check "negative fps message" err_has "--fps wants frames a second in (0, 1e6], not '-4'"
check "stop before start" run 2 capture --time 2:1 --fps 4 --output "$tmp/img/s{frame}.png"
check "stop before start message" err_has "--time START:STOP wants STOP >= START, not '2:1'"
check "NaN time" run 2 capture --time nan --output "$tmp/img/s.png"
check "NaN time message" err_has "--time wants SECONDS or START:STOP (finite numbers), not 'nan'"
check "fps without a range" run 2 capture --time 1 --fps 4 --output "$tmp/img/s.png"
check "fps without a range message" err_has "--fps goes with --time START:STOP"
check "unknown animation" run 2 capture --size 16x12 --animation walk --output "$tmp/img/s.png"
check "unknown animation message" first_error_has "--animation walk: scene 'cornell' has no animation 'walk'"
# An index is digits alone: " 0" was taken as animation 0.
check "an index with a space" run 2 capture --scene "$root/data/scenes/door.glb" --size 16x12 --animation " 0" --output "$tmp/img/s.png"
check "an index with a space: what was given and what exists" first_error_has "scene 'door.glb' has no animation ' 0' (it has 0 'open'; or 'all')"
check "bad time values leave no file" no_files
# A sequence whose frame 2 fails (its EXR cannot take its name): frames 0 and 1 whole, and nothing of frame 2,
# not its PNG written before the EXR failed; the failed frame named.
mkdir "$tmp/img/f0002.exr"
check "a failing frame" run 1 capture --size 16x12 --tech dl --time 0:1 --fps 4 --quiet \
  --output "$tmp/img/f{frame}.png" --output "$tmp/img/f{frame}.exr"
check "a failing frame named" first_error_has "frame 2 at 0.500 s: $tmp/img/f0002.exr"
check "the frames before it, whole, and nothing of it" \
  test "$(ls "$tmp/img" | tr '\n' ' ')" = "f0000.exr f0000.png f0001.exr f0001.png f0002.exr "
rm -rf "$tmp/img/"*
# video: raw RGB frames piped to the ffmpeg program (a stand-in here that keeps its arguments and
# input; the real program is not needed to check what limn hands it)
mkdir -p "$tmp/bin"
cat > "$tmp/bin/ffmpeg" <<'SH'
#!/bin/sh
for a; do out=$a; done
echo "$@" > "$(dirname "$out")/../ffmpeg-args"
cat > "$out"
[ -z "${FAKE_FFMPEG_FAIL:-}" ] || { echo "ffmpeg: no encoder" >&2; exit 1; }
SH
chmod +x "$tmp/bin/ffmpeg"
check "video of a sequence" env PATH="$tmp/bin:$PATH" "$limn" capture --size 32x24 --tech dl --time 0:1 --fps 4 --quiet \
  --output "$tmp/img/v.mp4"
check "video: 5 frames of 32x24 RGB handed over" test "$(stat -c %s "$tmp/img/v.mp4")" = $((5 * 32 * 24 * 3))
check "video: raw RGB at the sequence's size and rate" grep -qF -- "-f rawvideo -pix_fmt rgb24 -s 32x24 -r 4 -i -" "$tmp/ffmpeg-args"
check "video: ffmpeg writes a temporary name" grep -q "/v.tmp-[0-9]*.mp4\$" "$tmp/ffmpeg-args"
rm -f "$tmp/img/"*
check "video: ffmpeg fails" bash -c "FAKE_FFMPEG_FAIL=1 PATH='$tmp/bin:$PATH' '$limn' capture --size 32x24 --tech dl \
  --time 0:1 --fps 4 --output '$tmp/img/v.webm' 2>'$tmp/err'; [ \$? = 1 ]"
check "video: ffmpeg's failure named" err_has "--output $tmp/img/v.webm: ffmpeg failed (exit status 1"
check "video: no file from a failed ffmpeg" no_files
check "video without ffmpeg" bash -c "PATH=/nonexistent '$limn' capture --size 32x24 --tech dl --time 0:1 --fps 4 \
  --output '$tmp/img/v.mp4' 2>'$tmp/err'; [ \$? = 1 ]"
check "video without ffmpeg: a clear error" err_has "--output $tmp/img/v.mp4: video needs the ffmpeg program (Debian package ffmpeg): not found on the PATH"
check "video without ffmpeg: no file" no_files
check "video of a still" run 2 capture --time 1 --output "$tmp/img/v.mp4"
check "video of a still message" err_has "a video is of a sequence"
# SIGTERM part-way through a sequence (a stop, a job scheduler's time limit): the frame in hand is finished,
# then the run dies of the signal, leaving whole frames and no video, not even its temporary file.
PATH="$tmp/bin:$PATH" "$limn" capture --size 32x24 --tech dl --time 0:100 --fps 4 --quiet \
  --output "$tmp/img/f{frame}.png" --output "$tmp/img/v.mp4" 2>"$tmp/err" & pid=$!
wait_until 60 test -e "$tmp/img/f0001.png"
kill -TERM "$pid"
wait "$pid"; rc=$?
check "stopped: dies of SIGTERM" test "$rc" = 143
check "stopped: said so" err_has "stopped by signal 15 after"
check "stopped: no video and no temporary file" test -z "$(ls "$tmp/img" | grep -v '^f[0-9]*\.png$')"
whole_pngs() { local f; for f in "$@"; do tail -c 12 "$f" | grep -q IEND || { echo "  $f is cut short"; return 1; }; done; }
check "stopped: the frames written whole" whole_pngs "$tmp/img/"f*.png
rm -f "$tmp/img/"*

# effects: `--set bloom=true` turns on bloom.enabled; dotted names set parameters
check "effects capture" run 0 capture --scene cornell --script scripts/pp.lua --tech dl --size 64x48 \
  --set bloom=true --set hdr=true --set dof=on --set dof.focus=3.5 --set dof.mode=lens --output "$tmp/img/e.png"
check "effects run their passes" out_has "hdr.tonemap"
check "effects list dof" out_has "dof.gather"
rm -f "$tmp/img/"*
check "bad effect value" run 1 capture --size 64x48 --set dof.mode=pinhole --output "$tmp/img/f.png"
check "bad effect value names it" first_error_has "dof.mode must be one of range, lens (got pinhole)"
check "bad effect value leaves no file" no_files
rm -f "$tmp/img/"*

# broken scripts: exit 1, a first line naming script:line or the pass, no image
cat >"$tmp/syntax.lua" <<'LUA'
Techniques = { "dl" }
function OnRender(tech)
  local x = = 2
end
LUA
check "syntax error" run 1 capture --script "$tmp/syntax.lua" --output "$tmp/img/s.png"
check "syntax error names line" first_error_has "syntax.lua:3:"
check "syntax error leaves no file" no_files

cat >"$tmp/runtime.lua" <<'LUA'
Techniques = { "dl" }
function OnRender(tech)
  local t = nil
  present(t.lit)
end
LUA
check "runtime error" run 1 capture --script "$tmp/runtime.lua" --output "$tmp/img/r.png"
check "runtime error names line" first_error_has "runtime.lua:4: attempt to index a nil value"
check "runtime error has a traceback" err_has "stack traceback"
check "runtime error leaves no file" no_files

# A script that fails on frame 5 of a sequence: exit 1 naming script:line and the frame; frames 0-4 whole,
# nothing of frame 5.
late_script "$tmp/late.lua"
check "a script failing on frame 5" run 1 capture --script "$tmp/late.lua" --size 16x12 --time 0:2 --fps 4 --quiet \
  --output "$tmp/img/l{frame}.png" --output "$tmp/img/l{frame}.exr"
check "frame 5's error names the frame and script:line" first_error_has "frame 5 at 1.250 s: $tmp/late.lua:6: frame 5 fails"
check "frames 0-4, nothing of frame 5" test "$(ls "$tmp/img" | tr '\n' ' ')" = \
  "l0000.exr l0000.png l0001.exr l0001.png l0002.exr l0002.png l0003.exr l0003.png l0004.exr l0004.png "
rm -f "$tmp/img/"*

cat >"$tmp/shader.lua" <<'LUA'
Techniques = { "dl" }
function OnRender(tech)
  local t = target{ "t", format = "rgba8" }
  present(pass{ "glow", shader = "no_such_shader.frag", out = t })
end
LUA
check "unknown shader" run 1 capture --script "$tmp/shader.lua" --output "$tmp/img/u.png"
check "unknown shader names the pass" first_error_has "shader.lua:4: pass 'glow'"
check "unknown shader names the file" first_error_has "no_such_shader.frag"
check "unknown shader leaves no file" no_files

cat >"$tmp/nowriter.lua" <<'LUA'
Techniques = { "dl" }
function OnRender(tech)
  local G = require("gbuffer").targets()
  local lit = target{ "lit", format = "rgba16f" }
  pass{ "direct", shader = "direct.frag", inputs = require("gbuffer").inputs(G), out = lit }
  present(lit)
end
LUA
check "read without writer" run 1 capture --script "$tmp/nowriter.lua" --output "$tmp/img/n.png"
check "read without writer names pass and line" first_error_has "nowriter.lua:5: pass 'direct' reads target 'gbuffer.clr' that no pass writes before it"
check "read without writer leaves no file" no_files

finish
