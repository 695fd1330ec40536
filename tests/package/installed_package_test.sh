#!/usr/bin/env bash
# The installed package as another project meets it: `cmake --install BUILD` into a fresh
# prefix, examples/cpp configured against that prefix alone (find_package(ParaPM)) and built,
# then run: parapm-example-levels builds a PM of a committed mesh (checked lossless by
# `parapm check`) and a glTF chain of levels; parapm-example-openmesh does it through OpenMesh
# and writes a level as .om, which parapm reads; parapm-example-submit (with the service) sends
# a mesh to a real coordinator on loopback and downloads its PM, checked the same way.
# Usage: installed_package_test.sh BUILD_DIR
set -euo pipefail
build="$(cd "$1" && pwd)"
root="$(cd "$(dirname "$0")/../.." && pwd)"
work="$(mktemp -d)"
coordinator=""
cleanup() {
  [[ -n "$coordinator" ]] && kill "$coordinator" 2> /dev/null && wait "$coordinator" 2> /dev/null
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$work/prefix" > "$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
cmake -S "$root/examples/cpp" -B "$work/examples" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log" 2>&1 \
  || { cat "$work/configure.log"; fail "the example project does not configure against the package"; }
cmake --build "$work/examples" > "$work/build.log" 2>&1 \
  || { cat "$work/build.log"; fail "the example project does not build against the package"; }
echo "examples built against $(find "$work/prefix" -type f | wc -l) installed files"

mesh="$root/tests/data/stratocaster-9k.ply"
"$work/examples/parapm-example-levels" "$mesh" "$work/out"
"$build/bin/parapm" --log-level warn check "$work/out/mesh.pm" --against "$mesh" \
  || fail "the example's PM does not rebuild its input"
[[ -s "$work/out/lods.glb" ]] || fail "no lods.glb"
"$work/examples/parapm-example-openmesh" "$mesh" "$work/out/level.om"
"$build/bin/parapm" --log-level warn simplify "$work/out/level.om" -o "$work/out/level.pm" \
  > /dev/null || fail "parapm does not read the .om the example wrote"

if [[ -x "$work/examples/parapm-example-submit" ]]; then
  "$build/bin/parapm-coordinator" --listen 127.0.0.1:0 --port-file "$work/port" \
    --data "$work/data" --local-threads 2 --log-level warn &
  coordinator=$!
  for _ in $(seq 100); do [[ -s "$work/port" ]] && break; sleep 0.1; done
  [[ -s "$work/port" ]] || fail "the coordinator did not start"
  mesh="$root/tests/data/cad-cycloidal-43k.ply"
  "$work/examples/parapm-example-submit" "127.0.0.1:$(cat "$work/port")" "$mesh" "$work/service.pm" > "$work/submit.log" \
    || { cat "$work/submit.log"; fail "parapm-example-submit"; }
  grep -q "^done: " "$work/submit.log" || { cat "$work/submit.log"; fail "no done event printed"; }
  "$build/bin/parapm" --log-level warn check "$work/service.pm" --against "$mesh" \
    || fail "the service's PM does not rebuild its input"
fi
echo "PASS"
