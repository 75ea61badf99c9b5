#!/usr/bin/env bash
# tools/gi_time.sh: frame time of GI techniques against dl+esm, as ratios
# measured in one run: each technique renders every scene of the reference
# set (data/jobs/reference.lua's scenes, camera 0) at SIZE, FRAMES timed
# frames after WARMUP untimed ones (capture's median "total"), interleaved
# scene by scene so that load on the machine falls on all alike; ROUNDS
# times over, and a technique's figure is the median of its rounds' means
# over the scenes (one process's frames on this 2-core machine run 10-30%
# slower or faster than the next one's, alike for every technique: one round
# moved dl+esm's mean from 4.5 to 6.7 ms). A benchmark, not a test: it
# prints figures and exits 0 when the run completes.
#   BUILD_DIR  the build (default build)   SIZE  (default 256x192)
#   ROUNDS     rounds over scenes and techniques (default 3)
#   FRAMES     timed frames (default 5)    TECHS (default below; "tech:opt=v,opt=v" sets options)
#   WARMUP     untimed frames first (default 1; with temporal reuse, more than rsm.temporal.frames
#              times the converged frame)
#   SCENES     the scenes, space-separated (default the reference set's and the Cornell box)
#   MOTION     1: the frame while the camera moves instead of a still one: `limn bench --motion`'s
#              moving frame (an orbit around the scene, 2 degrees a frame, every cache on and
#              histories carried; no settled skip, no shadow tile kept whole), the median of FRAMES
#              after WARMUP. A still capture keeps its shadow tiles and, with temporal reuse on,
#              skips the GI passes once settled: cheaper than any frame of a moving camera.
#   CLOCK      with MOTION=1, process: the moving frames' process CPU time (every thread's: on
#              llvmpipe the rendering's work, steadier than the wall clock on a loaded machine,
#              though not the frame's latency); default wall
set -euo pipefail
cd "$(dirname "$0")/.."
LIMN=${BUILD_DIR:-build}/limn
[ -x "$LIMN" ] || { echo "gi_time: no $LIMN (build first: tools/dev.sh build)" >&2; exit 2; }
SIZE=${SIZE:-256x192} FRAMES=${FRAMES:-5} WARMUP=${WARMUP:-1} ROUNDS=${ROUNDS:-3} CLOCK=${CLOCK:-wall}
case "$CLOCK" in wall | process) ;; *) echo "gi_time: CLOCK wants wall or process, not '$CLOCK'" >&2; exit 2 ;; esac
[ "$CLOCK" = wall ] || [ "${MOTION:-0}" = 1 ] || { echo "gi_time: CLOCK=process needs MOTION=1" >&2; exit 2; }
read -r -a techs <<< "${TECHS:-dl+esm rsm+esm vpl+esm isr+rsm+esm isr+esm lpv+esm isr+lpv+esm}"
read -r -a scenes <<< "${SCENES:-data/scenes/reference/room.glb data/scenes/reference/street.glb \
data/scenes/reference/blocks.glb data/scenes/cornell.glb}"
declare -A rounds # spec -> its rounds' means over the scenes, space-separated
for ((round = 0; round < ROUNDS; round++)); do
declare -A sum=()
for scene in "${scenes[@]}"; do
  for spec in "${techs[@]}"; do
    args=(--tech "${spec%%:*}")
    if [ "$spec" != "${spec%%:*}" ]; then
      IFS=, read -r -a sets <<< "${spec#*:}"
      for s in "${sets[@]}"; do args+=(--set "$s"); done
    fi
    if [ "${MOTION:-0}" = 1 ]; then
      ms=$("$LIMN" bench --motion --scene "$scene" "${args[@]}" --sizes "$SIZE" --warmup "$WARMUP" --frames "$FRAMES" \
             --set ambient=0 --json 2>/dev/null |
           python3 -c 'import json, statistics, sys
m = json.load(sys.stdin)["motion"]
print(m["moving"]["frame_ms"] if sys.argv[1] == "wall" else statistics.median(m["per_frame"]["moving_cpu_ms"]))' "$CLOCK")
    else
      ms=$("$LIMN" capture --scene "$scene" "${args[@]}" --size "$SIZE" --warmup "$WARMUP" --frames "$FRAMES" \
             --set ambient=0 --output /tmp/gi_time_$$.png 2>&1 | awk '$1 == "total" { print $2 }')
    fi
    sum[$spec]=$(awk -v a="${sum[$spec]:-0}" -v b="$ms" 'BEGIN { print a + b }')
  done
done
for spec in "${techs[@]}"; do
  rounds[$spec]+="$(awk -v s="${sum[$spec]}" -v n="${#scenes[@]}" 'BEGIN { print s / n }') "
done
done
rm -f /tmp/gi_time_$$.png
median() { tr ' ' '\n' | sed '/^$/d' | sort -g | awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
base=$(median <<< "${rounds[${techs[0]}]}")
echo "frame time$([ "${MOTION:-0}" = 1 ] && echo " with a moving camera (limn bench --motion's moving frame)"):" \
     "median of $FRAMES frames after $WARMUP untimed, median of $ROUNDS rounds;" \
     "clock: glFinish + $([ "$CLOCK" = wall ] && echo "CLOCK_MONOTONIC" || echo "the process's CPU time (CLOCK_PROCESS_CPUTIME_ID)") on llvmpipe"
printf "%-40s %10s %8s  %s\n" "technique ($SIZE, ${#scenes[@]} scenes)" "ms/frame" "time x" "rounds (ms)"
for spec in "${techs[@]}"; do
  awk -v m="$(median <<< "${rounds[$spec]}")" -v b="$base" -v t="$spec" -v r="${rounds[$spec]}" \
    'BEGIN { printf "%-40s %10.1f %8.2f  %s\n", t, m, m / b, r }'
done
