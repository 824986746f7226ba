#!/usr/bin/env bash
# The main job: installs the dependencies, builds, starts drivegated on config/demo.yaml with
# simulated drives, and runs the demo client, which drives the axes through a short sequence
# while it shows them live. Ctrl-C stops the client; the daemon then stops and disables every
# axis and exits.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${DRIVEGATE_BUILD_DIR:-$root/build}
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh" "$build" -DDRIVEGATE_TESTS=OFF -DDRIVEGATE_BENCH=OFF

log=$(mktemp -t drivegated.XXXXXX.log)
"$build/daemon/drivegated" --config "$root/config/demo.yaml" 2>"$log" &
daemon=$!
stop_daemon() {
  if kill -0 "$daemon" 2>/dev/null; then
    kill -TERM "$daemon"
    wait "$daemon" || true
  fi
  echo "drivegated stopped; its log is in $log"
}
trap stop_daemon EXIT
trap 'exit 130' INT TERM
echo "drivegated started (pid $daemon, log $log)"
"$build/client/drivegate-demo" "$@"
