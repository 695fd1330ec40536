#!/usr/bin/env bash
# bench/parallel.sh MESH... : the parallel construction (issue 5) against the sequential build.
#
# For every MESH, metric of METRICS (default "energy quadric") and p of PS (default "2 4") it
# builds the sequential PM and the parallel PM (--parallel p --rounds ROUNDS
# --handover-ratio HANDOVER; empty: the CLI's defaults) down to RATIO (default 0.01) of the
# faces, and prints one TSV row: mesh, metric, p, rounds performed, sequential wall and CPU
# seconds (the sequential build is single-threaded: its simplification wall time is its CPU),
# parallel wall seconds (a run on THREADS threads, default 0: min(p, hardware)), parallel CPU
# seconds (subsets, state export and master) from a run on one thread (on a shared VM a
# thread's CPU time grows when the host runs other work beside it; the .pm is the same
# whatever the thread count), CPU ratio, critical path (setup + per round partition,
# extraction, slowest subset CPU, merge, band pass + final pass + PM assembly, from the same
# one-thread run), the implied speed-up (sequential CPU / critical path), and for the levels at 50%,
# 10%, 2% of the input faces and the base mesh, metro's RMS and Hausdorff distances of the
# parallel level relative to the sequential level of the same face count (1.00: as good).
# With REPEATS=N (default 1) every p is timed N times, each time right after a sequential build
# of its own (the sequential time of the same minute: on a shared VM a build's time moves by
# 10-25% from one minute to the next), and the row gives the medians of the N pairs, plus the
# smallest and largest implied speed-ups (implied_min, implied_max); the metro columns come
# from the one PM (the same bytes every time).
# Environment: METRICS, PS, RATIO, ROUNDS, HANDOVER, THREADS (default 0), REPEATS, BENCH_OUT (default
# ./bench-out-parallel), PARAPM_BUILD_DIR (default build/), METRO (default the one bench/run.sh
# builds: $PEERS_BUILD/metro, PEERS_BUILD defaulting to ./.peers-build).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
[[ $# -ge 1 ]] || { echo "usage: $0 MESH..." >&2; exit 2; }
metrics="${METRICS:-energy quadric}"
ps="${PS:-2 4}"
ratio="${RATIO:-0.01}"
repeats="${REPEATS:-1}"
check_repeats "$repeats"
out="${BENCH_OUT:-$PWD/bench-out-parallel}"
bin="$(parapm_program "$root")"
metro="${METRO:-${PEERS_BUILD:-$PWD/.peers-build}/metro}"
[[ -x "$metro" ]] || { echo "no metro (set METRO, or run bench/run.sh once)" >&2; exit 2; }
par_opts=()
[[ -n "${ROUNDS:-}" ]] && par_opts+=(--rounds "$ROUNDS")
[[ -n "${HANDOVER:-}" ]] && par_opts+=(--handover-ratio "$HANDOVER")
mkdir -p "$out"
jget() { jq -r "$2" <<< "$1"; }  # JSON field by jq path
# metro of level N of PM against MESH: "rms hausdorff" (relative to the bbox diagonal)
level_error() {
  "$bin" --log-level warn lod "$2" --faces "$3" -o "$4" > /dev/null
  local m
  m="$("$metro" "$1" "$4" 2>/dev/null || echo '{}')"
  echo "$(jget "$m" .rms_rel) $(jget "$m" .hausdorff_rel)"
}
ratio_of() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.3f", a / b; else print "nan" }'; }

printf 'mesh\tmetric\tp\trounds\tseq_wall\tseq_cpu\tpar_wall\tpar_cpu\tcpu_ratio\tcritical_path\timplied_speedup\timplied_min\timplied_max'
for level in 50 10 2 base; do printf '\trms_%s\thausdorff_%s' "$level" "$level"; done
printf '\n'
for mesh in "$@"; do
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  for metric in $metrics; do
    seq_pm="$out/$name.$metric.seq.pm"
    echo "[parallel] $name $metric sequential" >&2
    sj="$("$bin" --log-level warn simplify "$mesh" -o "$seq_pm" --metric "$metric" --ratio "$ratio" --json)"
    in_faces="$(jget "$sj" .in_faces)"
    base_faces="$(jget "$sj" .base_faces)"
    seq_secs="$(jget "$sj" .seconds)"
    declare -A seq_err=()
    for level in 50 10 2 base; do
      n=$([[ $level == base ]] && echo "$base_faces" || echo $(( in_faces * level / 100 )))
      seq_err[$level]="$(level_error "$mesh" "$seq_pm" "$n" "$out/$name.$metric.seq.$level.ply")"
    done
    for p in $ps; do
      par_pm="$out/$name.$metric.p$p.pm"
      echo "[parallel] $name $metric p=$p" >&2
      seqs=() walls=() cpus=() cpu_ratios=() crits=() implied=()
      for ((i = 0; i < repeats; i++)); do
        s="$seq_secs"
        if ((i > 0)); then
          s="$(jget "$("$bin" --log-level warn simplify "$mesh" -o "$seq_pm" --metric "$metric" \
            --ratio "$ratio" --json)" .seconds)"
        fi
        wj="$("$bin" --log-level warn simplify "$mesh" -o "$par_pm" --metric "$metric" --ratio "$ratio" \
          --parallel "$p" "${par_opts[@]}" --threads "${THREADS:-0}" --json)"
        pj="$("$bin" --log-level warn simplify "$mesh" -o "$par_pm" --metric "$metric" --ratio "$ratio" \
          --parallel "$p" "${par_opts[@]}" --threads 1 --json)"
        seqs+=("$s") walls+=("$(jget "$wj" .seconds)") cpus+=("$(jget "$pj" .parallel.cpu_seconds)")
        cpu_ratios+=("$(ratio_of "${cpus[-1]}" "$s")")
        crits+=("$(jget "$pj" .parallel.critical_path_seconds)")
        implied+=("$(ratio_of "$s" "${crits[-1]}")")
      done
      par_base="$(jget "$pj" .base_faces)"
      rounds="$(jget "$pj" .parallel.rounds)"
      seq_med="$(median <<< "${seqs[*]}")"
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s' "$name" "$metric" "$p" "$rounds" \
        "$seq_med" "$seq_med" "$(median <<< "${walls[*]}")" "$(median <<< "${cpus[*]}")" \
        "$(median <<< "${cpu_ratios[*]}")" "$(median <<< "${crits[*]}")" \
        "$(median <<< "${implied[*]}")" "$(printf '%s\n' "${implied[@]}" | sort -g | head -1)" \
        "$(printf '%s\n' "${implied[@]}" | sort -g | tail -1)"
      for level in 50 10 2 base; do
        n=$([[ $level == base ]] && echo "$par_base" || echo $(( in_faces * level / 100 )))
        read -r prms phd <<< "$(level_error "$mesh" "$par_pm" "$n" "$out/$name.$metric.p$p.$level.ply")"
        read -r srms shd <<< "${seq_err[$level]}"
        printf '\t%s\t%s' "$(ratio_of "$prms" "$srms")" "$(ratio_of "$phd" "$shd")"
      done
      printf '\n'
    done
    unset seq_err
  done
done
