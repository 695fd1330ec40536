#!/usr/bin/env bash
# bench/ab_pairs.sh BUILD_A BUILD_B MESH... : two builds of parapm compared on one-thread
# simplifications, run in turn (A, B, A, B, ...), so that both see the same moments of a noisy
# machine. Per mesh, one TSV row: mesh, A's and B's median seconds (`parapm simplify --json`
# "seconds": the PM built in memory), the median of the pairs' ratios B / A, and whether the
# two wrote the same .pm bytes. With INSTRUCTIONS=1, each build also runs once under
# cachegrind, and the row adds both whole processes' instructions and mispredicted branches
# (cachegrind's simulation: free of the machine's timing noise, slow).
#
# BUILD_A and BUILD_B are build directories (holding bin/parapm). Environment: PAIRS (default
# 7), METRIC (default quadric), RATIO (default 0.02), THREADS (default 1), ARGS (more options
# for `parapm simplify`, e.g. "--parallel 16"), INSTRUCTIONS (default 0).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
if [[ $# -lt 3 ]]; then
  echo "usage: $0 BUILD_A BUILD_B MESH..." >&2
  exit 2
fi
a="$(PARAPM_BUILD_DIR="$1" parapm_program "$root")"
b="$(PARAPM_BUILD_DIR="$2" parapm_program "$root")"
shift 2
pairs="${PAIRS:-7}"
check_repeats "$pairs"
metric="${METRIC:-quadric}"
ratio="${RATIO:-0.02}"
threads="${THREADS:-1}"
read -r -a extra <<< "${ARGS:-}"
if [[ "${INSTRUCTIONS:-0}" == 1 ]] && ! command -v valgrind > /dev/null; then
  echo "$0: INSTRUCTIONS=1 needs valgrind" >&2
  exit 2
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Runs build $1 on mesh $2 writing $3; prints its "seconds".
seconds() {
  "$1" --log-level error simplify "$2" -o "$3" --metric "$metric" --ratio "$ratio" \
    --threads "$threads" "${extra[@]}" --json | jq -r .seconds
}

# Prints build $1's whole-process instructions and mispredicted branches on mesh $2.
instructions() {
  valgrind --tool=cachegrind --cache-sim=no --branch-sim=yes --cachegrind-out-file=/dev/null \
    "$1" --log-level error simplify "$2" -o "$work/cg.pm" --metric "$metric" --ratio "$ratio" \
    --threads "$threads" "${extra[@]}" 2>&1 >/dev/null |
    awk '/I *refs:/ {gsub(",", "", $4); ir = $4} /Mispredicts:/ {gsub(",", "", $3); bm = $3}
         END {printf "%s\t%s", ir, bm}'
}

header='mesh\ta_s\tb_s\tratio_b_over_a\tsame_pm'
[[ "${INSTRUCTIONS:-0}" == 1 ]] && header+='\ta_instructions\ta_mispredicts\tb_instructions\tb_mispredicts'
printf '%b\n' "$header"
for mesh in "$@"; do
  times_a=() times_b=() ratios=()
  for ((i = 0; i < pairs; i++)); do
    ta="$(seconds "$a" "$mesh" "$work/a.pm")"
    tb="$(seconds "$b" "$mesh" "$work/b.pm")"
    times_a+=("$ta") times_b+=("$tb")
    ratios+=("$(awk -v x="$ta" -v y="$tb" 'BEGIN {printf "%.6f", y / x}')")
  done
  same=no
  cmp -s "$work/a.pm" "$work/b.pm" && same=yes
  row="$(basename "$mesh")\t$(median <<< "${times_a[*]}")\t$(median <<< "${times_b[*]}")"
  row+="\t$(median <<< "${ratios[*]}")\t$same"
  [[ "${INSTRUCTIONS:-0}" == 1 ]] && row+="\t$(instructions "$a" "$mesh")\t$(instructions "$b" "$mesh")"
  printf '%b\n' "$row"
done
