#!/usr/bin/env bash
# bench/run.sh MESH... : ParaPM beside the peers of ../shared/tools, measured in one run.
#
# For every MESH and every ratio (RATIOS, default "0.5 0.1 0.02"; 0 is the whole PM, down to
# the smallest legal base mesh, the peers skip it) it runs
#   - parapm simplify --metric M --ratio R for every M of METRICS (default "quadric"; also
#     "energy"), the whole PM down to R, median of REPEATS runs, then metro on its base mesh;
#   - the peers (meshoptimizer, OpenMesh Decimater, CGAL Garland-Heckbert and Lindstrom-Turk)
#     through ../shared/tools/bench-peers.sh, with metro on their outputs;
# and prints one TSV table on stdout: mesh, tool, ratio, out_faces, seconds (simplification
# only, single thread), hausdorff_rel, rms_rel (metro, relative to the bbox diagonal),
# normal_mean_deg, for ParaPM the peak memory in bytes per input face, and the fraction of the
# output's triangles whose least angle is below 10 degrees (slivers; parapm-triangle-quality).
# Environment: RATIOS, REPEATS (default 3), METRICS, PEERS (default "meshopt openmesh cgal-gh
# cgal-lt"; "none" skips them),
# PEERS_BUILD (default ./.peers-build; built with ../shared/tools/build.sh when missing),
# BENCH_OUT (default ./bench-out), PARAPM_BUILD_DIR (default build/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="$root/../shared"
[[ $# -ge 1 ]] || { echo "usage: $0 MESH..." >&2; exit 2; }
ratios="${RATIOS:-0.5 0.1 0.02}"
metrics="${METRICS:-quadric}"
peer_ratios="$(tr ' ' '\n' <<< "$ratios" | grep -vx '0' | tr '\n' ' ' || true)"
repeats="${REPEATS:-3}"
out="${BENCH_OUT:-$PWD/bench-out}"
peers_build="${PEERS_BUILD:-$PWD/.peers-build}"
bin="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
export PEERS="${PEERS:-meshopt openmesh cgal-gh cgal-lt}"

[[ -x "$bin" ]] || "$root/scripts/bootstrap.sh" >&2
if [[ ! -x "$peers_build/metro" ]]; then
  echo "[bench] building the peers into $peers_build" >&2
  "$shared/tools/build.sh" "$peers_build" >&2
fi
mkdir -p "$out"
jget() { sed -nE "s/.*\"$2\":(\"?)([^,\"}]*)\1.*/\2/p" <<< "$1"; }
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"

quality="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm-triangle-quality"
[[ -x "$quality" ]] || { echo "no $quality (build the parapm-triangle-quality target)" >&2; exit 2; }
slivers() { "$quality" "$1" 2> /dev/null | sed -nE 's/.*"below_10_deg":([^,}]*).*/\1/p' || echo NA; }

printf 'mesh\ttool\tratio\tout_faces\tseconds\thausdorff_rel\trms_rel\tnormal_mean_deg\tbytes_per_face\tbelow_10_deg\n'
for mesh in "$@"; do
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  for metric in $metrics; do
    for ratio in $ratios; do
      pm="$out/$name.parapm-$metric.r$ratio.pm"
      base="$out/$name.parapm-$metric.r$ratio.ply"
      secs=""
      for ((i = 1; i <= repeats; i++)); do
        echo "[bench] $name parapm-$metric r=$ratio run $i/$repeats" >&2
        js="$("$bin" --log-level warn simplify "$mesh" -o "$pm" --metric "$metric" --ratio "$ratio" --json)"
        secs+=" $(jget "$js" seconds)"
      done
      "$bin" --log-level warn lod "$pm" --faces "$(jget "$js" base_faces)" -o "$base" > /dev/null
      m="$("$peers_build/metro" "$mesh" "$base" 2>/dev/null || echo '{}')"
      bpf=$(( $(jget "$js" peak_memory_bytes) / $(jget "$js" in_faces) ))
      printf '%s\tparapm-%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$metric" "$ratio" \
        "$(jget "$js" base_faces)" "$(echo $secs | median)" "$(jget "$m" hausdorff_rel)" \
        "$(jget "$m" rms_rel)" "$(jget "$m" normal_mean_deg)" "$bpf" "$(slivers "$base")"
    done
  done
  [[ "$PEERS" == none ]] && continue
  # shellcheck disable=SC2086
  PEERS_BUILD="$peers_build" PEERS_OUT="$out" REPEATS="$repeats" \
    "$shared/tools/bench-peers.sh" "$mesh" $peer_ratios |
    tail -n +2 | while IFS=$'\t' read -r -a f; do
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t-\t%s\n' "${f[0]}" "${f[1]}" "${f[2]}" "${f[3]}" \
        "${f[4]}" "${f[5]}" "${f[6]}" "${f[10]}" "$(slivers "$out/${f[0]}.${f[1]}.r${f[2]}.ply")"
    done
done
