#!/usr/bin/env bash
# `fieldrig batch` against a real Slurm: munged, slurmctld and slurmd started here on localhost
# with a one-node configuration in a temporary folder (no accounting, so `batch status` must
# read squeue and the disk). Three synthetic sessions, an array of 4 tasks; one task is cancelled
# with scancel while it runs, the job is resubmitted, and the merged result must equal what
# `fieldrig process` gives serially on the same sessions, line for line. Everything started here
# is stopped on exit. Exit 77 (skipped) only when Slurm or munge is not installed or cannot start.
#
# Usage: batch_slurm_test.sh FIELDRIG_BINARY
set -euo pipefail

fieldrig=$(realpath "$1")
skip() {
  echo "SKIPPED: $*" >&2
  exit 77
}
for program in munged slurmctld slurmd sbatch squeue scancel python3; do
  command -v "$program" >/dev/null || skip "$program not found (scripts/install-deps.sh installs slurm-wlm and munge)"
done

# slurmd starts each task as the user who submitted it, which only root can do.
[[ $(id -u) == 0 ]] || skip "slurmd needs root to start jobs (CI runs as root)"

work=$(mktemp -d /tmp/fieldrig_batch_slurm.XXXXXX)
pids=()
cleanup() {
  local pid
  # Stop our daemons by the pids we started, newest first.
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do
    pid=${pids[i]}
    kill "$pid" 2>/dev/null || true
  done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  if [[ ${KEEP_WORK:-0} == 1 ]]; then echo "work folder kept: $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT

show_logs() {
  for log in "$work"/munged.log "$work"/slurmctld.log "$work"/slurmd.log; do
    [[ -f $log ]] && { echo "--- $log (tail)" >&2; tail -n 20 "$log" >&2; }
  done
  return 0
}

# --- munge: our own key, socket and daemon, so that a system munged is neither needed nor used.
mkdir -p "$work/munge" && chmod 700 "$work/munge"
if command -v mungekey >/dev/null; then
  mungekey --create --keyfile="$work/munge/munge.key" >/dev/null 2>&1
else
  dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
fi
chmod 400 "$work/munge/munge.key"
socket="$work/munge/munge.socket"
munged --force --foreground --key-file="$work/munge/munge.key" --socket="$socket" \
  --pid-file="$work/munge/munged.pid" --seed-file="$work/munge/munged.seed" \
  --log-file="$work/munged.log" >"$work/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [[ -S $socket ]] && break; sleep 0.1; done
[[ -S $socket ]] || { show_logs; cat "$work/munged.out" >&2; skip "munged did not start"; }

# --- Slurm: one node (this host, 2 CPUs), ports of our own, state under the work folder.
host=$(hostname -s)
port=$((20000 + RANDOM % 20000))
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
cat >"$SLURM_CONF" <<EOF
ClusterName=fieldrigtest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
ReturnToService=2
KillWait=2
MinJobAge=600
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$host CPUs=2 State=UNKNOWN
PartitionName=batch Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i -f "$SLURM_CONF" >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/slurmd.out" 2>&1 &
pids+=($!)
ready=0
for _ in $(seq 100); do
  if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then ready=1; break; fi
  sleep 0.2
done
if ((!ready)); then
  show_logs
  sinfo 2>&1 | tail -n 3 >&2 || true
  skip "slurmctld/slurmd did not bring the node up"
fi
echo "slurm is up on $host (port $port)"

# --- three small sessions of different lengths: 4 + 3 + 5 = 12 sets, 3 per task.
cd "$work"
counts=(4 3 5)
for i in 0 1 2; do
  "$fieldrig" sim plots --out "season/day$i" --count "${counts[i]}" --seed $((7 + i)) >/dev/null
done
"$fieldrig" batch plan season/day0 season/day1 season/day2 --out job --shards 4 >plan.json
python3 - <<'EOF'
import json
plan = json.load(open("plan.json"))
assert plan["sets"] == 12 and plan["sets_per_task"] == [3, 3, 3, 3], plan
EOF

# --- submit; cancel a task while it has written some but not all of its sets.
"$fieldrig" batch submit job >submit1.json
job_id=$(python3 -c 'import json; print(json.load(open("submit1.json"))["job_id"])')
echo "submitted job $job_id"
done_lines() {  # plots written by task $1
  cat job/tasks/task-"$1"/*/plots.jsonl 2>/dev/null | grep -c '^{' || true
}
cancelled=""
for _ in $(seq 1500); do
  for task in 0 1 2 3; do
    lines=$(done_lines "$task")
    if ((lines >= 1 && lines < 3)); then
      scancel "${job_id}_${task}"
      cancelled=$task
      break 2
    fi
  done
  squeue -h -j "$job_id" 2>/dev/null | grep -q . || break
  sleep 0.1
done
[[ -n $cancelled ]] || { show_logs; echo "FAIL: no task was caught mid-run" >&2; exit 1; }
echo "cancelled task $cancelled after $(done_lines "$cancelled") of 3 sets"
for _ in $(seq 1800); do
  squeue -h -j "$job_id" 2>/dev/null | grep -q . || break
  sleep 0.1
done

# status: the cancelled task failed (unless scancel came after its last set), the others done.
status=0
"$fieldrig" batch status job >status1.json || status=$?
cat status1.json
left=$(done_lines "$cancelled")
if ((left < 3)); then
  [[ $status == 3 ]] || { echo "FAIL: status exit $status with task $cancelled unfinished" >&2; exit 1; }
  python3 - "$cancelled" <<'EOF'
import json, sys
lines = [json.loads(l) for l in open("status1.json")]
tasks = {l["task"]: l for l in lines if "task" in l}
cancelled = int(sys.argv[1])
assert tasks[cancelled]["state"] == "failed", tasks[cancelled]
assert all(t["state"] == "done" for k, t in tasks.items() if k != cancelled), tasks
assert lines[-1]["summary"]["scheduler"] == "squeue", lines[-1]  # no accounting here
EOF
  # merge refuses a shorter table, naming the absent plots.
  merge_status=0
  "$fieldrig" batch merge job >merge_refused.json 2>merge_refused.err || merge_status=$?
  [[ $merge_status == 3 ]] || { echo "FAIL: merge with absent plots exit $merge_status" >&2; exit 1; }
  grep -q "absent: $work/season/day" merge_refused.err || { cat merge_refused.err >&2; exit 1; }
  [[ ! -e job/merged/season.jsonl ]] || { echo "FAIL: merge wrote a partial table" >&2; exit 1; }
fi

# --- resubmit: only the unfinished task goes, and it skips what it already wrote.
"$fieldrig" batch submit job >submit2.json
cat submit2.json
python3 - "$cancelled" "$left" <<'EOF'
import json, sys
s = json.load(open("submit2.json"))
cancelled, left = int(sys.argv[1]), int(sys.argv[2])
if left < 3:
    assert s["submitted"] and s["tasks"] == [cancelled], s
else:
    assert not s["submitted"], s
EOF
job2=$(python3 -c 'import json; print(json.load(open("submit2.json")).get("job_id", ""))')
if [[ -n $job2 ]]; then
  for _ in $(seq 1800); do
    squeue -h -j "$job2" 2>/dev/null | grep -q . || break
    sleep 0.1
  done
  grep -q "\"already_done\":$left" "job/logs/task-$cancelled.out" ||
    { cat "job/logs/task-$cancelled.out" >&2; echo "FAIL: the resubmitted task did not resume" >&2; exit 1; }
fi
"$fieldrig" batch status job >status2.json || { cat status2.json; show_logs; exit 1; }
"$fieldrig" batch merge job >merge1.json
cp job/merged/season.jsonl season1.jsonl
cp job/merged/season.csv season1.csv
"$fieldrig" batch merge job >merge2.json
cmp season1.jsonl job/merged/season.jsonl
cmp season1.csv job/merged/season.csv

# --- the same sessions serially; the merged lines are theirs with the session's name first.
for i in 0 1 2; do
  "$fieldrig" process "season/day$i" --out "serial/day$i" >/dev/null
done
python3 - <<'EOF'
import json
merged = open("job/merged/season.jsonl").read().splitlines()
provenance = json.loads(merged[0])["provenance"]
assert provenance["plots"] == 12 and provenance["absent"] == [], provenance
assert [s["name"] for s in provenance["sessions"]] == ["day0", "day1", "day2"]
assert provenance["calibration"] and all(len(c["sha256"]) == 64 for c in provenance["calibration"])
expected = []
for i in range(3):
    for line in open(f"serial/day{i}/plots.jsonl").read().splitlines():
        expected.append('{"session":"day%d",' % i + line[1:])
assert merged[1:] == expected, "merged lines differ from the serial run's"
csv = open("job/merged/season.csv").read().splitlines()
assert csv[0].startswith("# provenance: ")
serial_csv = [open(f"serial/day{i}/plots.csv").read().splitlines() for i in range(3)]
assert csv[1] == "session," + serial_csv[0][0]
assert csv[2:] == [f"day{i}," + row for i in range(3) for row in serial_csv[i][1:]]
print("merged season equals the serial run: 12 plots")
EOF
echo "PASS"
