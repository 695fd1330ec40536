#!/usr/bin/env bash
# Builds if needed (scripts/bootstrap.sh), then runs every test. When ../shared/meshes is
# present beside the clone, the tests also run over every mesh in it (the extended suite).
# Under CI (CI=true), or with PARAPM_FUZZ_RUNS=N, the fuzz targets then run N inputs each
# (CI: 200000, a fixed seed) from their corpus (scripts/fuzz.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
fuzz_runs="${PARAPM_FUZZ_RUNS:-}"
if [[ -z "$fuzz_runs" && "${CI:-}" == true ]]; then fuzz_runs=200000; fi
PARAPM_WITH_FUZZ="$fuzz_runs" "$root/scripts/bootstrap.sh"
build="${PARAPM_BUILD_DIR:-$root/build}"
if [[ -d "$root/../shared/meshes" ]]; then
  echo "[test] extended suite on: $(cd "$root/../shared/meshes" && pwd)" >&2
else
  echo "[test] ../shared/meshes absent: committed test meshes only" >&2
fi
ctest --test-dir "$build" --output-on-failure -j "${JOBS:-$(nproc)}"
if [[ -n "$fuzz_runs" ]]; then "$root/scripts/fuzz.sh" "$fuzz_runs"; fi
