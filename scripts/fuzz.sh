#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for SECONDS (default 60)
# on a scratch copy of its seed corpus (fuzz/README.md).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      TARGET: NAME of a fuzz/fuzz_NAME.cpp (default: all)
#
# Environment: BUILD_DIR (default build-fuzz next to the source tree), WORK_DIR (scratch, default
# a new mktemp -d), JOBS (ninja -j, default 2).
# Crashes, leaks and sanitizer reports: libFuzzer writes the input as WORK_DIR/<target>/crash-*
# (leak-*, timeout-*, oom-*); the log is WORK_DIR/<target>/fuzz.log. Reproduce with
# BUILD_DIR/fuzz/fuzz_<target> FILE, or fuzz_replay_<target> FILE in a normal build.
set -euo pipefail

src=$(cd "$(dirname "$0")/.." && pwd)

seconds=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in "$src"/fuzz/fuzz_*.cpp; do
    name=${f##*/fuzz_}
    targets+=("${name%.cpp}")
  done
fi
build=${BUILD_DIR:-$src/../build-fuzz}
work=${WORK_DIR:-$(mktemp -d /tmp/drivegate-fuzz.XXXXXX)}
jobs=${JOBS:-2}

# The whole tree gets the coverage instrumentation (fuzzer-no-link); only fuzz_* link libFuzzer.
CC=clang CXX=clang++ cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DDRIVEGATE_FUZZ=ON -DDRIVEGATE_TESTS=OFF -DDRIVEGATE_BENCH=OFF \
  "-DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined" >/dev/null
ninja -C "$build" -j "$jobs" "${targets[@]/#/fuzz_}"

found=0
printf '%-14s %10s %12s  %s\n' target exec/s executions result
for t in "${targets[@]}"; do
  dir=$work/$t
  mkdir -p "$dir/corpus"
  cp "$src/fuzz/corpus/$t/"* "$dir/corpus/"
  # -rss_limit_mb: the config target reads YAML through yaml-cpp, which may build large trees.
  if (cd "$dir" && "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -rss_limit_mb=4096 -print_final_stats=1 \
        -artifact_prefix="$dir/" corpus >"$dir/fuzz.log" 2>&1); then
    result=ok
  else
    result="FOUND: $(ls "$dir" | grep -E '^(crash|leak|timeout|oom|slow-unit)-' | tr '\n' ' ')"
    found=1
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/fuzz.log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$dir/fuzz.log")
  printf '%-14s %10s %12s  %s\n' "$t" "${rate:-?}" "${execs:-?}" "$result"
done
echo "logs, grown corpora and any crash-* files: $work/<target>/"
exit $found
