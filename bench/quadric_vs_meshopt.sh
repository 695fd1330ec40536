#!/usr/bin/env bash
# bench/quadric_vs_meshopt.sh [MESH...] : the quadric's whole PM against meshoptimizer's
# simplification, one thread each, to RATIO of the faces (default 0.02), on every mesh (default:
# every mesh of ../shared/meshes): issue 37's "within 4x meshoptimizer's time on every shared
# mesh".
#
# Per mesh, REPEATS (default 3) runs of each in turn; prints one TSV row per mesh: mesh, input
# faces, ParaPM's seconds (`parapm simplify --json` "seconds": the whole PM built in memory, not
# reading, repair or writing), meshoptimizer's (its simplification call), their ratio (medians),
# and ParaPM's costings per input face. The last line: the geometric mean and the largest ratio.
# Environment: RATIO, REPEATS, PLACEMENT (`--quadric-placement`: auto, the default,
# constrained or free), PARAPM_BUILD_DIR (default build/), PEERS_BUILD (default ./.peers-build;
# built with ../shared/tools/build.sh when missing).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="$root/../shared"
# shellcheck source=bench/common.sh
source "$root/bench/common.sh"
ratio="${RATIO:-0.02}"
repeats="${REPEATS:-3}"
placement="${PLACEMENT:-auto}"
check_repeats "$repeats"
bin="$(parapm_program "$root")"
peers="${PEERS_BUILD:-$PWD/.peers-build}"
if [[ ! -x "$peers/peer-meshopt" ]]; then
  echo "[quadric_vs_meshopt] building the peers into $peers" >&2
  "$shared/tools/build.sh" "$peers" >&2
fi
if [[ $# -eq 0 ]]; then set -- "$shared"/meshes/*.{obj,off,ply,stl,gz}; fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

printf 'mesh\tfaces\tparapm_s\tmeshopt_s\tratio\tcostings_per_face\n'
for mesh in "$@"; do
  ours=() theirs=() faces=0 costings=0
  for ((i = 0; i < repeats; i++)); do
    json="$("$bin" --log-level error simplify "$mesh" -o "$work/pm.pm" --metric quadric \
      --quadric-placement "$placement" --ratio "$ratio" --json)"
    ours+=("$(jq -r .seconds <<< "$json")")
    faces="$(jq -r .in_faces <<< "$json")"
    costings="$(jq -r .costings <<< "$json")"
    theirs+=("$("$peers/peer-meshopt" "$mesh" "$work/out.obj" -r "$ratio" 2> /dev/null |
      jq -r .seconds)")
  done
  ours_s="$(echo "${ours[*]}" | median)"
  theirs_s="$(echo "${theirs[*]}" | median)"
  awk -v m="$(basename "$mesh")" -v f="$faces" -v o="$ours_s" -v t="$theirs_s" -v c="$costings" \
    'BEGIN { printf "%s\t%d\t%.4f\t%.4f\t%.1f\t%.1f\n", m, f, o, t, o / t, c / f }'
done | tee "$work/rows.tsv"
awk -F'\t' '{ s += log($5); n++; if ($5 > worst) { worst = $5; at = $1 } }
  END { if (n) printf "# %d meshes: geometric mean %.1fx, largest %.1fx (%s)\n", n, exp(s / n), worst, at }' \
  "$work/rows.tsv"
