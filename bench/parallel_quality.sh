#!/usr/bin/env bash
# bench/parallel_quality.sh MESH... : how close the parallel PM's levels are to the sequential
# PM's (issue 5's quality target), over many meshes at once.
#
# For every MESH it builds the sequential PM of METRIC (default energy) once (kept in BENCH_OUT
# and reused by later runs with the same LABEL-free name), then the parallel PM for every p of
# PS (default "2 4 8 16") with the extra options PAR_ARGS (e.g. "--border-excess 0"), and
# prints one TSV row per mesh and p: metro's RMS and Hausdorff of the parallel level over the
# sequential level of the same face count at 50%, 10% and 2% of the input faces and at the
# base (at the larger of the two base meshes' face counts: the base of one, a level of the
# other) (1.000: as good), the rounds performed, the parallel build's seconds and its work (CPU
# over the sequential build's CPU: the median over WORK_REPEATS pairs, default 3, of a parallel build and a
# sequential build timed one after the other, so that both see the machine of the same minute;
# a sequential time kept from another run made the small meshes' work swing by 30%, their
# builds lasting a fifth of a second), and its costings (the edges all its modules costed over
# the sequential build's: the same work without the machine's noise, which still moves a
# small mesh's pairs by 10-30% from one run to the next). A summary per p follows on
# stderr and in BENCH_OUT/LABEL.summary: geometric means over the meshes, cells above 1.15
# (costings), 1.05 (RMS) and 1.10 (Hausdorff), the worst cell.
# Timing is not the point here (see bench/parallel.sh): meshes run JOBS at a time (default 2).
# Environment: METRIC, PS, RATIO (default 0.01), PAR_ARGS, LABEL (default "default"), JOBS,
# WORK_REPEATS (default 3),
# BENCH_OUT (default ./bench-out-quality), PARAPM_BUILD_DIR (default build/), METRO (default
# $PEERS_BUILD/metro, PEERS_BUILD defaulting to ./.peers-build).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
[[ $# -ge 1 ]] || { echo "usage: $0 MESH..." >&2; exit 2; }
export METRIC="${METRIC:-energy}" PS="${PS:-2 4 8 16}" RATIO="${RATIO:-0.01}"
export PAR_ARGS="${PAR_ARGS:-}" LABEL="${LABEL:-default}" WORK_REPEATS="${WORK_REPEATS:-3}"
export OUT="${BENCH_OUT:-$PWD/bench-out-quality}"
export BIN="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
export METRO="${METRO:-${PEERS_BUILD:-$PWD/.peers-build}/metro}"
[[ -x "$BIN" ]] || { echo "no $BIN (build the parapm target)" >&2; exit 2; }
[[ -x "$METRO" ]] || { echo "no metro (set METRO, or build ../shared/tools)" >&2; exit 2; }
mkdir -p "$OUT"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
export -f median

one_mesh() {
  set -euo pipefail
  local mesh="$1" name
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  # "rms hausdorff" of level N of a PM against the mesh; fails, saying why, when lod or metro
  # does (a missing figure must not read as an error of 0)
  level_error() {
    local figures
    "$BIN" --log-level warn lod "$1" --faces "$2" -o "$3" > /dev/null
    figures="$("$METRO" "$mesh" "$3" 2> "$3.metro-err" | jq -r '"\(.rms_rel) \(.hausdorff_rel)"')" ||
      true
    if [[ ! "$figures" =~ ^[0-9.e+-]+\ [0-9.e+-]+$ ]]; then
      echo "[parallel_quality] $name: metro on level $2 of $1 gave no figures: $(cat "$3.metro-err")" >&2
      return 1
    fi
    rm -f "$3.metro-err"
    echo "$figures"
  }
  local seq_pm="$OUT/$name.$METRIC.seq.pm" seq_json="$OUT/$name.$METRIC.seq.json"
  if [[ ! -s "$seq_json" ]]; then
    "$BIN" --log-level warn simplify "$mesh" -o "$seq_pm" --metric "$METRIC" --ratio "$RATIO" \
      --json > "$seq_json.tmp"
    mv "$seq_json.tmp" "$seq_json"
  fi
  local in_faces level n
  in_faces="$(jq -r .in_faces "$seq_json")"
  declare -A seq_err
  for level in 50 10 2; do
    n=$(( in_faces * level / 100 ))
    local cache="$OUT/$name.$METRIC.seq.$level.err"
    [[ -s "$cache" ]] || level_error "$seq_pm" "$n" "$OUT/$name.$METRIC.seq.$level.ply" > "$cache"
    seq_err[$level]="$(cat "$cache")"
  done
  local p
  for p in $PS; do
    local par_pm="$OUT/$name.$METRIC.$LABEL.p$p.pm" pj
    # shellcheck disable=SC2086
    pj="$("$BIN" --log-level warn simplify "$mesh" -o "$par_pm" --metric "$METRIC" --ratio "$RATIO" \
      --parallel "$p" --threads 1 $PAR_ARGS --json)"
    local row
    # work: the parallel build's CPU (jobs, merges, passes) over the sequential build's CPU
    # (not its wall time, which counts waits for a busy machine), each pair timed together;
    # the median of the pairs' ratios
    local ratios="" r par_cpu seq_s seq_json_now seq_costings=""
    par_cpu="$(jq .parallel.cpu_seconds <<< "$pj")"
    for ((r = 0; r < WORK_REPEATS; r++)); do
      if ((r > 0)); then
        # shellcheck disable=SC2086
        par_cpu="$("$BIN" --log-level warn simplify "$mesh" -o "$par_pm.time" --metric "$METRIC" \
          --ratio "$RATIO" --parallel "$p" --threads 1 $PAR_ARGS --json | jq .parallel.cpu_seconds)"
      fi
      seq_json_now="$("$BIN" --log-level warn simplify "$mesh" -o "$par_pm.time" \
        --metric "$METRIC" --ratio "$RATIO" --json)"
      seq_s="$(jq .cpu_seconds <<< "$seq_json_now")"
      seq_costings="$(jq .costings <<< "$seq_json_now")"
      ratios+="$(jq -n --argjson a "$par_cpu" --argjson b "$seq_s" '$a / $b') "
    done
    rm -f "$par_pm.time"
    # costings: the edges the parallel build's modules costed over the sequential build's
    # (deterministic: the work without the machine's noise)
    row="$(printf '%s\t%s\t%s\t%s\t%.2f\t%.2f\t%.3f' "$name" "$LABEL" "$p" \
      "$(jq -r .parallel.rounds <<< "$pj")" "$(jq -r .seconds <<< "$pj")" \
      "$(median <<< "$ratios")" \
      "$(jq -n --argjson a "$(jq .parallel.costings <<< "$pj")" --argjson b "$seq_costings" \
        '$a / $b')")"
    # The base: both PMs at the larger base (a parallel build may stop a few faces apart).
    local seq_base par_base
    seq_base="$(jq -r .base_faces "$seq_json")"
    par_base="$(jq -r .base_faces <<< "$pj")"
    local base_n=$(( seq_base > par_base ? seq_base : par_base ))
    local base_cache="$OUT/$name.$METRIC.seq.base$base_n.err"
    [[ -s "$base_cache" ]] ||
      level_error "$seq_pm" "$base_n" "$OUT/$name.$METRIC.seq.base$base_n.ply" > "$base_cache"
    seq_err[base]="$(cat "$base_cache")"
    for level in 50 10 2 base; do
      if [[ "$level" == base ]]; then n=$base_n; else n=$(( in_faces * level / 100 )); fi
      local prms phd srms shd
      local figures
      figures="$(level_error "$par_pm" "$n" "$OUT/$name.$METRIC.$LABEL.p$p.$level.ply")"
      read -r prms phd <<< "$figures"
      read -r srms shd <<< "${seq_err[$level]}"
      row+="$(awk -v a="$prms" -v b="$srms" -v c="$phd" -v d="$shd" \
        'BEGIN { printf "\t%.3f\t%.3f", (b > 0 ? a / b : 1), (d > 0 ? c / d : 1) }')"
    done
    printf '%s\n' "$row"
    rm -f "$par_pm" "$OUT/$name.$METRIC.$LABEL.p$p".*.ply
  done
}
export -f one_mesh

tsv="$OUT/$LABEL.tsv"
printf 'mesh\tlabel\tp\trounds\tseconds\twork\tcostings\trms_50\thd_50\trms_10\thd_10\trms_2\thd_2\trms_base\thd_base\n' |
  tee "$tsv"
printf '%s\n' "$@" | xargs -P "${JOBS:-2}" -I{} bash -c 'one_mesh "$1"' _ {} | tee -a "$tsv"

# Geometric means per p and level; cells above 1.05 (RMS) / 1.10 (Hausdorff); the worst.
awk -F'\t' 'NR > 1 {
    p = $3; n[p]++; lw[p] += log($6); lc[p] += log($7); sr[p] += $4
    if ($7 > 1.15) cc[p]++
    for (k = 0; k < 4; k++) {
      r = $(8 + 2 * k); h = $(9 + 2 * k)
      lr[p, k] += log(r); lh[p, k] += log(h)
      if (r > 1.05) cr[p, k]++
      if (h > 1.10) ch[p, k]++
      if (r > wr[p, k]) { wr[p, k] = r; wm[p, k] = $1 }
    }
  }
  END {
    split("50% 10% 2% base", lv, " ")
    for (p in n) {
      line = sprintf("p = %s (%d meshes): rounds %.1f, work %.2f, costings %.3f (%d above 1.15);",
        p, n[p], sr[p] / n[p], exp(lw[p] / n[p]), exp(lc[p] / n[p]), cc[p])
      for (k = 0; k < 4; k++)
        line = line sprintf("  %s RMS %.3f (%d above 1.05, worst %.3f %s), Hausdorff %.3f (%d above 1.1)",
          lv[k + 1], exp(lr[p, k] / n[p]), cr[p, k], wr[p, k], wm[p, k], exp(lh[p, k] / n[p]), ch[p, k])
      print line
    }
  }' "$tsv" | sort | tee "$OUT/$LABEL.summary" >&2
