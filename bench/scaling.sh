#!/usr/bin/env bash
# bench/scaling.sh MESH... : the parallel build's time and memory against p (issue 37), as a
# user sees them: the process's wall clock from start to the .pm written, and its peak memory.
#
# For every MESH and metric of METRICS (default "energy quadric"), REPEATS (default 3) times:
# `parapm simplify MESH --ratio RATIO` (default 0.02) sequentially, then with `--parallel p`
# for every p of PS (default "2 4 8 16"; on min(p, cores) threads, or THREADS), each p timed
# against the sequential run of its own repeat (on a shared machine a build's time moves from
# one minute to the next). One TSV row per p: mesh, metric, p, threads, the medians of the
# sequential and parallel wall seconds, the median speed-up over the repeats (sequential /
# parallel) and its smallest and largest, the parallel run's build, critical-path and read +
# repair seconds (its --json), both runs' peak memory (MB, the process's maximum resident set)
# and their ratio.
# The large meshes: `build/bin/parapm-tile MESH OUT.ply --grid 2x2` (bench/tile_mesh.cpp), e.g.
# the 871k dragon tiled 2 x 2 (3.49M faces).
# ALL_ALIVE=1: every p on p threads with the process told it has p cores (the preloaded
# build/bin/libparapm-cores.so, bench/cores_shim.cpp), so that every job of a round is alive at
# once as on a p-core machine: for its peak memory; its times mean nothing on fewer cores.
# Environment: METRICS, PS, RATIO, REPEATS, THREADS, ALL_ALIVE, BENCH_OUT (default
# ./bench-out-scaling), PARAPM_BUILD_DIR (default build/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
[[ $# -ge 1 ]] || { echo "usage: $0 MESH..." >&2; exit 2; }
metrics="${METRICS:-energy quadric}"
ps="${PS:-2 4 8 16}"
ratio="${RATIO:-0.02}"
repeats="${REPEATS:-3}"
check_repeats "$repeats"
out="${BENCH_OUT:-$PWD/bench-out-scaling}"
bin="$(parapm_program "$root")"
command -v jq > /dev/null || { echo "$0 needs jq" >&2; exit 2; }
mkdir -p "$out"
cores_shim="$(dirname "$bin")/libparapm-cores.so"
if [[ "${ALL_ALIVE:-0}" == 1 && ! -f "$cores_shim" ]]; then
  echo "ALL_ALIVE=1 needs $cores_shim (build the parapm-cores target)" >&2
  exit 2
fi

# One run: prints "wall_seconds json" (the --json object on one line). With FAKE_CORES set,
# the process sees that many cores.
timed_run() {
  local t0 t1 json preload=()
  [[ -n "${FAKE_CORES:-}" ]] && preload=(env "LD_PRELOAD=$cores_shim" "FAKE_CORES=$FAKE_CORES")
  t0=$(date +%s.%N)
  json="$("${preload[@]}" "$bin" --log-level warn simplify "$@" --ratio "$ratio" --json | jq -c 'del(.parallel.round_stats)')"
  t1=$(date +%s.%N)
  echo "$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }') $json"
}
ratio_of() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.2f", a / b; else print "nan" }'; }
mb() { awk -v b="$1" 'BEGIN { printf "%.0f", b / 1048576 }'; }

printf 'mesh\tmetric\tp\tthreads\tseq_wall_s\tpar_wall_s\tspeedup\tspeedup_min\tspeedup_max'
printf '\tpar_build_s\tpar_critical_path_s\tpar_read_repair_s\tseq_peak_MB\tpar_peak_MB\tmemory_ratio\n'
thread_opt=()
[[ -n "${THREADS:-}" ]] && thread_opt=(--threads "$THREADS")
for mesh in "$@"; do
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  for metric in $metrics; do
    # Per repeat, the sequential build and then every p, each p's speed-up against the
    # sequential run of its own repeat.
    declare -A walls=() speedups=() peaks=() builds=() crits=() reads=() threads=()
    seqs=() seq_peaks=()
    for ((i = 0; i < repeats; i++)); do
      echo "[scaling] $name $metric sequential (repeat $((i + 1)) of $repeats)" >&2
      read -r seq_wall seq_json <<< "$(timed_run "$mesh" -o "$out/$name.$metric.seq.pm" \
        --metric "$metric")"
      seqs+=("$seq_wall")
      seq_peaks+=("$(jq -r .peak_memory_bytes <<< "$seq_json")")
      for p in $ps; do
        echo "[scaling] $name $metric p=$p" >&2
        fake_cores="" opts=("${thread_opt[@]}")
        if [[ "${ALL_ALIVE:-0}" == 1 ]]; then fake_cores="$p" opts=(--threads "$p"); fi
        read -r par_wall par_json <<< "$(FAKE_CORES="$fake_cores" timed_run "$mesh" \
          -o "$out/$name.$metric.p$p.pm" --metric "$metric" --parallel "$p" "${opts[@]}")"
        walls[$p]+=" $par_wall"
        speedups[$p]+=" $(ratio_of "$seq_wall" "$par_wall")"
        peaks[$p]+=" $(jq -r .peak_memory_bytes <<< "$par_json")"
        builds[$p]+=" $(jq -r .seconds <<< "$par_json")"
        crits[$p]+=" $(jq -r '.parallel.critical_path_seconds // 0' <<< "$par_json")"
        reads[$p]+=" $(jq -r '.read_seconds + .repair_seconds' <<< "$par_json")"
        threads[$p]="$(jq -r '.parallel.threads // 1' <<< "$par_json")"
      done
    done
    seq_wall="$(median <<< "${seqs[*]}")"
    seq_peak="$(median <<< "${seq_peaks[*]}")"
    for p in $ps; do
      sorted="$(tr ' ' '\n' <<< "${speedups[$p]}" | grep -v '^$' | sort -g)"
      par_peak="$(median <<< "${peaks[$p]}")"
      printf '%s\t%s\t%s\t%s\t%.3f\t%.3f\t%.2f\t%s\t%s\t%.3f\t%.3f\t%.3f\t%s\t%s\t%s\n' \
        "$name" "$metric" "$p" "${threads[$p]}" "$seq_wall" "$(median <<< "${walls[$p]}")" \
        "$(median <<< "${speedups[$p]}")" "$(head -1 <<< "$sorted")" "$(tail -1 <<< "$sorted")" \
        "$(median <<< "${builds[$p]}")" "$(median <<< "${crits[$p]}")" \
        "$(median <<< "${reads[$p]}")" "$(mb "$seq_peak")" "$(mb "$par_peak")" \
        "$(ratio_of "$par_peak" "$seq_peak")"
    done
    unset walls speedups peaks builds crits reads threads
  done
done
