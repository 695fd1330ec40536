#!/usr/bin/env bash
# bench/partition.sh [MESH...] : the mesh partitioner, greedy vs bfs vs greedy+refine.
#
# For every MESH (default: the four Stanford dragons of ../shared/meshes, 11k, 48k, 203k and
# 871k faces), every P (PS, default "2 4 8 16") and every method (greedy = --algo greedy,
# bfs = --algo bfs, greedy+refine = --algo greedy --refine) it runs
#   parapm partition MESH -p P ... --json
# REPEATS times and prints one TSV table on stdout: mesh, faces (after repair, the sum of the
# subset sizes), p, method, seconds (median over the REPEATS runs; partitioning only, not
# reading or repair), stddev_faces, biggest_faces, ideal_faces, B_over_ideal (biggest / ideal),
# cut_faces, cut_edges, components (connected pieces of the subsets: total/max per subset).
# The metrics other than seconds come from the last run (a warning on stderr if they vary).
# Environment: PS, REPEATS (default 5), SEED (default 1), PARAPM_BUILD_DIR (default build/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="$root/../shared"
ps="${PS:-2 4 8 16}"
repeats="${REPEATS:-5}"
seed="${SEED:-1}"
bin="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
[[ $# -ge 1 ]] || set -- "$shared"/meshes/stanford-dragon-{res4-11k,res3-48k,res2-203k,871k}.ply.gz
[[ "$repeats" =~ ^[1-9][0-9]*$ ]] || { echo "$0: REPEATS must be a positive integer" >&2; exit 2; }

[[ -x "$bin" ]] || "$root/scripts/bootstrap.sh" >&2

# summarize: REPEATS JSON lines of `partition --json` on stdin -> the table's columns from
# faces onwards, minus p and method: faces, seconds, stddev, biggest, ideal, B/ideal,
# cut_faces, cut_edges, components.
if command -v python3 > /dev/null; then
  summarize() {
    python3 -c '
import json, statistics, sys
runs = [json.loads(l) for l in sys.stdin if l.strip()]
if not runs:
    sys.exit(1)
last = runs[-1]
key = lambda r: {k: v for k, v in r.items() if k != "seconds"}
if any(key(r) != key(last) for r in runs):
    print("[bench] warning: metrics differ between runs", file=sys.stderr)
c = last["components"]
print("\t".join([str(sum(last["subset_faces"])),
                 "%.6f" % statistics.median(r["seconds"] for r in runs),
                 "%.1f" % last["stddev_faces"], str(last["biggest_faces"]),
                 "%.1f" % last["ideal_faces"],
                 "%.3f" % (last["biggest_faces"] / last["ideal_faces"]),
                 str(last["cut_faces"]), str(last["cut_edges"]),
                 "%d/%d" % (sum(c), max(c))]))'
  }
elif command -v jq > /dev/null; then
  summarize() {
    jq -rs '(map(.seconds) | sort) as $s | ($s | length) as $n | .[-1] as $l
      | [($l.subset_faces | add),
         (if $n % 2 == 1 then $s[($n - 1) / 2] else ($s[$n / 2 - 1] + $s[$n / 2]) / 2 end),
         $l.stddev_faces, $l.biggest_faces, $l.ideal_faces, $l.biggest_faces / $l.ideal_faces,
         $l.cut_faces, $l.cut_edges,
         "\($l.components | add)/\($l.components | max)"] | @tsv' |
      awk -F'\t' '{printf "%s\t%.6f\t%.1f\t%s\t%.1f\t%.3f\t%s\t%s\t%s\n", $1, $2, $3, $4, $5, $6, $7, $8, $9}'
  }
else
  jget() { sed -nE "s/.*\"$2\":(\"?)([^,\"}]*)\1.*/\2/p" <<< "$1"; }
  jlist() { sed -nE "s/.*\"$2\":\[([^]]*)\].*/\1/p" <<< "$1" | tr ',' '\n'; }
  # shellcheck source=bench/common.sh
  source "$root/bench/common.sh"
  summarize() {
    local lines last
    lines="$(cat)"; last="$(tail -n 1 <<< "$lines")"
    printf '%s\t%s\t%.1f\t%s\t%.1f\t%s\t%s\t%s\t%s\n' \
      "$(jlist "$last" subset_faces | awk '{s+=$1} END{print s}')" \
      "$(while IFS= read -r l; do jget "$l" seconds; done <<< "$lines" | median)" \
      "$(jget "$last" stddev_faces)" "$(jget "$last" biggest_faces)" "$(jget "$last" ideal_faces)" \
      "$(awk -v b="$(jget "$last" biggest_faces)" -v i="$(jget "$last" ideal_faces)" 'BEGIN{printf "%.3f", b/i}')" \
      "$(jget "$last" cut_faces)" "$(jget "$last" cut_edges)" \
      "$(jlist "$last" components | awk '{s+=$1; if($1>m)m=$1} END{printf "%d/%d", s, m}')"
  }
fi

printf 'mesh\tfaces\tp\tmethod\tseconds\tstddev_faces\tbiggest_faces\tideal_faces\tB_over_ideal\tcut_faces\tcut_edges\tcomponents\n'
for mesh in "$@"; do
  name="$(basename "$mesh")"; name="${name%.[gG][zZ]}"; name="${name%.*}"
  for p in $ps; do
    for method in greedy bfs greedy+refine; do
      case "$method" in
        greedy) args=(--algo greedy) ;;
        bfs) args=(--algo bfs) ;;
        greedy+refine) args=(--algo greedy --refine) ;;
      esac
      echo "[bench] $name p=$p $method x$repeats" >&2
      row="$(for ((i = 1; i <= repeats; i++)); do
               "$bin" --log-level warn partition "$mesh" -p "$p" "${args[@]}" --seed "$seed" --json || exit
             done | summarize)"
      IFS=$'\t' read -r faces rest <<< "$row"
      printf '%s\t%s\t%s\t%s\t%s\n' "$name" "$faces" "$p" "$method" "$rest"
    done
  done
done
