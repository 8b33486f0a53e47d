#!/bin/bash
# Runs deploy/slurm/ on a throwaway one-node Slurm cluster and checks that the sharded bake
# merges to the one-process bake byte for byte (docs/deploy.md "Slurm").
#
#   sudo bash scripts/slurm_test.sh [RDM_BINARY]      (default build/cli/rdm)
#
# Installs slurm-wlm and munge with apt-get when missing. munged, slurmctld and slurmd run
# from a temporary directory (their own key, socket, config, state and logs; ports 6817 and
# 6818) and are stopped at the end, pass or fail. For chess and island: export the scene,
# submit a 4-shard array and its merge with deploy/slurm/submit.sh, bake the same scene in
# one process, and `cmp` atlas.exr, index.json and face_light.bin. Exits non-zero on any
# mismatch, failed job or timeout. Environment: RDM_SLURM_TIMEOUT (seconds for the jobs,
# default 600), RDM_SLURM_KEEP=1 keeps the temporary directory.
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
rdm=${1:-$repo/build/cli/rdm}
timeout_s=${RDM_SLURM_TIMEOUT:-600}
shards=4
scenes=(chess island)
bake_options=(--spp 2 --face-light 4 --quiet)
started=$EPOCHREALTIME
since() { awk -v a="$1" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }'; }

die() {
  echo "slurm_test: FAIL: $*" >&2
  exit 1
}
log() { echo "slurm_test: [$(date -u +%T)] $*"; }

[[ -x $rdm ]] || die "no rdm binary at $rdm (build it: cmake --build build --target rdm)"
rdm=$(realpath "$rdm")
((EUID == 0)) || die "needs root (apt-get, munged, slurmd); run with sudo"

if ! command -v slurmctld > /dev/null || ! command -v slurmd > /dev/null ||
  ! command -v munged > /dev/null || ! command -v sbatch > /dev/null; then
  log "installing slurm-wlm and munge"
  apt-get update -qq || die "apt-get update failed"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    slurm-wlm munge > /dev/null || die "apt-get install slurm-wlm munge failed"
fi
for port in 6817 6818; do
  if ss -ltn 2> /dev/null | grep -q ":$port "; then
    die "port $port is in use: is a Slurm daemon already running here?"
  fi
done

work=$(mktemp -d /tmp/rdm-slurm.XXXXXX)
chmod 755 "$work"  # munged wants its socket's directories searchable by all
pids=()  # slurmd, slurmctld: stopped in this order
stop() {    # PID: SIGTERM, then SIGKILL after 15 s
  kill "$1" 2> /dev/null || return 0
  for _ in $(seq 30); do
    kill -0 "$1" 2> /dev/null || return 0
    sleep 0.5
  done
  echo "slurm_test: $1 ignored SIGTERM for 15 s: SIGKILL" >&2
  kill -9 "$1" 2> /dev/null || true
}
our_stepds() {  # slurmstepd processes with a file open under $work (their log or socket)
  local dir name
  for dir in /proc/[0-9]*; do
    name=
    { read -r -d '' name < "$dir/cmdline"; } 2> /dev/null
    [[ $name == slurmstepd* ]] || continue
    find "$dir/fd" -lname "$work/*" 2> /dev/null | grep -q . && echo "${dir#/proc/}"
  done
  return 0
}
cleanup() {
  local rc=$? pid stopping=$EPOCHREALTIME
  set +e
  if ((${#pids[@]} > 0)); then
    # Cancel, then let the steps report to slurmctld before it goes: a step that cannot
    # report its end retries for ever.
    scancel --quiet --user root 2> /dev/null
    for _ in $(seq 60); do
      [[ -z $(squeue -h 2> /dev/null) ]] && break
      sleep 0.5
    done
    for pid in "${pids[@]}"; do stop "$pid"; done
    for pid in $(our_stepds); do stop "$pid"; done
  fi
  [[ -f $work/munge-run/munged.pid ]] && stop "$(cat "$work/munge-run/munged.pid")"
  log "jobs and daemons stopped in $(since "$stopping") s"
  if ((rc != 0)); then
    for f in "$work"/log/*.log "$work"/out/*/logs/*.log; do
      [[ -f $f ]] && echo "--- $f (last 20 lines)" >&2 && tail -n 20 "$f" >&2
    done
  fi
  if [[ ${RDM_SLURM_KEEP:-0} == 1 ]]; then
    echo "slurm_test: kept $work" >&2
  else
    rm -rf "$work"
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
mkdir -m 700 "$work/munge-key"
mkdir -m 755 "$work/munge-run"
mkdir -p "$work/etc" "$work/log" "$work/state" "$work/spool" "$work/out"

log "starting munged"
mungekey --create --keyfile="$work/munge-key/munge.key" || die "mungekey failed"
munged --key-file="$work/munge-key/munge.key" --socket="$work/munge-run/munge.sock" \
  --pid-file="$work/munge-run/munged.pid" --log-file="$work/log/munged.log" \
  --seed-file="$work/munge-key/munged.seed" || die "munged did not start ($work/log/munged.log)"

host=$(hostname -s)
cpus=$(nproc)
memory_mib=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
export SLURM_CONF=$work/etc/slurm.conf
cat > "$SLURM_CONF" << CONF
ClusterName=rdmtest
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge-run/munge.sock
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
SchedulerType=sched/backfill
SchedulerParameters=kill_invalid_depend
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/state/slurmctld.pid
SlurmdPidFile=$work/spool/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
MinJobAge=600
NodeName=$host CPUs=$cpus RealMemory=$memory_mib State=UNKNOWN
PartitionName=rdm Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
log "starting slurmctld and slurmd ($host: $cpus CPUs, $memory_mib MiB)"
slurmctld -D -c -f "$SLURM_CONF" > "$work/log/slurmctld.out" 2>&1 &
pids=($!)
slurmd -D -f "$SLURM_CONF" > "$work/log/slurmd.out" 2>&1 &
pids=($! "${pids[@]}")

wait_until() {  # SECONDS WHAT COMMAND...: polls COMMAND every second
  local limit=$1 what=$2
  local deadline=$((SECONDS + limit))
  shift 2
  until "$@"; do
    ((SECONDS < deadline)) || die "timed out after $limit s waiting for $what"
    for pid in "${pids[@]}"; do
      kill -0 "$pid" 2> /dev/null || die "a Slurm daemon exited while waiting for $what"
    done
    sleep 1
  done
}
node_idle() { [[ $(sinfo -h -n "$host" -o %t 2> /dev/null) == idle ]]; }
wait_until 60 "node $host to be idle (sinfo)" node_idle
setup_s=$(since "$started")
log "node idle after $setup_s s"

# Submit both scenes' arrays, then bake the references while Slurm runs them.
declare -A merge_of
jobs_started=$EPOCHREALTIME
for scene in "${scenes[@]}"; do
  "$rdm" scene --scene "$scene" -o "$work/$scene.json" > /dev/null
  ids=$(RDM=$rdm RDM_CPUS=1 RDM_MEM=1G RDM_TIME=00:20:00 \
    "$repo/deploy/slurm/submit.sh" "$work/$scene.json" "$work/out/$scene" "$shards" \
    "${bake_options[@]}") || die "submit.sh failed for $scene"
  merge_of[$scene]=${ids#* }
  log "$scene: array ${ids% *}, merge ${merge_of[$scene]}"
done
for scene in "${scenes[@]}"; do
  "$rdm" bake "$work/$scene.json" "${bake_options[@]}" -o "$work/one/$scene" \
    > "$work/log/one-$scene.log" 2>&1 || die "one-process bake of $scene failed"
done

job_state() { scontrol show job -o "$1" 2> /dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2; }
merges_done() {
  local scene state
  for scene in "${scenes[@]}"; do
    state=$(job_state "${merge_of[$scene]}")
    case $state in
      COMPLETED) ;;
      PENDING | CONFIGURING | RUNNING | COMPLETING | "") return 1 ;;
      *) die "$scene: merge job ${merge_of[$scene]} ended $state (a shard failed?)" ;;
    esac
  done
}
wait_until "$timeout_s" "the bakes and merges (squeue)" merges_done
jobs_s=$(since "$jobs_started")
left=$(squeue -h | wc -l)
((left == 0)) || die "$left job(s) still queued after the merges completed"

for scene in "${scenes[@]}"; do
  for f in atlas.exr index.json face_light.bin rdms.bin; do
    cmp "$work/one/$scene/$f" "$work/out/$scene/atlas/$f" ||
      die "$scene: $f of the Slurm bake differs from the one-process bake"
  done
  log "$scene: atlas.exr, index.json, face_light.bin, rdms.bin identical ($shards shards + merge vs one process)"
done
echo "slurm_test: PASS: ${#scenes[@]} scenes x $shards shards; cluster up in $setup_s s," \
  "bakes + merges $jobs_s s, total $(since "$started") s"
