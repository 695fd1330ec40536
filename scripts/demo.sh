#!/usr/bin/env bash
# The embedded default: builds if needed, turns the bundled mesh into a Progressive Mesh,
# checks that it rebuilds the input exactly, writes levels of detail at 50%, 10% and 2% of
# the faces, and prints a summary table. Outputs go to out/ (or $PARAPM_OUT).
# Usage: scripts/demo.sh [MESH]   (default: the bundled tests/data/pymeshlab-bunny-textured-10k.obj)
# Runs in-process for now; the service issue moves it onto the coordinator and workers.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
mesh="${1:-$root/tests/data/pymeshlab-bunny-textured-10k.obj}"
out="${PARAPM_OUT:-$root/out}"
"$root/scripts/bootstrap.sh" 2> >(grep -vE '^\[|^ninja: no work' >&2 || true)
bin="${PARAPM_BUILD_DIR:-$root/build}/bin/parapm"
mkdir -p "$out"
name="$(basename "$mesh")"; name="${name%.gz}"; name="${name%.*}"
jget() { sed -nE "s/.*\"$2\":(\"?)([^,\"}]*)\1.*/\2/p" <<< "$1"; }

pm="$out/$name.pm"
summary="$("$bin" --log-level warn simplify "$mesh" -o "$pm" --json)"
in_faces="$(jget "$summary" in_faces)"
"$bin" --log-level warn check "$pm" --against "$mesh" > /dev/null \
  && lossless="yes (parapm check)" || lossless="NO"

metro=""
for dir in "${PEERS_BUILD:-}" "$root/.peers-build"; do
  [[ -n "$dir" && -x "$dir/metro" ]] && metro="$dir/metro" && break
done

printf '\nParaPM demo: %s\n' "$mesh"
printf 'Progressive Mesh %s: %s vertex splits over a %s-face base mesh, built in %.3f s; lossless: %s\n' \
  "$pm" "$(jget "$summary" vsplits)" "$(jget "$summary" base_faces)" "$(jget "$summary" seconds)" "$lossless"
printf '.pm %s bytes, binary PLY %s bytes\n\n' "$(jget "$summary" pm_bytes)" "$(jget "$summary" binary_ply_bytes)"
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
