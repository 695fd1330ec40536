#!/usr/bin/env bash
# Builds if needed (scripts/bootstrap.sh), then runs every test. When ../shared/meshes is
# present beside the clone, the tests also run over every mesh in it (the extended suite).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/bootstrap.sh"
build="${PARAPM_BUILD_DIR:-$root/build}"
if [[ -d "$root/../shared/meshes" ]]; then
  echo "[test] extended suite on: $(cd "$root/../shared/meshes" && pwd)" >&2
else
  echo "[test] ../shared/meshes absent: committed test meshes only" >&2
fi
ctest --test-dir "$build" --output-on-failure -j "${JOBS:-$(nproc)}"
