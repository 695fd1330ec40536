#!/usr/bin/env bash
# bench/fidelity.sh [MESH...] : ParaPM's levels beside CGAL Lindstrom-Turk (LT), judged by metro,
# on every mesh (default: every mesh of ../shared/meshes).
#
# For every mesh and ratio of RATIOS (default "0.5 0.1 0.02"):
#   - LT (../shared/tools peer-cgal) to that ratio of the input's faces, and metro on its output;
#     both kept in BENCH_OUT/lt and reused by later runs (LT does not change);
#   - for every metric of METRICS (default "quadric energy"), one sequential PM built down to
#     the smallest ratio, its level at LT's face count (the largest with at most that many
#     faces), and metro on it.
# Then bench/fidelity_table.py prints the table on stdout: per mesh and ratio, LT's RMS and
# Hausdorff distance (relative to the bounding-box diagonal), each metric's and its ratio to
# LT's; the geometric means per ratio and metric; and last the cells over issue 33's targets
# (RMS above 1.5x LT's and above 1e-5, Hausdorff above 2x LT's and above 1e-4), worst last.
# Meshes run JOBS at a time (default: the cores). Environment: RATIOS, METRICS, JOBS,
# BENCH_OUT (default ./bench-out-fidelity), PARAPM_BIN (default PARAPM_BUILD_DIR/bin/parapm,
# PARAPM_BUILD_DIR defaulting to build/), PEERS_BUILD
# (default ./.peers-build; built with ../shared/tools/build.sh when missing), SIMPLIFY_ARGS
# (extra options for parapm simplify).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="$root/../shared"
if [[ $# -eq 0 ]]; then set -- "$shared"/meshes/*.{obj,off,ply,stl,gz}; fi
export RATIOS="${RATIOS:-0.5 0.1 0.02}" METRICS="${METRICS-quadric energy}"
export SIMPLIFY_ARGS="${SIMPLIFY_ARGS:-}"
export OUT="${BENCH_OUT:-$PWD/bench-out-fidelity}"
export BIN="${PARAPM_BIN:-${PARAPM_BUILD_DIR:-$root/build}/bin/parapm}"
export PEERS="${PEERS_BUILD:-$PWD/.peers-build}"
[[ -z "$METRICS" || -x "$BIN" ]] || "$root/scripts/bootstrap.sh" >&2
if [[ ! -x "$PEERS/metro" || ! -x "$PEERS/peer-cgal" ]]; then
  echo "[fidelity] building the peers into $PEERS" >&2
  "$shared/tools/build.sh" "$PEERS" >&2
fi
mkdir -p "$OUT/lt" "$OUT/rows"

# One mesh: writes OUT/rows/NAME.tsv (mesh, ratio, tool, faces, rms_rel, hausdorff_rel).
one_mesh() {
  set -euo pipefail
  local mesh="$1" name ratio metric smallest
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  local rows="$OUT/rows/$name.tsv.tmp" work="$OUT/levels/$name"
  mkdir -p "$work"; : > "$rows"
  declare -A lt_faces
  metro_row() {  # ratio tool faces level-file
    "$PEERS/metro" "$mesh" "$4" --threads=1 2> /dev/null |
      jq -r --arg n "$name" --arg r "$1" --arg t "$2" --arg f "$3" \
        '[$n, $r, $t, $f, .rms_rel, .hausdorff_rel] | @tsv' >> "$rows"
  }
  for ratio in $RATIOS; do
    local lt="$OUT/lt/$name.r$ratio"
    if [[ ! -s "$lt.metro.json" ]]; then
      echo "[fidelity] $name LT r=$ratio" >&2
      "$PEERS/peer-cgal" "$mesh" "$lt.ply" -r "$ratio" 2> /dev/null > "$lt.json"
      "$PEERS/metro" "$mesh" "$lt.ply" --threads=1 2> /dev/null > "$lt.metro.json.tmp"
      mv "$lt.metro.json.tmp" "$lt.metro.json"
    fi
    lt_faces[$ratio]="$(jq -r .out_faces "$lt.json")"
    jq -r --arg n "$name" --arg r "$ratio" --arg f "${lt_faces[$ratio]}" \
      '[$n, $r, "lt", $f, .rms_rel, .hausdorff_rel] | @tsv' "$lt.metro.json" >> "$rows"
  done
  smallest="$(tr ' ' '\n' <<< "$RATIOS" | grep -v '^$' | sort -g | head -n 1)"
  for metric in $METRICS; do
    echo "[fidelity] $name $metric" >&2
    # shellcheck disable=SC2086
    "$BIN" --log-level error simplify "$mesh" -o "$work/$metric.pm" --metric "$metric" \
      --ratio "$smallest" $SIMPLIFY_ARGS > /dev/null
    for ratio in $RATIOS; do
      local level="$work/$metric.r$ratio.ply" faces
      faces="$("$BIN" --log-level error lod "$work/$metric.pm" --faces "${lt_faces[$ratio]}" \
        -o "$level" --json | jq -r .faces)"
      metro_row "$ratio" "$metric" "$faces" "$level"
    done
  done
  mv "$rows" "$OUT/rows/$name.tsv"
}
export -f one_mesh

names=()
for mesh in "$@"; do
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  rm -f "$OUT/rows/$name.tsv"; names+=("$OUT/rows/$name.tsv")
done
printf '%s\0' "$@" | xargs -0 -n 1 -P "${JOBS:-$(nproc)}" bash -c 'one_mesh "$1"' _ ||
  echo "[fidelity] some meshes failed: the table lists them at its end" >&2
python3 "$root/bench/fidelity_table.py" "${names[@]}"
