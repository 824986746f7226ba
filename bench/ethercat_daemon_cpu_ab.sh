#!/usr/bin/env bash
# Alternates two or more drivegated binaries under bench_ethercat_daemon_cpu (transport raw, no DC)
# and prints, per run, the cycle thread's time per cycle, perf stat's task-clock during phase (a)
# and the benchmark's own phase (a) and (b) figures. On a shared machine the spread between runs
# of one binary is larger than most changes: only alternated runs compare.
#
#   bench/ethercat_daemon_cpu_ab.sh BUILD_DIR RUNS DRIVEGATED_A DRIVEGATED_B [...]
#
# Each binary is copied over BUILD_DIR/daemon/drivegated for its runs (the benchmark starts that
# one); the one built there is put back at the end. Needs root (veth, namespaces) and perf.
set -euo pipefail
build=${1:?usage: $0 BUILD_DIR RUNS DRIVEGATED... }
runs=${2:?usage: $0 BUILD_DIR RUNS DRIVEGATED... }
shift 2
seconds=${SECONDS_PER_PHASE:-10}
daemon=$build/daemon/drivegated
own=$(mktemp)
out=$(mktemp)
cp "$daemon" "$own"
trap 'cp "$own" "$daemon"; rm -f "$own" "$out"' EXIT
for _ in $(seq "$runs"); do
  for bin in "$@"; do
    cp "$bin" "$daemon"
    "$build/bench/bench_ethercat_daemon_cpu" --transport raw --no-dc --seconds "$seconds" >"$out" 2>&1 &
    bench=$!
    for _ in $(seq 240); do grep -q "drivegated pid" "$out" && break; sleep 0.5; done
    pid=$(grep -o "drivegated pid [0-9]*" "$out" | awk '{print $3}')
    sleep 1
    clock=$(perf stat -x, -e task-clock -p "$pid" -- sleep $((seconds - 2)) 2>&1 | grep task-clock | cut -d, -f1)
    wait "$bench" || true
    printf '%s: cycle(a) %s us  perf(a) %.2f %%  bench(a) %s %%  bench(b) %s %%  %s\n' "$bin" \
      "$(grep -m1 dg-cycle "$out" | awk '{print $5}')" "$(echo "$clock / ($seconds - 2) / 10" | bc -l)" \
      "$(grep -m1 'drivegated   process' "$out" | awk '{print $3}')" \
      "$(grep 'drivegated   process' "$out" | tail -1 | awk '{print $3}')" "$(grep -o 'refused [0-9]*' "$out" || echo 'did not finish')"
  done
done
