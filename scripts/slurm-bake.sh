#!/usr/bin/env bash
# Bakes a world with `ldc bake` as a Slurm job array (issue 23; docs/bake.md).
#
#   scripts/slurm-bake.sh [options] [-- WORLD-ARGS...]
#     --out DIR          output folder (default: a temp folder, printed)
#     --shards N         array size (default 4)
#     --partition P      submit to an existing cluster's partition; no local daemons
#     --ldc PATH         the ldc tool (default: $LDC, else build/tools/ldc); on an existing
#                        cluster it must be at the same path on every node, as must --out
#     --products LIST    passed to ldc bake (default mesh,nav,voxels)
#     --test             the CI check: N = 4 over a 256 x 256 m landscape; the merged
#                        bake must equal a one-process bake (--shard 0/1) byte for byte,
#                        and one task killed midway (timeout -s KILL) then resubmitted
#                        must give the same bytes; a resubmitted finished array is skipped
#     WORLD-ARGS         what ldc bake takes as the world (default: --terrain-size 256,256
#                        --cell-size 1); e.g. -- my.ldcs, or -- --terrain-size 1024,1024 --cell-size 0.5
#
# Without --partition it starts a local single-node cluster (root needed): installs
# slurm-wlm and munge with apt-get when missing, runs munged, slurmctld and slurmd
# with their state under a temp folder, and stops them at exit (trap).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
ldc=${LDC:-$root/build/tools/ldc}
out=""; shards=4; partition=""; products="mesh,nav,voxels"; test_mode=0
world=(--terrain-size 256,256 --cell-size 1)
while [ $# -gt 0 ]; do
  case $1 in
    --out) out=$2; shift 2 ;;
    --shards) shards=$2; shift 2 ;;
    --partition) partition=$2; shift 2 ;;
    --ldc) ldc=$2; shift 2 ;;
    --products) products=$2; shift 2 ;;
    --test) test_mode=1; shift ;;
    --) shift; world=("$@"); break ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "slurm-bake.sh: unknown option '$1' (see --help)" >&2; exit 1 ;;
  esac
done
[ -x "$ldc" ] || { echo "slurm-bake.sh: no ldc tool at $ldc (build first, or give --ldc)" >&2; exit 1; }
ldc=$(cd "$(dirname "$ldc")" && pwd)/$(basename "$ldc")
t0=$(date +%s.%N)
elapsed() { awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
log() { echo "[slurm-bake $(elapsed) s] $*"; }

tmp=$(mktemp -d /tmp/slurm-bake.XXXXXX)
chmod 755 "$tmp"
[ -n "$out" ] || out=$tmp/out
mkdir -p "$out"; out=$(cd "$out" && pwd)

cleanup() {
  local rc=$?
  for p in slurmd slurmctld munged; do
    if [ -s "$tmp/$p.pid" ]; then kill "$(cat "$tmp/$p.pid")" 2>/dev/null || true; fi
  done
  sleep 0.5
  if [ "$rc" -ne 0 ]; then
    for f in "$tmp"/*.log "$tmp"/task-*.out; do [ -f "$f" ] && { echo "--- $f"; tail -20 "$f"; } >&2; done
  fi
  [ "$test_mode" = 1 ] && [ "$rc" -eq 0 ] && rm -rf "$tmp"
  exit "$rc"
}
trap cleanup EXIT

start_local_cluster() {
  [ "$(id -u)" = 0 ] || { echo "slurm-bake.sh: a local cluster needs root (or give --partition)" >&2; exit 1; }
  if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    log "installing slurm-wlm and munge (apt-get)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge >"$tmp/apt.log" 2>&1 ||
      { DEBIAN_FRONTEND=noninteractive apt-get update >>"$tmp/apt.log" 2>&1 &&
        DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge >>"$tmp/apt.log" 2>&1; }
  fi
  local host cpus mem
  host=$(hostname -s); cpus=$(nproc)
  mem=$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
  # munge: a fresh key and socket under the temp folder (nothing in /etc is touched)
  mkdir -p "$tmp/munge"; chmod 700 "$tmp/munge"
  dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 2>/dev/null; chmod 400 "$tmp/munge/munge.key"
  munged --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge.sock" \
    --pid-file="$tmp/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge/munge.seed" 2>>"$tmp/munged.log"
  mkdir -p "$tmp/state" "$tmp/spool"
  cat >"$tmp/slurm.conf" <<CONF
ClusterName=ldcbake
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge.sock
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
SlurmctldPort=$((6817 + RANDOM % 1000))
SlurmdPort=$((7817 + RANDOM % 1000))
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
MinJobAge=3600
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=bake Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
CONF
  export SLURM_CONF=$tmp/slurm.conf
  slurmctld -f "$SLURM_CONF"
  slurmd -f "$SLURM_CONF"
  for _ in $(seq 100); do
    sinfo -h -o %t 2>/dev/null | grep -qE '^idle' && break
    sleep 0.2
  done
  sinfo -h -o %t | grep -qE '^idle' || { echo "slurm-bake.sh: the local node did not come up idle" >&2; sinfo >&2 || true; exit 1; }
  partition=bake
  log "local cluster up: node $host, $cpus CPUs, partition bake"
}

# Submits tasks (an sbatch --array spec) and waits; extra sbatch options before them.
submit() {
  local spec=$1; shift
  local wrap="$*"
  sbatch --parsable --partition="$partition" --array="$spec" --cpus-per-task=1 --wait \
    --output="$tmp/task-%a.out" --job-name=ldc-bake --wrap "$wrap"
}

bake_cmd() {  # the command every array task runs (the shard index comes from Slurm)
  printf '%q ' "$ldc" -q bake "${world[@]}" --out "$out" --products "$products" --shard
  printf '"$SLURM_ARRAY_TASK_ID"/%d' "$shards"
}

[ -n "$partition" ] || start_local_cluster

log "submitting the bake: sbatch --array=0-$((shards - 1)) --wait"
ta=$(date +%s.%N)
submit "0-$((shards - 1))" "$(bake_cmd)" >/dev/null
"$ldc" -q bake --merge "$out"
tb=$(date +%s.%N)
array_s=$(awk -v a="$ta" -v b="$tb" 'BEGIN { printf "%.2f", b - a }')
log "array of $shards tasks + merge: $array_s s (sbatch --wait included); index: $out/index.json"
if [ -f "$tmp/slurmctld.log" ]; then  # local cluster: the tasks' own span, from the controller's log
  span=$(grep -E 'sched: Allocate JobId=|_job_complete: .* done' "$tmp/slurmctld.log" |
    sed -E 's/^\[[0-9-]+T([0-9:.]+)\].*/\1/' |
    awk -F: '{ t = $1 * 3600 + $2 * 60 + $3; if (NR == 1 || t < lo) lo = t; if (t > hi) hi = t } END { printf "%.2f", hi - lo }')
  log "array tasks ran from the first start to the last end in $span s"
fi

[ "$test_mode" = 1 ] || exit 0

# --- the CI check -------------------------------------------------------------
same_bake() {  # index.json and every file it lists, byte for byte (explicit returns: set -e is off in $(...) ||)
  cmp "$1/index.json" "$2/index.json" >&2 || return 1
  local n=0 f
  while read -r f; do cmp "$1/$f" "$2/$f" >&2 || return 1; n=$((n + 1)); done \
    < <(grep -o '"name": *"[^"]*"' "$1/index.json" | sed 's/.*"\([^"]*\)"$/\1/')
  [ "$n" -gt 0 ] || { echo "no files in $1/index.json" >&2; return 1; }
  diff -r --exclude=shards "$1" "$2" >/dev/null || { echo "the merged folders $1 and $2 differ" >&2; return 1; }
  echo "$n"
}
one=$tmp/one
t1=$(date +%s.%N)
"$ldc" -q bake "${world[@]}" --out "$one" --products "$products" --shard 0/1 >"$tmp/one.txt"
"$ldc" -q bake --merge "$one" >/dev/null
one_s=$(awk -v a="$t1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
n=$(same_bake "$one" "$out") || { echo "FAIL: the $shards-task array bake differs from the one-process bake" >&2; exit 1; }
log "merged array bake == one-process bake: index.json and $n files byte-identical (1 process: $one_s s, array: $array_s s)"

# A finished array resubmitted: every task skips its shard.
submit "0-$((shards - 1))" "$(bake_cmd)" >/dev/null
grep -q "already baked" "$tmp/task-0.out" || { echo "FAIL: a resubmitted finished shard was not skipped" >&2; exit 1; }
log "resubmitted finished array: skipped ($(head -c 60 "$tmp/task-0.out")...)"

# Kill one task midway, resubmit it, same bytes.
victim=$((shards / 2))
rm -rf "${out:?}/shards/$victim" "$out/index.json"
kill_after=$(awk -v s="$one_s" -v n="$shards" 'BEGIN { k = s / n / 3; if (k < 0.2) k = 0.2; printf "%.2f", k }')
submit "$victim" "timeout -s KILL $kill_after $(bake_cmd)" >/dev/null 2>&1 || true
[ ! -e "$out/shards/$victim/manifest.json" ] || { echo "FAIL: task $victim finished within $kill_after s; it was not killed midway" >&2; exit 1; }
partial=$(find "$out/shards/$victim" -type f 2>/dev/null | wc -l)
log "task $victim killed after $kill_after s: $partial files, no manifest"
if "$ldc" -q bake --merge "$out" 2>"$tmp/merge-refused.txt"; then echo "FAIL: merge accepted a killed shard" >&2; exit 1; fi
log "merge refused it: $(cat "$tmp/merge-refused.txt")"
submit "$victim" "$(bake_cmd)" >/dev/null
"$ldc" -q bake --merge "$out" >/dev/null
n=$(same_bake "$one" "$out") || { echo "FAIL: after the resubmitted task the bake differs from the one-process bake" >&2; exit 1; }
log "resubmitted task $victim: merged bake == one-process bake ($n files byte-identical)"
echo "slurm-bake test passed in $(elapsed) s (1 process $one_s s; $shards-task array $array_s s; $(grep -c . "$one/index.json" >/dev/null && du -sb "$one" | cut -f1) bytes per bake incl. index)"
