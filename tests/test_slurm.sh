#!/usr/bin/env bash
# limn farm slurm on a real one-node Slurm cluster started here: munged,
# slurmctld and slurmd from Debian's packages, with a config written into a
# scratch folder (own ports, own munge socket and key; no systemd).
# 1. A 3-shard array of a small job with its POV-Ray references, then the
#    merge task: every image and every reference rendered exactly once.
# 2. Afresh, one task cancelled (scancel) while it renders its references:
#    the merge fails naming what is missing; the array run again renders only
#    that (each image still from its first run).
# 3. A 6-frame turntable sequence with its references: each task renders two
#    consecutive frames and their references; the merge finds each once.
# Every daemon started here is stopped by its process id, also on failure.
# Skipped (77) without Slurm, munge or POV-Ray (tools/dev.sh installs them),
# or when not root (slurmd runs the tasks as their user).
set -u
limn=$1
root=$2
for p in munged slurmctld slurmd sbatch squeue sinfo scancel scontrol povray; do
  command -v "$p" >/dev/null || { echo "$p not installed: skipped (tools/dev.sh installs munge, slurmctld, slurmd, slurm-client, povray)"; exit 77; }
done
[ "$(id -u)" = 0 ] || { echo "not root: skipped (the one-node cluster runs slurmd as root)"; exit 77; }

. "$(dirname "$0")/shell_test.sh" # wait_until; fail is this test's own (below: it shows the daemons' logs)
tmp=$(mktemp -d /tmp/limn-slurm-XXXXXX) # POV-Ray writes only under /tmp and the current folder
pids=()
queue_empty() { [ -z "$(squeue -h 2>/dev/null)" ]; }
gone() { ! kill -0 "$1" 2>/dev/null; }
stop() {
  rm -f "$tmp/hold"
  if [ -n "${SLURM_CONF:-}" ] && [ ${#pids[@]} -eq 3 ]; then
    scancel --quiet --partition=limn 2>/dev/null
    wait_until 5 queue_empty
  fi
  local p
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  for p in "${pids[@]}"; do
    wait_until 5 gone "$p"
    kill -9 "$p" 2>/dev/null
    wait "$p" 2>/dev/null
  done
  rm -rf "$tmp"
}
trap stop EXIT
trap "exit 1" INT TERM HUP # the EXIT trap runs then too
fail() {
  echo "FAIL: $*"
  for f in "$tmp"/log/slurm*.log "$tmp"/work/farm/logs/*.log; do [ -e "$f" ] && { echo "--- $f"; tail -15 "$f"; }; done
  exit 1
}

# ---- the cluster ----------------------------------------------------------
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log" "$tmp/work"
chmod 700 "$tmp/munge"
head -c 1024 /dev/urandom > "$tmp/munge/key" && chmod 400 "$tmp/munge/key"
munged --foreground --force --socket="$tmp/munge/socket" --key-file="$tmp/munge/key" \
  --log-file="$tmp/log/munged.log" --pid-file="$tmp/munge/pid" --seed-file="$tmp/munge/seed" >/dev/null 2>&1 &
pids+=($!)
free_port() { # a port nothing listens on
  local p
  while :; do
    p=$((20000 + RANDOM % 30000))
    (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null || { echo "$p"; return; }
  done
}
host=$(hostname -s)
ctld_port=$(free_port)
slurmd_port=$(free_port)
[ "$ctld_port" != "$slurmd_port" ] || slurmd_port=$((ctld_port + 1))
export SLURM_CONF=$tmp/slurm.conf
cat > "$SLURM_CONF" <<CONF
ClusterName=limntest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/socket
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=3 RealMemory=1000 State=UNKNOWN
PartitionName=limn Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
wait_until 30 test -S "$tmp/munge/socket" || fail "munged did not start in 30 s"
slurmctld -D -f "$SLURM_CONF" > "$tmp/log/slurmctld.out.log" 2>&1 &
pids+=($!)
slurmd -D -N "$host" -f "$SLURM_CONF" > "$tmp/log/slurmd.out.log" 2>&1 &
pids+=($!)
node_idle() { sinfo -h -o %T 2>/dev/null | grep -q idle; }
wait_until 60 node_idle || fail "the node did not come up in 60 s: $(sinfo 2>&1)"
echo "cluster up: slurmctld on port $ctld_port, slurmd on $slurmd_port"

wait_jobs() { # until the queue is empty (at most 90 s)
  wait_until 90 queue_empty && return 0
  squeue
  fail "jobs still queued after 90 s"
}
job_state() { scontrol show job "$1" | grep -o 'JobState=[A-Z_]*' | head -1; }
rendered() { # sum of "N rendered" over the lines of the logs matching $1
  cat "${@:2}" | grep "$1" | grep -o '[0-9]* rendered' | awk '{ s += $1 } END { print s + 0 }'
}

# ---- the job: 5 cameras x 2 techniques = 10 views, 5 references ----------
cd "$tmp/work" || exit 1
cp "$root/data/scenes/pov_ball.gltf" ball.gltf
cat > ball.cams <<'CAMS'
front  0 1.5 3    0 0.3 0  45
left  -3 1.5 0    0 0.3 0  45
high   0 3 2      0 0 0    50
back   0 1.5 -3   0 0.3 0  45
side   3 1 1      0 0.3 0  45
CAMS
cat > job.lua <<'JOB'
return {
  scenes = { { scene = "ball.gltf", cameras = "ball.cams" } },
  techniques = { "dl", "isr" },
  sizes = { "32x24" },
  set = { ambient = 0 },
  output = "out/{camera}_{technique}.png",
}
JOB
# A POV-Ray that holds the 'side' view while the file hold exists (step 2).
cat > povray-hold <<HOLD
#!/bin/sh
case "\$*" in *+Iside_*) if [ -e "$tmp/hold" ]; then touch "$tmp/held"; while [ -e "$tmp/hold" ]; do sleep 0.1; done; fi ;; esac
exec povray "\$@"
HOLD
chmod +x povray-hold
"$limn" farm slurm --job job.lua --shards 3 --references --refs refs --povray "$tmp/work/povray-hold" \
  --count 10 --pretrace-start 0.2 --pretrace-end 0.1 --time 5 --submit > submit1.txt 2>&1 \
  || { cat submit1.txt; fail "limn farm slurm --submit"; }
cat submit1.txt
script=farm/limn-job.sbatch
grep -q '^#SBATCH --array=0-2$' $script || fail "the script is not a 3-task array"
grep -q '^#SBATCH --time=5$' $script || fail "--time is not passed to sbatch"
# shards: views 0,3,6,9 / 1,4,7 / 2,5,8; references: places 0,3 / 1,4 / 2

# ---- 1. the whole array and its merge ---------------------------------------
read -r array1 merge1 < <(sed -n 's/.*as job \([0-9]*\), the merge as job \([0-9]*\).*/\1 \2/p' submit1.txt)
[ -n "${merge1:-}" ] || fail "no job ids in: $(cat submit1.txt)"
wait_jobs
[ "$(job_state "$merge1")" = JobState=COMPLETED ] || fail "the merge: $(job_state "$merge1")"
for i in 0 1 2; do [ "$(job_state "${array1}_$i")" = JobState=COMPLETED ] || fail "task $i: $(job_state "${array1}_$i")"; done
logs1=(farm/logs/limn-job-"$array1"_*.log)
[ ${#logs1[@]} = 3 ] || fail "not three task logs: ${logs1[*]}"
grep -q "shard 1/3 from SLURM_ARRAY_TASK_ID=1, count 3 given" farm/logs/limn-job-"$array1"_1.log \
  || fail "task 1 does not say where its shard came from"
[ "$(rendered '^job job.lua: ' "${logs1[@]}")" = 10 ] || fail "the tasks rendered $(rendered '^job job.lua: ' "${logs1[@]}") images, not 10"
[ "$(rendered '^references of job.lua: ' "${logs1[@]}")" = 5 ] || fail "the tasks rendered $(rendered '^references of' "${logs1[@]}") references, not 5"
[ "$(ls out/*.png | wc -l)" = 10 ] || fail "not 10 images: $(ls out)"
[ "$(ls refs/ball/*.exr | wc -l)" = 5 ] || fail "not 5 references: $(ls refs/ball)"
grep -q "job.lua: 10 views from 3 shards, each rendered once; 5 references there; out/manifest.json" \
  farm/logs/limn-job-merge-"$merge1".log || fail "the merge log: $(cat farm/logs/limn-job-merge-"$merge1".log)"
# The merged manifest: each view once, in order, from the shards' single run.
[ "$(grep -c '{"file": ' out/manifest.json)" = 10 ] || fail "the merged manifest has not 10 images"
for v in 0 1 2 3 4 5 6 7 8 9; do
  [ "$(grep -c "\"view\": $v, \"run\": 1," out/manifest.json)" = 1 ] || fail "view $v is not in the manifest once"
done
grep -q '"shards": 3,' out/manifest.json || fail "the merged manifest does not say its shards"
echo "step 1: 10 images and 5 references, each rendered once; merged"

# ---- 2. a task cancelled mid-run, the array run again ----------------------
rm -rf out refs # a fresh start: every task has work
touch "$tmp/hold"
bash $script > submit2.txt 2>&1 || { cat submit2.txt; fail "submitting again"; }
read -r array2 merge2 < <(sed -n 's/.*as job \([0-9]*\), the merge as job \([0-9]*\).*/\1 \2/p' submit2.txt)
# Task 1 renders references 1 (left) and 4 (side; held), then its images.
wait_until 60 test -e "$tmp/held" || fail "task 1 never reached its 'side' reference"
left_done() { ls refs/ball 2>/dev/null | grep -qE '^left_32x24-[0-9a-f]{16}\.exr$'; } # not its temporary file
wait_until 60 left_done || fail "task 1 did not render its 'left' reference"
echo "step 2: cancelling task 1 while it renders its 'side' reference"
scancel "${array2}_1" || fail "scancel"
rm -f "$tmp/hold"
wait_jobs
[ "$(job_state "${array2}_1")" = JobState=CANCELLED ] || fail "task 1: $(job_state "${array2}_1")"
[ "$(job_state "$merge2")" = JobState=FAILED ] || fail "the merge after a cancelled task: $(job_state "$merge2")"
mlog=farm/logs/limn-job-merge-"$merge2".log
cat "$mlog"
grep -q "view 1 (ball, camera 'left', dl, 32x24) out/left_dl.png: missing (shard 1/3)" "$mlog" \
  || fail "the merge does not name a missing image with its shard"
grep -q "reference of view 4 (ball, camera 'side', 32x24) refs/ball/side_32x24-.*: missing (shard 1/3)" "$mlog" \
  || fail "the merge does not name the missing reference"
grep -q "3 of 10 views missing, 0 duplicated, 1 of 5 references missing: nothing written. Rerun shards 1 " "$mlog" \
  || fail "the merge's summary"
[ -e out/manifest.json ] && fail "a failed merge wrote the manifest"
[ "$(ls refs/ball/*.exr | wc -l)" = 4 ] || fail "not 4 references after the cancel"
ls refs/ball | grep -q tmp && fail "a temporary reference was left"

bash $script > submit3.txt 2>&1 || { cat submit3.txt; fail "submitting a third time"; }
read -r array3 merge3 < <(sed -n 's/.*as job \([0-9]*\), the merge as job \([0-9]*\).*/\1 \2/p' submit3.txt)
wait_jobs
[ "$(job_state "$merge3")" = JobState=COMPLETED ] || { cat farm/logs/limn-job-merge-"$merge3".log; fail "the last merge: $(job_state "$merge3")"; }
logs3=(farm/logs/limn-job-"$array3"_*.log)
grep -q "1 rendered, 1 cached" farm/logs/limn-job-"$array3"_1.log || fail "task 1 did not render only its missing reference"
grep -q "3 rendered, 0 skipped" farm/logs/limn-job-"$array3"_1.log || fail "task 1 did not render its 3 images"
[ "$(rendered '^job job.lua: ' "${logs3[@]}")" = 3 ] || fail "the rerun rendered $(rendered '^job job.lua: ' "${logs3[@]}") images, not the 3 missing"
[ "$(rendered '^references of job.lua: ' "${logs3[@]}")" = 1 ] || fail "the rerun rendered other references"
[ "$(ls out/*.png | wc -l)" = 10 ] && [ "$(ls refs/ball/*.exr | wc -l)" = 5 ] || fail "not every image and reference"
[ "$(grep -c '{"file": ' out/manifest.json)" = 10 ] || fail "the last merged manifest has not 10 images"
[ "$(grep -c '"run": 1,' out/manifest.json)" = 10 ] || fail "an image was rendered in another run than the first"
grep -q '"run": 2,' out/manifest.shard-0-of-3.json || fail "shard 0's manifest does not count its second run"
echo "step 2: the rerun rendered only the 3 images and 1 reference that were missing; merged"

# ---- 3. a sequence: its frames split into contiguous runs, references per frame ----
cat > turn.lua <<'JOB'
return {
  scenes = { "ball.gltf" }, techniques = { "dl" }, sizes = { "32x24" }, set = { ambient = 0 },
  time = { 0, 1, 5 }, turntable = { turns = 1 },
  output = "seq/{camera}_{frame}.png",
}
JOB
"$limn" farm slurm --job turn.lua --shards 3 --references --refs seqrefs --count 10 --pretrace-start 0.2 \
  --pretrace-end 0.1 --time 5 --submit > submit4.txt 2>&1 || { cat submit4.txt; fail "limn farm slurm of a sequence"; }
read -r array4 merge4 < <(sed -n 's/.*as job \([0-9]*\), the merge as job \([0-9]*\).*/\1 \2/p' submit4.txt)
wait_jobs
[ "$(job_state "$merge4")" = JobState=COMPLETED ] || { cat farm/logs/limn-turn-merge-"$merge4".log; fail "the sequence's merge: $(job_state "$merge4")"; }
for i in 0 1 2; do # task i renders frames 2i and 2i + 1, and their references
  log=farm/logs/limn-turn-"$array4"_$i.log
  grep -q "turn.lua: 6 views (2 in shard $i/3)" "$log" || fail "task $i's share of the frames: $(cat "$log")"
  grep -q "seq/turntable_000$((2 * i)).png" "$log" && grep -q "seq/turntable_000$((2 * i + 1)).png" "$log" \
    || fail "task $i did not render frames $((2 * i)) and $((2 * i + 1)): $(cat "$log")"
  grep -q "2 rendered, 0 cached" "$log" || fail "task $i did not render its 2 frames' references"
done
[ "$(ls seq/*.png | wc -l)" = 6 ] && [ "$(ls seqrefs/ball/turntable_32x24-000[0-5]-*.exr | wc -l)" = 6 ] \
  || fail "not 6 frames and 6 references: $(ls seq seqrefs/ball)"
grep -q "turn.lua: 6 views from 3 shards, each rendered once; 6 references there; seq/manifest.json" \
  farm/logs/limn-turn-merge-"$merge4".log || fail "the sequence's merge log"
echo "step 3: a 6-frame sequence in 3 tasks of 2 consecutive frames each, with a reference a frame; merged"
echo "passed"
