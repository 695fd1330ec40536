#!/usr/bin/env bash
# bench/service.sh MESH... : the service end to end against the in-process parallel build.
#
# Starts `parapm up` (a coordinator and WORKERS workers, default 2, of WORKER_THREADS threads,
# default 1, on loopback, fresh data folder), then for every MESH: `parapm submit MESH
# --parallel P --metric METRIC -o X.pm --json` (upload, job, download) and `parapm simplify
# MESH --parallel P --metric METRIC -o Y.pm` (read, build, write, in-process on min(P, cores)
# threads), and prints one TSV row: mesh, p, in-process wall s, service wall s (client: upload
# to end of download), its parts (upload, wait, download), the transport inside the job
# (coordinator reading the upload, encoding jobs, subset calls' time beyond the workers' own
# summed over calls, storing the PM), the MB of jobs and of results moved between coordinator
# and workers and their sum per input face (bytes), transport / service wall, service /
# in-process wall, whether both .pm files are byte-identical (they must be), and the share of
# the state the jobs left out, their workers holding it from a round before (quadrics, or the
# energy's points' positions). With REPEATS
# (default 1) above 1, each mesh is run that many times, in turn, and a last line ("# ...")
# gives the medians of both wall clocks and of their ratio.
# Environment: P (default 2), METRIC (default energy), WORKERS, WORKER_THREADS, REPEATS, PORT
# (default 50151), BENCH_OUT (default ./bench-out-service), PARAPM_BUILD_DIR (default build/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
[[ $# -ge 1 ]] || { echo "usage: $0 MESH..." >&2; exit 2; }
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
check_repeats "${REPEATS:-1}"
p="${P:-2}"
metric="${METRIC:-energy}"
workers="${WORKERS:-2}"
port="${PORT:-50151}"
out="${BENCH_OUT:-$PWD/bench-out-service}"
bin="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
[[ -x "$bin" ]] || { echo "no $bin (build parapm, parapm-coordinator, parapm-worker)" >&2; exit 2; }
command -v jq > /dev/null || { echo "bench/service.sh needs jq" >&2; exit 2; }
rm -rf "$out/data"
mkdir -p "$out"
"$bin" up --workers "$workers" --worker-threads "${WORKER_THREADS:-1}" --data "$out/data" \
  --listen "127.0.0.1:$port" --log-level warn 2> "$out/up.log" &
up_pid=$!
trap 'kill -INT $up_pid 2> /dev/null; wait $up_pid 2> /dev/null || true' EXIT
for _ in $(seq 100); do [[ -s "$out/data/coordinator.port" ]] && break; sleep 0.1; done
sleep 1  # the workers register
server=(--server "127.0.0.1:$port")
printf "mesh\tp\tinprocess_s\tservice_s\tupload_s\twait_s\tdownload_s\tread_s\tencode_s\tcall_overhead_s\tstore_s\tjob_MB\tresult_MB\tbytes_per_face\ttransport_share\tservice_over_inprocess\tidentical\theld_share\n"
for mesh in "$@"; do
  name="$(basename "$mesh")"; name="${name%%.*}"
  rows=""
  for _ in $(seq "${REPEATS:-1}"); do
    svc="$("$bin" --log-level warn submit "$mesh" --parallel "$p" --metric "$metric" \
      -o "$out/$name-service.pm" --json "${server[@]}")"
    job="$(jq -r .job_id <<< "$svc")"
    fin="$("$bin" watch "$job" --json "${server[@]}" | jq -c 'select(.finished) | .finished')"
    t0=$(date +%s.%N)
    "$bin" --log-level warn simplify "$mesh" --parallel "$p" --metric "$metric" \
      -o "$out/$name-local.pm" > /dev/null
    t1=$(date +%s.%N)
    same=no; cmp -s "$out/$name-service.pm" "$out/$name-local.pm" && same=yes
    faces="$("$bin" info "$out/$name-local.pm" --json | jq .input_faces)"
    row="$(jq -r --argjson fin "$fin" --arg mesh "$name" --arg p "$p" --arg local "$(echo "$t1 - $t0" | bc)" \
      --arg same "$same" --argjson faces "$faces" '
      ($fin.transport // {}) as $t
      | [($t.read_seconds // 0), ($t.encode_seconds // 0), ($t.call_overhead_seconds // 0),
         ($t.store_seconds // 0)] as $parts
      | (.client.upload_seconds + .client.download_seconds + ($parts | add)) as $moved
      | [$mesh, $p, ($local | tonumber | . * 1000 | round / 1000),
         (.client.total_seconds * 1000 | round / 1000),
         (.client.upload_seconds * 1000 | round / 1000), (.client.wait_seconds * 1000 | round / 1000),
         (.client.download_seconds * 1000 | round / 1000),
         ($parts[] | . * 1000 | round / 1000),
         ((($t.job_bytes // "0") | tonumber) / 1e6 | . * 10 | round / 10),
         ((($t.result_bytes // "0") | tonumber) / 1e6 | . * 10 | round / 10),
         (((($t.job_bytes // "0") | tonumber) + (($t.result_bytes // "0") | tonumber)) / $faces
          | round),
         ($moved / .client.total_seconds * 1000 | round / 1000),
         (.client.total_seconds / ($local | tonumber) * 1000 | round / 1000), $same,
         ((($t.held_items // "0") | tonumber) as $h | (($t.sent_items // "0") | tonumber) as $s
          | if $h + $s > 0 then ($h / ($h + $s) * 1000 | round / 1000) else 0 end)] | @tsv' <<< "$svc"
    )"
    printf "%s\n" "$row"
    rows+="$row"$'\n'
  done
  if [[ "${REPEATS:-1}" -gt 1 ]]; then
    printf "# %s: medians of %s runs: in-process %s s, service %s s, service / in-process %s\n" \
      "$name" "$REPEATS" "$(cut -f3 <<< "${rows%$'\n'}" | median)" \
      "$(cut -f4 <<< "${rows%$'\n'}" | median)" "$(cut -f16 <<< "${rows%$'\n'}" | median)"
  fi
done
