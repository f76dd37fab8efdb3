#!/usr/bin/env bash
# A real Slurm cluster of one node on this machine: installs Debian's slurmctld, slurmd and munge,
# starts munged, slurmctld and slurmd with their state in a directory of their own, and submits
# the `sbatch --array` lines of docs/dataset-format.md as written (a simulated dataset in 4 tasks,
# 2 at a time; the coverage-vs-divisions study in 3). Each result must equal one unsharded process
# byte for byte (the study's timings apart); then a task is killed mid-way by `scontrol requeue`,
# and the dataset it resumes must be the same again. The daemons stop when the script ends.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
bash ci/install-deps.sh slurm
[ -x build/sim/sonarbench ] || bash ci/build.sh --target sonarbench

work=$(mktemp -d /tmp/sonarbench-slurm.XXXXXX)
state="$work/cluster"
mkdir -p "$state/spool" "$state/save" "$state/munge" "$state/log" "$work/out"
chmod 700 "$state/munge"
stop() {
  local code=$?
  local pids=() pid
  for f in "$state/slurmd.pid" "$state/slurmctld.pid" "$state/munge/munged.pid"; do
    [ -f "$f" ] && pids+=("$(cat "$f")")
  done
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  # A daemon writes its state as it stops: the folder goes once every one has exited (10 s at most).
  for _ in $(seq 100); do
    local alive=0
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  if [ "$code" -ne 0 ]; then
    echo "ci/test-slurm.sh: failed; the daemons' logs:" >&2
    tail -n 30 "$state"/log/*.log "$work"/out/*.log >&2 2>/dev/null || true
  fi
  rm -rf "$work" || echo "ci/test-slurm.sh: warning: $work not removed" >&2
  exit "$code"
}
trap stop EXIT

dd if=/dev/urandom of="$state/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$state/munge/munge.key"
munged --force --key-file="$state/munge/munge.key" --socket="$state/munge/socket" \
  --pid-file="$state/munge/munged.pid" --log-file="$state/log/munged.log" \
  --seed-file="$state/munge/seed"
host=$(hostname -s)
export SLURM_CONF="$state/slurm.conf"
cat > "$SLURM_CONF" <<EOF
ClusterName=sonarbench
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$state/munge/socket
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$state/save
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
JobRequeue=1
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
SchedulerParameters=sched_interval=2,bf_interval=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=bench Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do sinfo -h -o %T 2>/dev/null | grep -q idle && break; sleep 1; done
sinfo -h -o %T | grep -q idle || { echo "ci/test-slurm.sh: the node never came up" >&2; exit 1; }
echo "ci/test-slurm.sh: a Slurm cluster of one node ($host, $(nproc) CPUs) is up"

# The documented lines, their /scratch/ directories moved under $work/out.
mapfile -t lines < <(grep '^sbatch --array' docs/dataset-format.md)
[ ${#lines[@]} -eq 2 ] || { echo "ci/test-slurm.sh: expected 2 sbatch lines in docs/dataset-format.md" >&2; exit 1; }

# Submits a documented line (its directory renamed to $2) and prints the job's id.
submit() {
  local line=${1//\/scratch\//$work/out/}
  line=${line//$work\/out\/$3/$work/out/$2}
  eval "sbatch --parsable --chdir=\"$root\" --output=\"$work/out/%x-%A_%a.log\" ${line#sbatch }"
}
# Waits until job $1 has left the queue (every task ended) and checks that each task exited 0.
wait_job() {
  while [ -n "$(squeue -h -j "$1" 2>/dev/null)" ]; do sleep 1; done
  local failed
  failed=$(scontrol show job "$1" 2>/dev/null | grep -o 'ExitCode=[0-9]*:[0-9]*' | grep -vc 'ExitCode=0:0' || true)
  [ "$failed" -eq 0 ] || { echo "ci/test-slurm.sh: job $1 had $failed failed tasks" >&2; exit 1; }
}
# The files of two result directories compared byte for byte (the lock, and the divisions study's
# map_s timings and time plot, apart).
same() {
  python3 - "$1" "$2" <<'PY'
import csv, io, json, pathlib, sys
a, b = map(pathlib.Path, sys.argv[1:3])
def files(d):
    return sorted(p.relative_to(d) for p in d.rglob('*')
                  if p.is_file() and p.name not in ('.sonarbench.lock', 'time_vs_divisions.png'))
def untimed(p):
    if p.suffix == '.json':
        def drop(v):
            if isinstance(v, dict): return {k: drop(x) for k, x in v.items() if k != 'map_s'}
            if isinstance(v, list): return [drop(x) for x in v]
            return v
        return json.dumps(drop(json.loads(p.read_text())), sort_keys=True)
    if p.suffix == '.csv':
        rows = list(csv.reader(io.StringIO(p.read_text())))
        keep = [i for i, h in enumerate(rows[0]) if h != 'map_s']
        return [[r[i] for i in keep] for r in rows]
    return p.read_bytes()
fa, fb = files(a), files(b)
if fa != fb:
    sys.exit(f"{a} and {b} hold different files: {sorted(set(fa) ^ set(fb))}")
for f in fa:
    if untimed(a / f) != untimed(b / f):
        sys.exit(f"{a / f} differs from {b / f}")
print(f"ci/test-slurm.sh: {b} equals {a}: {len(fa)} files")
PY
}

dataset=$(basename "$(echo "${lines[0]}" | grep -o '/scratch/[^ "]*')")
study=$(basename "$(echo "${lines[1]}" | grep -o '/scratch/[^ "]*')")
echo "ci/test-slurm.sh: ${lines[0]}"
job=$(submit "${lines[0]}" "$dataset" "$dataset")
echo "ci/test-slurm.sh: ${lines[1]}"
job2=$(submit "${lines[1]}" "$study" "$study")
# The same work in one process each, while the cluster runs.
for i in 0 1; do
  dir=$([ "$i" -eq 0 ] && echo "$dataset" || echo "$study")
  cmd=$(echo "${lines[$i]}" | sed -E 's/.*--wrap "(.*)"/\1/' | sed "s#/scratch/$dir#$work/out/one-$dir#")
  $cmd > "$work/out/one-$dir.log"
done
wait_job "$job"
wait_job "$job2"
# Each task ran its own shard, as SLURM_ARRAY_* gave it.
for spec in "$job:4" "$job2:3"; do
  shards=$(cat "$work"/out/*-"${spec%:*}"_*.log | grep -oE "^shard [0-9]+/${spec#*:}:" | sort -u | wc -l)
  [ "$shards" -eq "${spec#*:}" ] || { echo "ci/test-slurm.sh: job ${spec%:*} ran $shards shards, expected ${spec#*:}" >&2; exit 1; }
done
same "$work/out/one-$dataset" "$work/out/$dataset"
same "$work/out/one-$study" "$work/out/$study"

# A task killed mid-way: requeued once its shard (task K writes the sweeps s with s mod 4 = K - 1)
# has a sweep complete (its record in .sonarbench-partial/, which a resume trusts), and before it
# has all of them.
shards=$(echo "${lines[0]}" | grep -oE -- '--array=1-[0-9]+' | grep -oE '[0-9]+$')
scene=$(echo "${lines[0]}" | grep -oE 'scenes/[^ ]+\.yaml')
share=$(( ($(grep -oE '^sweeps: *[0-9]+' "$scene" | grep -oE '[0-9]+$') + shards - 1) / shards ))
written() {  # the complete sweeps of shard $2 in dataset $1
  local n=0 f
  for f in "$1"/.sonarbench-partial/sweep_*.json; do
    [ -e "$f" ] || continue
    f=${f##*sweep_}; f=$((10#${f%.json}))
    [ $((f % shards)) -eq $(($2 - 1)) ] && n=$((n + 1))
  done
  echo "$n"
}
for attempt in 1 2 3; do
  name="requeued-$attempt"
  job=$(submit "${lines[0]}" "$name" "$dataset")
  killed=""
  for _ in $(seq 6000); do
    for task in $(squeue -h -j "$job" -t R -o %i); do
      n=$(written "$work/out/$name" "${task#*_}")
      if [ "$n" -ge 1 ] && [ "$n" -lt "$share" ]; then
        scontrol requeue "$task" && killed=$task
        echo "ci/test-slurm.sh: requeued task $task with $n of its $share sweeps written"
        break 2
      fi
    done
    sleep 0.05
  done
  wait_job "$job"
  if [ -n "$killed" ] && grep -q "skipped [1-9][0-9]* already complete" "$work"/out/*-"$killed".log; then
    echo "ci/test-slurm.sh: task $killed resumed the sweeps it had written"
    same "$work/out/one-$dataset" "$work/out/$name"
    echo "ci/test-slurm.sh: passed"
    exit 0
  fi
  echo "ci/test-slurm.sh: attempt $attempt did not catch a task mid-way; again"
done
echo "ci/test-slurm.sh: no task was caught mid-way in 3 attempts" >&2
exit 1
