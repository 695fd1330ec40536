#!/usr/bin/env bash
# bench/viewer.sh [MESH...] : the viewer page's speed (issue 36's targets), per mesh: its PM
# built by a local service (`parapm up`, quadric, whole PM), then opened in headless Chromium
# over loopback (viewer/bench/viewer_bench.mjs): time to the first frame with the base mesh,
# to the whole PM, vsplits applied per second, slider moves of 100k vsplits. One TSV row per
# mesh (default: the 871k dragon of ../shared/meshes). Environment: PARAPM_BUILD_DIR (default
# build/), METRIC (default quadric), CHROMIUM.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bin="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
[[ $# -ge 1 ]] || set -- "$root/../shared/meshes/stanford-dragon-871k.ply.gz"
work="$(mktemp -d)"
"$bin" up --workers 1 --data "$work/data" --listen 127.0.0.1:0 --http 127.0.0.1:0 --log-level warn 2> "$work/up.log" &
up=$!
trap 'kill -INT $up 2> /dev/null; wait $up 2> /dev/null || true; rm -rf "$work"' EXIT
for _ in $(seq 300); do grep -q "viewer: " "$work/up.log" && grep -q "is up" "$work/up.log" && break; sleep 0.1; done
server="$(sed -nE 's/.*coordinator at ([^ ]+) .*/\1/p' "$work/up.log")"
url="$(sed -nE 's/^viewer: (.*)$/\1/p' "$work/up.log")"
header=1
for mesh in "$@"; do
  job="$("$bin" --log-level warn submit "$mesh" --metric "${METRIC:-quadric}" --server "$server" -o "$work/x.pm" --json |
    sed -nE 's/.*"job_id":"([^"]+)".*/\1/p')"
  row="$(node "$root/viewer/bench/viewer_bench.mjs" "$url" "$job")"
  if [[ $header == 1 ]]; then printf 'mesh\t%s\n' "$(head -n 1 <<< "$row")"; header=0; fi
  printf '%s\t%s\n' "$(basename "$mesh")" "$(tail -n 1 <<< "$row")"
done
