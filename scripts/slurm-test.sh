#!/usr/bin/env bash
# The real Slurm test of `crumple farm slurm` (issue 8, docs/FARM.md):
#  1. installs slurm-wlm, munge and ffmpeg when missing (scripts/bootstrap.sh:
#     Debian packages, as root or through sudo, idempotent);
#  2. builds the crumple binary (Release) into $CRUMPLE_BUILD_DIR (default build/);
#  3. starts a one-machine Slurm on localhost: munged, slurmctld and slurmd
#     with a minimal slurm.conf (this machine's CPUs and memory, no cgroups),
#     their state, logs and sockets in a temporary folder;
#  4. runs samples/drape (--chunk 12) and then samples/wiggle (it has
#     [sound]) through `crumple farm slurm`, waits for the jobs, and checks
#     every output: each job COMPLETED in the order of the chain, the cache,
#     every frame PNG of the range, the summary, the PROGRESS lines in the
#     logs, the render array's chunks (and that its tasks ran in parallel),
#     the movie (and sound.wav with its audio track for wiggle);
#  5. stops the daemons it started (by their process ids).
# Exit 0 only when everything is there. Takes about a minute on 2 cores.
# Usage: bash scripts/slurm-test.sh       (KEEP=1 keeps the temporary folder)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${CRUMPLE_BUILD_DIR:-$root/build}"

if [ "$(id -u)" -ne 0 ]; then
  # slurmd must run as root to start jobs.
  if command -v sudo >/dev/null 2>&1; then exec sudo -E bash "$0" "$@"; fi
  echo "slurm-test: needs root (or sudo) to run slurmd" >&2
  exit 1
fi

say() { echo "slurm-test: $*"; }
failures=0
check() {  # check DESCRIPTION COMMAND...: "ok" or "FAIL" with the description
  local what="$1"
  shift
  if "$@"; then echo "  ok    $what"; else
    echo "  FAIL  $what"
    failures=$((failures + 1))
  fi
}

bash "$root/scripts/bootstrap.sh" slurm-wlm munge ffmpeg
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target crumple -j "${CRUMPLE_JOBS:-$(nproc)}" >/dev/null
crumple="$build/crumple"

tmp="$(mktemp -d /tmp/crumple-slurm.XXXXXX)"
chmod 711 "$tmp"
mkdir -p "$tmp/munge" "$tmp/state" "$tmp/spool" "$tmp/log"
chmod 711 "$tmp/munge"
pids=()
jobs_submitted=()

stop() {
  local status=$?
  set +e
  if [ ${#jobs_submitted[@]} -gt 0 ] && [ -n "${SLURM_CONF:-}" ]; then
    scancel "${jobs_submitted[@]}" 2>/dev/null
    for _ in $(seq 1 40); do
      [ -z "$(squeue -h -j "$(IFS=,; echo "${jobs_submitted[*]}")" -o %i 2>/dev/null)" ] && break
      sleep 0.5
    done
  fi
  # The daemons this script started, newest first, by process id.
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill "${pids[$i]}" 2>/dev/null; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null; done
  [ ${#pids[@]} -gt 0 ] && say "stopped slurmd, slurmctld and munged"
  if [ "$status" -ne 0 ] || [ "$failures" -ne 0 ] || [ -n "${KEEP:-}" ]; then
    say "kept $tmp (slurm.conf, daemon logs in log/, the shots)"
  else
    rm -rf "$tmp"
  fi
}
trap stop EXIT

# Waits up to $1 seconds for a command to succeed.
wait_for() {
  local seconds="$1"
  shift
  for _ in $(seq 1 $((seconds * 5))); do
    "$@" >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  return 1
}

# ---- munge: its own key and socket, so no system munged is touched.
dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge/munge.key"
socket="$tmp/munge/munge.socket"
munged --foreground --force --socket="$socket" --key-file="$tmp/munge/munge.key" \
  --log-file="$tmp/log/munged.log" --pid-file="$tmp/munge/munged.pid" \
  --seed-file="$tmp/munge/munged.seed" >"$tmp/log/munged.out" 2>&1 &
pids+=($!)
wait_for 20 bash -c "munge -n -S '$socket' | unmunge -S '$socket'" ||
  { say "munged did not start"; cat "$tmp/log/munged.out"; exit 1; }

# ---- slurm.conf: one node, this machine as slurmd -C sees it.
node_line="$(slurmd -C | head -n 1)"
node="$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<<"$node_line")"
cat >"$tmp/slurm.conf" <<EOF
ClusterName=crumpletest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=${SLURMCTLD_PORT:-16817}
SlurmdPort=${SLURMD_PORT:-16818}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
MailProg=/bin/true
# A container: no cgroups.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$tmp/log/jobcomp.txt
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MinJobAge=3600
$node_line NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=crumple Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$tmp/slurm.conf"

slurmctld -D -f "$SLURM_CONF" >"$tmp/log/slurmctld.out" 2>&1 &
pids+=($!)
wait_for 30 scontrol ping ||
  { say "slurmctld did not start"; tail -n 20 "$tmp/log/slurmctld.log"; exit 1; }
slurmd -D -f "$SLURM_CONF" >"$tmp/log/slurmd.out" 2>&1 &
pids+=($!)
wait_for 60 bash -c '[ "$(sinfo -h -o %T)" = idle ]' ||
  { say "slurmd did not come up"; sinfo; tail -n 20 "$tmp/log/slurmd.log"; exit 1; }
cpus="$(sinfo -h -o %c)"
say "$(sinfo --version) on $node: $cpus CPUs, $(sinfo -h -o %m) MB; state in $tmp"

# Seconds since the epoch of a Slurm time (2026-01-02T03:04:05).
epoch() { date -d "$1" +%s; }
# A field of `scontrol show job -o` lines: field LINE NAME.
field() { grep -o " $2=[^ ]*" <<<" $1" | head -n 1 | cut -d= -f2-; }

# run_shot NAME SAMPLE CHUNK FIRST LAST SOUND: submits, waits, checks.
run_shot() {
  local name="$1" sample="$2" chunk="$3" first="$4" last="$5" sound="$6"
  local out="$tmp/$name"
  local count=$((last - first + 1))
  local tasks=$(((count + chunk - 1) / chunk))
  local submit
  submit="$("$crumple" farm slurm "$root/samples/$sample" --chunk "$chunk" --out "$out")"
  echo "$submit" | sed 's/^/  > /'
  local sim render fin
  sim="$(sed -n 's/^simulate job \([0-9]*\)$/\1/p' <<<"$submit")"
  render="$(sed -n 's/^render job \([0-9]*\) .*/\1/p' <<<"$submit")"
  fin="$(sed -n 's/^finalize job \([0-9]*\)$/\1/p' <<<"$submit")"
  [ -n "$sim" ] && [ -n "$render" ] && [ -n "$fin" ] || { say "no job ids printed"; exit 1; }
  jobs_submitted+=("$sim" "$render" "$fin")

  # Wait for the chain, counting the render tasks running at once.
  local started max_running=0 running
  started="$(date +%s)"
  while [ -n "$(squeue -h -j "$sim,$render,$fin" -o %i 2>/dev/null)" ]; do
    running="$(squeue -h -r -j "$render" -t RUNNING -o %i 2>/dev/null | wc -l)"
    [ "$running" -gt "$max_running" ] && max_running="$running"
    if [ $(($(date +%s) - started)) -gt "${SLURM_TEST_TIMEOUT:-1200}" ]; then
      say "$name: the jobs did not finish in time"
      squeue
      exit 1
    fi
    sleep 0.2
  done
  local wall=$(($(date +%s) - started))

  local simjob finjob arr
  simjob="$(scontrol show job -o "$sim")"
  finjob="$(scontrol show job -o "$fin")"
  arr="$(scontrol show job -o "$render")"
  local all_ok=1 line
  while read -r line; do
    [ "$(field "$line" JobState)" = COMPLETED ] && [ "$(field "$line" ExitCode)" = 0:0 ] || {
      all_ok=0
      echo "  job $(field "$line" JobId) ($(field "$line" JobName)): $(field "$line" JobState) exit $(field "$line" ExitCode)"
    }
  done <<<"$simjob"$'\n'"$arr"$'\n'"$finjob"
  check "every job COMPLETED with exit 0:0 (simulate $sim, render $render, finalize $fin)" \
    test "$all_ok" -eq 1
  check "the render array has $tasks tasks" test "$(grep -c . <<<"$arr")" -eq "$tasks"

  # The chain's order, from Slurm's own start and end times (seconds).
  local sim_end render_start=9999999999 render_end=0 fin_start s e
  sim_end="$(epoch "$(field "$simjob" EndTime)")"
  fin_start="$(epoch "$(field "$finjob" StartTime)")"
  while read -r line; do
    s="$(epoch "$(field "$line" StartTime)")"
    e="$(epoch "$(field "$line" EndTime)")"
    [ "$s" -lt "$render_start" ] && render_start="$s"
    [ "$e" -gt "$render_end" ] && render_end="$e"
  done <<<"$arr"
  check "render tasks start after simulate ends, finalize after the last render task" \
    test "$render_start" -ge "$sim_end" -a "$fin_start" -ge "$render_end"
  check "the render array ran in parallel: up to $max_running of its tasks at once on $cpus CPUs" \
    test "$max_running" -ge 2
  say "$name: chain done in $wall s: simulate $(($(epoch "$(field "$simjob" EndTime)") - $(epoch "$(field "$simjob" StartTime)"))) s, render array $((render_end - render_start)) s, finalize $(($(epoch "$(field "$finjob" EndTime)") - fin_start)) s"

  # The outputs.
  local frames_json
  frames_json="$("$crumple" inspect --json "$out/cache.pcache" 2>/dev/null | grep -o '"frame_count":[0-9]*' || true)"
  check "cache.pcache holds $count frames ($first-$last)" test "$frames_json" = "\"frame_count\":$count"
  local missing=0 f png
  for ((f = first; f <= last; f++)); do
    png="$(printf '%s/frames/%04d.png' "$out" "$f")"
    [ "$(head -c 4 "$png" 2>/dev/null | tail -c 3)" = PNG ] || missing=$((missing + 1))
  done
  check "every frame PNG $(printf %04d "$first")-$(printf %04d "$last") is there ($((count - missing)) of $count)" \
    test "$missing" -eq 0
  check "summary.json says $count frames simulated" grep -q "\"frames_simulated\":$count" "$out/summary.json"
  check "the simulate log has its PROGRESS lines up to 100" \
    grep -qx "PROGRESS 100" "$out/farm/logs/$name-simulate-$sim.out"
  local task rendered=0 n chunks_ok=1 expect
  for ((task = 0; task < tasks; task++)); do
    local log="$out/farm/logs/$name-render-${render}_$task.out"
    n="$(sed -n 's/^\([0-9]*\) frames rendered.*/\1/p' "$log" 2>/dev/null)"
    expect=$((task + 1 < tasks ? chunk : count - chunk * (tasks - 1)))
    [ "${n:-0}" -eq "$expect" ] && grep -qx "PROGRESS 100" "$log" || chunks_ok=0
    rendered=$((rendered + ${n:-0}))
  done
  check "each render task's log: its chunk's frames rendered ($rendered in all), PROGRESS up to 100" \
    test "$chunks_ok" -eq 1 -a "$rendered" -eq "$count"
  local fin_log="$out/farm/logs/$name-finalize-$fin.out"
  check "the finalize log names the movie" grep -q "^movie: $out/preview.mp4" "$fin_log"
  local vframes streams
  vframes="$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$out/preview.mp4" 2>/dev/null || true)"
  check "preview.mp4 has $count video frames ($vframes)" test "$vframes" = "$count"
  streams="$(ffprobe -v error -show_entries stream=codec_type -of csv=p=0 "$out/preview.mp4" 2>/dev/null | sort | tr '\n' ' ')"
  if [ "$sound" = sound ]; then
    local seconds
    seconds="$(ffprobe -v error -show_entries format=duration -of csv=p=0 "$out/sound.wav" 2>/dev/null || true)"
    check "sound.wav lasts the shot's $count frames ($seconds s)" \
      awk -v s="${seconds:-0}" -v c="$count" 'BEGIN { exit !(s > 0 && (s - c / 24) ^ 2 < 1e-6) }'
    check "sound.png (the spectrogram) is there" test -s "$out/sound.png"
    check "the finalize log has the soundtrack's line" grep -q "^soundtrack: " "$fin_log"
    check "preview.mp4 has the soundtrack muxed in (streams: $streams)" test "$streams" = "audio video "
  else
    check "preview.mp4 is silent, drape has no [sound] (streams: $streams)" test "$streams" = "video "
  fi
}

say "drape: crumple farm slurm samples/drape --chunk 12"
run_shot drape drape 12 0 72 silent
say "wiggle: crumple farm slurm samples/wiggle --chunk 30 (it has [sound])"
run_shot wiggle wiggle 30 0 90 sound

if [ "$failures" -ne 0 ]; then
  say "$failures check(s) failed"
  exit 1
fi
say "every output is there"
