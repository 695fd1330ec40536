#!/usr/bin/env bash
# bench/coordinator_memory.sh [JOBS] : the coordinator's resident memory (VmRSS) idle, and
# after JOBS jobs (default 30) on three test meshes built by one worker, one after the other
# (each submitted with --wait), the last one ended.
# Environment: PARAPM_BUILD_DIR (default build/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="${PARAPM_BUILD_DIR:-$root/build}/bin"
jobs="${1:-30}"
work="$(mktemp -d)"
trap 'kill $coordinator $worker 2> /dev/null || true; wait 2> /dev/null || true; rm -rf "$work"' EXIT
"$bin/parapm-coordinator" --listen 127.0.0.1:0 --data "$work/data" --port-file "$work/port" \
  --log-level warn 2> "$work/coordinator.log" &
coordinator=$!
while [[ ! -s "$work/port" ]]; do sleep 0.1; done
server="127.0.0.1:$(cat "$work/port")"
"$bin/parapm-worker" --coordinator "$server" --listen 127.0.0.1:0 --threads 2 --log-level warn \
  2> "$work/worker.log" &
worker=$!
sleep 1
rss() { awk '/VmRSS/ {printf "%.0f MB", $2 / 1024}' "/proc/$coordinator/status"; }
echo "idle: $(rss)"
meshes=(pymeshlab-colored-airplane-11k.ply stratocaster-9k.ply cad-cycloidal-43k.ply)
for ((i = 0; i < jobs; ++i)); do
  "$bin/parapm" submit "$root/tests/data/${meshes[i % 3]}" --server "$server" --parallel 2 \
    --min-subset-faces 2000 --ratio 0.1 --seed "$((i + 1))" --wait > /dev/null 2>&1
done
echo "after $jobs jobs: $(rss)"
