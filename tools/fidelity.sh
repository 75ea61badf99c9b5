#!/usr/bin/env bash
# tools/fidelity.sh: how close each GI technique comes to POV-Ray and to Cycles
# on the reference set (data/jobs/reference.lua), and at what cost. A
# benchmark, not a test: it prints figures and the targets of the project's GI
# work with PASS or FAIL, and exits 0 when the run completes.
#   BUILD_DIR  the build (default build)
#   OUT        the report's folder (default out/fidelity)
#   FRAMES     timed frames per image, after one warm-up (default 3)
#   JOB        the job (default data/jobs/reference.lua)
#   REFS       the references' folder (default out/reference)
#   MOVING_SIZE  the size of the moving-camera times the time targets judge (default 256x192;
#              MOVING_ROUNDS rounds of tools/gi_time.sh, default 2)
# POV-Ray's references (radiosity and direct-only) are rendered once and cached
# under REFS; `limn report` writes report.md/.csv/.json/.svg to OUT. The Cycles
# column needs Cycles' references cached there (8 bounces, 0 bounces for the
# floor, a second seed for the noise: minutes a view on 2 cores, so never
# rendered here); without them one line names the command that renders them.
set -euo pipefail
cd "$(dirname "$0")/.."
LIMN=${BUILD_DIR:-build}/limn
[ -x "$LIMN" ] || { echo "fidelity: no $LIMN (build first: tools/dev.sh build)" >&2; exit 2; }
# shellcheck source=tools/techniques.sh
. tools/techniques.sh
# `6 rays temporal` (the best setting: docs/gi-combined.md): with isr.temporal a still report's history
# averages the RSM's turning pattern only; tools/moving_fidelity.py judges it on a moving camera's frame.
# `6 rays temporal grid`: the same with the solid grid (rsm.solid_cell, docs/gi-combined.md), a candidate.
limn_gi_report --targets --cycles --moving "${MOVING_SIZE:-256x192}" --refs "${REFS:-out/reference}" "${OUT:-out/fidelity}" \
  "${JOB:-data/jobs/reference.lua}" "${FRAMES:-3}" \
  "$LIMN_BASELINE=$LIMN_BASELINE" "seed ISR=$(limn_seed_isr_spec)" "ssdo+esm=ssdo+esm" "ssao+esm=ssao+esm" \
  "default=$(limn_default_spec)" "rsm+esm=rsm+esm" "vpl+esm=vpl+esm:vpl.lights=100;vpl.negative=50" \
  "vpl 300+0=vpl+esm:vpl.lights=300;vpl.negative=0" "combined=isr+rsm+esm" "lpv+esm=lpv+esm" \
  "isr+lpv=isr+lpv+esm" "lpv 2 bounces=lpv+esm:lpv.bounces=2" "isr+lpv 2 b.=isr+lpv+esm:lpv.bounces=2" \
  "combined 8 b.=isr+rsm+esm:isr.bounces=4;rsm.bounces=8" \
  "8 b. 8 rays=isr+rsm+esm:isr.bounces=4;rsm.bounces=8;isr.samples=8" \
  "8 b. 8 r. RSM rays=isr+rsm+esm:isr.bounces=4;rsm.bounces=8;isr.samples=8;rsm.ray_steps=2" \
  "default traced=isr+rsm+esm:rsm.trace=1" "8 b. 8 r. traced=isr+rsm+esm:isr.bounces=4;rsm.bounces=8;isr.samples=8;rsm.trace=1" \
  "5 b. traced reach 2=isr+rsm+esm:isr.bounces=4;rsm.bounces=5;isr.samples=8;rsm.trace=1;rsm.reach=2" \
  "5 b. traced 96 hits=isr+rsm+esm:isr.bounces=4;rsm.bounces=5;isr.samples=8;rsm.trace=1;rsm.reach=2;rsm.trace_samples=96" \
  "6 rays temporal=isr+rsm+esm:isr.bounces=4;rsm.bounces=5;isr.samples=6;rsm.trace=1;rsm.reach=2;rsm.trace_samples=64;isr.temporal.enabled=true" \
  "6 rays temporal grid=isr+rsm+esm:isr.bounces=4;rsm.bounces=5;isr.samples=6;rsm.trace=1;rsm.reach=2;rsm.trace_samples=64;isr.temporal.enabled=true;rsm.solid_cell=8"
