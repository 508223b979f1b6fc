#!/usr/bin/env bash
# The README's Slurm recipe on a real Slurm: a one-node cluster on this machine (munged,
# slurmctld and slurmd started here, no systemd, no cgroups), deploy/slurm/shards.sbatch run as
# a 4-task array on campaigns/files/ci.json, then the merge job; the merged outputs must equal a
# local `armfault run -j 2` byte for byte. A second round requeues one task while it runs
# (`scontrol requeue JOB_K`), and the task must finish its shard with --resume, byte-identical again.
# Usage (as root: it installs slurm-wlm and munge if missing and runs the daemons as root):
#   tools/slurm_check.sh [path/to/armfault]      (default: build/armfault)
# Exit: 0 all checks passed; 1 a check failed or Slurm could not run here (the reason is
# printed); 2 bad usage. Every wait is bounded, the whole check by SLURM_CHECK_LIMIT seconds
# (default 240, below the ctest TIMEOUT); everything started is stopped on exit.
set -euo pipefail

src=$(cd "$(dirname "$0")/.." && pwd)
say() { echo "slurm_check [${SECONDS}s]: $*"; }
die() { echo "slurm_check: FAIL: $*" >&2; exit 1; }

if [[ $# -gt 1 ]]; then echo "usage: $0 [path/to/armfault]" >&2; exit 2; fi
armfault=${1:-$src/build/armfault}
if [[ ! -x $armfault ]]; then echo "slurm_check: no armfault binary at '$armfault' (build first)" >&2; exit 2; fi
armfault=$(cd "$(dirname "$armfault")" && pwd)/$(basename "$armfault")
campaign=$src/campaigns/files/ci.json
sbatch_file=$src/deploy/slurm/shards.sbatch
shards=4
limit=${SLURM_CHECK_LIMIT:-240}
[[ $limit =~ ^[1-9][0-9]*$ ]] || { echo "slurm_check: SLURM_CHECK_LIMIT must be whole seconds, got '$limit'" >&2; exit 2; }
deadline=$((SECONDS + limit))
if [[ $(id -u) -ne 0 ]]; then
  # As README's tools/bootstrap.sh: root, or a user with (password-less) sudo.
  if sudo -n true 2>/dev/null; then exec sudo -n SLURM_CHECK_LIMIT="$limit" "$0" "$armfault"; fi
  echo "slurm_check: must run as root or with password-less sudo (installs packages; SlurmUser=root)" >&2
  exit 2
fi

# ------------------------------------------------------------------ install
missing=0
for cmd in munged munge slurmctld slurmd sbatch squeue scontrol; do
  command -v "$cmd" >/dev/null || missing=1
done
if [[ $missing -eq 1 ]]; then
  say "installing slurm-wlm and munge"
  { timeout 300 apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive timeout 600 apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null; } ||
    die "could not install slurm-wlm and munge with apt-get"
  deadline=$((SECONDS + limit))  # the limit is for the check itself
fi

# ------------------------------------------------------------------ cleanup
tmp=$(mktemp -d /tmp/armfault_slurm_check.XXXXXX)
chmod 755 "$tmp"  # munged wants its socket's directory searchable by all
# Every process this check starts (daemons, slurmstepd, job steps) carries this variable, so
# cleanup finds strays by it and touches no one else's processes.
marker="ARMFAULT_SLURM_CHECK=$tmp"
pids=()
export SLURM_CONF=$tmp/slurm.conf  # the client commands talk to this cluster only

marked_pids() {
  local d
  for d in /proc/[0-9]*; do
    { tr "\0" "\n" <"$d/environ"; } 2>/dev/null | grep -qFx "$marker" && echo "${d#/proc/}"
  done
  return 0
}
cleanup() {
  local status=$? p i
  set +e
  trap - EXIT INT TERM
  if [[ -f $SLURM_CONF ]] && [[ ${#pids[@]} -gt 0 ]]; then
    timeout 10 scancel --quiet --user=root >/dev/null 2>&1
    for i in $(seq 20); do
      [[ -z $(timeout 5 squeue -h 2>/dev/null) ]] && break
      sleep 0.5
    done
  fi
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  for i in $(seq 20); do
    [[ -z $(marked_pids) ]] && break
    sleep 0.5
  done
  for p in $(marked_pids); do kill -9 "$p" 2>/dev/null; done
  if [[ $status -ne 0 && -d $tmp/log ]]; then
    echo "slurm_check: daemon logs (last lines):" >&2
    for f in "$tmp"/log/*.out; do echo "== $f" >&2; tail -n 15 "$f" >&2; done
  fi
  rm -rf "$tmp"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# wait_for SECONDS WHAT CMD...: polls CMD until it succeeds; fails naming WHAT after SECONDS,
# or when the whole check's time is up.
wait_for() {
  local wait=$1 what=$2 end
  shift 2
  end=$((SECONDS + wait))
  until "$@"; do
    [[ $SECONDS -lt $end ]] || die "timed out after ${wait}s waiting for $what"
    [[ $SECONDS -lt $deadline ]] || die "SLURM_CHECK_LIMIT (${limit}s) reached waiting for $what"
    sleep 0.5
  done
}
alive() { kill -0 "$1" 2>/dev/null; }
# A port nobody listens on, from a random start (other builders may share the machine).
free_port() {
  local p=$((20000 + RANDOM % 20000)) i
  for i in $(seq 200); do
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null && [[ $p != "${ctld_port:-}" ]]; then
      echo "$p"
      return 0
    fi
    p=$((p + 1))
  done
  die "no free TCP port found on 127.0.0.1"
}

# ------------------------------------------------------------------ munge
mkdir -p "$tmp/log" "$tmp/state" "$tmp/spool"
head -c 1024 /dev/urandom >"$tmp/munge.key"
chmod 400 "$tmp/munge.key"
# --force: munged refuses a key and socket outside its usual root-owned directories otherwise.
env "$marker" munged --foreground --force --socket="$tmp/munge.socket" --key-file="$tmp/munge.key" \
  --log-file="$tmp/munged.log" --pid-file="$tmp/munged.pid" --seed-file="$tmp/munged.seed" \
  >"$tmp/log/munged.out" 2>&1 &
pids+=($!)
munge_ok() { alive "${pids[0]}" && munge -S "$tmp/munge.socket" -n 2>/dev/null | unmunge -S "$tmp/munge.socket" >/dev/null 2>&1; }
wait_for 15 "munged to encode and decode a credential" munge_ok

# ------------------------------------------------------------------ slurm.conf
node=$(hostname -s)
cpus=$(nproc)
ctld_port=$(free_port)
slurmd_port=$(free_port)
cat >"$SLURM_CONF" <<EOF
# A one-node cluster for tools/slurm_check.sh, everything under $tmp.
ClusterName=armfaultcheck
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
# Root: the container has no systemd to start daemons as the slurm user, and the jobs run as root.
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
# cred_expire is also how long a requeued job waits before it starts again (default 120 s).
AuthInfo=socket=$tmp/munge.socket,cred_expire=10
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
# No cgroups in a container: track processes by /proc, no task binding or confinement.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
# Scheduling passes every 2 s (defaults 60 s and 30 s): a requeued task whose begin time has
# passed, and the merge job, then start within seconds.
SchedulerParameters=sched_interval=2,bf_interval=2
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
# A killed (requeued) task gets SIGTERM, then SIGKILL after KillWait s (default 30).
KillWait=5
MinJobAge=600
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=check Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF

# ------------------------------------------------------------------ slurmctld, slurmd
say "starting slurmctld (port $ctld_port) and slurmd (port $slurmd_port) for node $node, $cpus CPUs"
env "$marker" slurmctld -D -f "$SLURM_CONF" >"$tmp/log/slurmctld.out" 2>&1 &
ctld_pid=$!
pids+=("$ctld_pid")
ctld_up() {
  alive "$ctld_pid" || die "slurmctld exited: $(tail -n 5 "$tmp/log/slurmctld.out")"
  timeout 5 scontrol ping 2>/dev/null | grep -q "is UP"
}
wait_for 30 "slurmctld to answer 'scontrol ping'" ctld_up
env "$marker" slurmd -D -f "$SLURM_CONF" >"$tmp/log/slurmd.out" 2>&1 &
slurmd_pid=$!
pids+=("$slurmd_pid")
node_idle() {
  alive "$slurmd_pid" || die "slurmd cannot run here, it exited: $(tail -n 5 "$tmp/log/slurmd.out")"
  [[ $(timeout 5 sinfo -h -n "$node" -o %T 2>/dev/null) == idle ]]
}
wait_for 30 "node $node to be idle in sinfo (slurmd registered)" node_idle
say "cluster up: $(timeout 5 sinfo -h -o '%P %a %D %T %N %c')"

# Jobs find armfault on PATH (sbatch passes the submitting environment on) and carry the marker.
export PATH="$(dirname "$armfault"):$PATH"
submit() { env "$marker" timeout 10 sbatch --parsable "$@"; }

# ------------------------------------------------------------------ the reference
say "local reference: armfault run ci.json -j 2"
timeout 120 "$armfault" run "$campaign" -o "$tmp/local" -j 2 -q >"$tmp/local.out" 2>&1 || die "local run failed: $(cat "$tmp/local.out")"
total=$(wc -l <"$tmp/local/results.jsonl")

# job_field JOB FIELD: a field of `scontrol show job` (the first, for one array task).
job_field() { timeout 10 scontrol show job "$1" | tr ' ' '\n' | sed -n "s/^$2=//p" | head -n 1; }
in_queue() { [[ -n $(timeout 10 squeue -h -j "$1" 2>/dev/null) ]]; }
gone() { ! in_queue "$1"; }

# round NAME [REQUEUE_TASK]: the shards array and the merge job in $tmp/NAME, checked.
round() {
  local name=$1 requeue_task=${2:-} dir=$tmp/$1 jobid merge k f lines state log
  mkdir -p "$dir"
  cp "$campaign" "$dir/camp.json"
  # The README's commands, with the array, CPUs and time limit sized for this one machine.
  jobid=$(cd "$dir" && PATH=${requeue_task:+$tmp/hold:}$PATH submit --array=0-$((shards - 1)) --cpus-per-task=1 --time=00:10:00 \
    "$sbatch_file" camp.json out)
  merge=$(cd "$dir" && submit --dependency=afterany:"$jobid" --job-name=armfault-merge --output=merge.out \
    --wrap 'armfault merge out/shard-* -o out/merged')
  say "$name: submitted array job $jobid ($shards tasks) and merge job $merge"
  timeout 10 squeue -o '%.8i %.16j %.2t %.10r' | sed 's/^/    /'

  if [[ -n $requeue_task ]]; then
    # Catch task K running (held by the wrapper) with part of its shard written, then requeue it.
    f=$dir/out/shard-$requeue_task/results.jsonl
    caught() {
      state=$(timeout 10 squeue -h -j "${jobid}_$requeue_task" -o %T 2>/dev/null)
      [[ $state == RUNNING && -f $dir/held-$requeue_task ]] && return 0
      [[ $state == RUNNING || $state == PENDING || $state == CONFIGURING ]] ||
        die "task ${jobid}_$requeue_task ended (${state:-gone}) before it could be requeued while running"
      return 1
    }
    wait_for 120 "task ${jobid}_$requeue_task to run and be held mid-shard" caught
    lines=$(wc -l <"$f")
    [[ $lines -ge 1 && $lines -lt $(((total - requeue_task + shards - 1) / shards)) ]] ||
      die "task ${jobid}_$requeue_task was held with $lines lines written, not mid-shard"
    timeout 10 scontrol requeue "${jobid}_$requeue_task"
    say "$name: requeued ${jobid}_$requeue_task while RUNNING with $lines of its $(((total - requeue_task + shards - 1) / shards)) lines written"
  fi

  wait_for 240 "array job $jobid and merge job $merge to leave the queue" gone "$jobid,$merge"
  say "$name: jobs done"
  for ((k = 0; k < shards; k++)); do
    state=$(job_field "${jobid}_$k" JobState)
    # A shard exits 1 when its share misses a floor (a result, not a failure); the merge judges.
    [[ $state == COMPLETED || ($state == FAILED && $(job_field "${jobid}_$k" ExitCode) == 1:0) ]] ||
      die "$name: task ${jobid}_$k ended $state (exit $(job_field "${jobid}_$k" ExitCode)): $(cat "$dir"/slurm-"${jobid}_$k".out 2>/dev/null)"
  done
  [[ $(job_field "$merge" ExitCode) == 0:0 ]] ||
    die "$name: merge job $merge exited $(job_field "$merge" ExitCode): $(cat "$dir/merge.out")"
  for f in campaign.json results.jsonl decisions.jsonl summary.json junit.xml; do
    cmp "$tmp/local/$f" "$dir/out/merged/$f" || die "$name: merged $f differs from the local run's"
  done
  say "$name: merged campaign.json, results.jsonl, decisions.jsonl, summary.json, junit.xml == local run (cmp)"
  say "$name: merge job $merge printed:"
  sed 's/^/    /' "$dir/merge.out"

  if [[ -n $requeue_task ]]; then
    log=$dir/slurm-${jobid}_$requeue_task.out
    grep -q "DUE TO JOB REQUEUE" "$log" || die "$name: the task's log shows no requeue: $(cat "$log")"
    [[ $(job_field "${jobid}_$requeue_task" Restarts) -ge 1 ]] || die "$name: task ${jobid}_$requeue_task did not restart"
    # The second attempt resumed the lines the first had written.
    grep -Eq '^ran [0-9]+ runs in .* \(([1-9][0-9]*) resumed, 0 failed\)' "$log" ||
      die "$name: the requeued task did not resume: $(cat "$log")"
    say "$name: task ${jobid}_$requeue_task's log, both attempts:"
    sed 's/^/    /' "$log"
  fi
}

# The requeue round's wrapper, first on PATH: on its first attempt, task K's shard is held
# (SIGSTOP) once it has written 2 of its lines, so the requeue lands mid-shard whatever the
# machine's speed (13 runs take about 2 s here: too short to catch reliably by polling). The held
# task is RUNNING to Slurm; the requeue kills it, and the next attempt (SLURM_RESTART_COUNT set)
# runs the real armfault straight through with --resume.
mkdir -p "$tmp/hold"
cat >"$tmp/hold/armfault" <<'WRAPPER'
#!/bin/bash
set -u
if [[ -n ${SLURM_RESTART_COUNT:-} || ${SLURM_ARRAY_TASK_ID:-} != "${HOLD_TASK:-}" || ${1:-} != run ]]; then
  exec "$REAL_ARMFAULT" "$@"
fi
args=("$@")
out=out
for ((i = 0; i + 1 < $#; i++)); do [[ ${args[i]} == -o ]] && out=${args[i + 1]}; done
"$REAL_ARMFAULT" "$@" &
pid=$!
for i in $(seq 3000); do  # at most 60 s
  [[ -f $out/results.jsonl && $(wc -l <"$out/results.jsonl") -ge 2 ]] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.02
done
kill -STOP "$pid" 2>/dev/null && touch "held-$SLURM_ARRAY_TASK_ID"
wait "$pid"
WRAPPER
chmod +x "$tmp/hold/armfault"

round plain
REAL_ARMFAULT=$armfault HOLD_TASK=3 round requeue 3
say "PASS: Slurm array + merge byte-identical to a local run, also with a task requeued while running"
