#!/usr/bin/env bash
# The embedded default: builds if needed, starts the service on this machine (`parapm up`: a
# coordinator and two workers on loopback, data in out/service-data), submits the bundled
# mesh (`parapm submit`: upload, parallel build on the workers, download; with
# `--min-subset-faces 2000`, since by default the quadric builds a mesh this small in one pass
# on the coordinator, its rounds costing more than they save below 8000 faces a subset), checks
# that the
# Progressive Mesh rebuilds the input exactly, writes levels of detail at 50%, 10% and 2% of
# the faces, prints the job's events and a summary table, and stops the service.
# Outputs go to out/ (or $PARAPM_OUT).
# Usage: scripts/demo.sh [MESH]   (default: the bundled tests/data/pymeshlab-bunny-textured-10k.obj)
# Environment: PARAPM_DEMO_PORT (default 50051), PARAPM_DEMO_WORKERS (default 2).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
mesh="${1:-$root/tests/data/pymeshlab-bunny-textured-10k.obj}"
out="${PARAPM_OUT:-$root/out}"
"$root/scripts/bootstrap.sh" 2> >(grep -vE '^\[|^ninja: no work' >&2 || true)
bin="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
mkdir -p "$out"
name="$(basename "$mesh")"; name="${name%.gz}"; name="${name%.*}"
jget() { sed -nE "s/.*\"$2\":(\"?)([^,\"}]*)\1.*/\2/p" <<< "$1"; }

# The service, in the background for the length of the demo.
port="${PARAPM_DEMO_PORT:-50051}"
server=(--server "127.0.0.1:$port")
rm -f "$out/service-data/coordinator.port"
"$bin" up --workers "${PARAPM_DEMO_WORKERS:-2}" --data "$out/service-data" \
  --listen "127.0.0.1:$port" --http 127.0.0.1:0 --log-level warn 2> "$out/service.log" &
up_pid=$!
trap 'kill -INT $up_pid 2> /dev/null; wait $up_pid 2> /dev/null || true' EXIT
for _ in $(seq 100); do
  [[ -s "$out/service-data/coordinator.port" ]] && break
  kill -0 $up_pid 2> /dev/null || { cat "$out/service.log" >&2; echo "demo: the service did not start (port $port busy? set PARAPM_DEMO_PORT)" >&2; exit 2; }
  sleep 0.1
done
sleep 0.5  # the workers register

pm="$out/$name.pm"
job="$("$bin" --log-level warn submit "$mesh" --min-subset-faces 2000 -o "$pm" --json "${server[@]}")"
job_id="$(jget "$job" job_id)"
in_faces="$(jget "$job" input_faces)"
"$bin" --log-level warn check "$pm" --against "$mesh" > /dev/null \
  && lossless="yes (parapm check)" || lossless="NO"

metro=""
for dir in "${PEERS_BUILD:-}" "$root/.peers-build"; do
  [[ -n "$dir" && -x "$dir/metro" ]] && metro="$dir/metro" && break
done

printf '\nParaPM demo: %s, through the service at 127.0.0.1:%s (log: %s)\n\n' "$mesh" "$port" "$out/service.log"
"$bin" watch "$job_id" "${server[@]}" | grep -vE 'progress|queued|started on' | sed 's/^/  /'
printf '\nProgressive Mesh %s (job %s): %s vertex splits over a %s-face base mesh, built in %.3f s; lossless: %s\n' \
  "$pm" "$job_id" "$(jget "$job" vsplits)" "$(jget "$job" base_faces)" "$(jget "$job" seconds)" "$lossless"
printf '.pm %s bytes\n\n' "$(jget "$job" pm_bytes)"
header="%-8s %10s %10s %12s %14s"
[[ -n "$metro" ]] && header+=" %14s %14s"
printf "$header\n" level faces_in faces_out seconds bound/diag ${metro:+rms/diag hausdorff/diag}
for pct in 50 10 2; do
  faces=$(( in_faces * pct / 100 ))
  lod="$out/$name.lod$pct.obj"
  info="$("$bin" --log-level warn lod "$pm" --faces "$faces" -o "$lod" --json)"
  bound_rel="$(awk -v e="$(jget "$info" error_bound)" -v d="$(jget "$info" bbox_diagonal)" 'BEGIN { printf "%.3g", (d > 0 ? e / d : 0) }')"
  row=("$pct%" "$in_faces" "$(jget "$info" faces)" "$(printf '%.3f' "$(jget "$info" seconds)")" "$bound_rel")
  if [[ -n "$metro" ]]; then
    m="$("$metro" "$mesh" "$lod" 2>/dev/null || true)"
    row+=("$(jget "$m" rms_rel)" "$(jget "$m" hausdorff_rel)")
  fi
  printf "$header\n" "${row[@]}"
done
printf '\nseconds: time to read the .pm, cut the level and write it. bound/diag: the PM'"'"'s own\n'
printf 'error bound for that level (RMS distance to the collapsed planes) over the bounding-box\n'
printf 'diagonal.\n'
[[ -n "$metro" ]] && printf 'rms/diag, hausdorff/diag: measured by metro, the independent judge of ../shared/tools.\n'
[[ -z "$metro" ]] && printf 'For measured errors, build the judge: ../shared/tools/build.sh .peers-build\n'
printf 'Levels of detail written to %s/%s.lod{50,10,2}.obj\n' "$out" "$name"
