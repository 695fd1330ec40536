#!/usr/bin/env bash
# scripts/fuzz.sh [RUNS] : builds the fuzz targets with clang under ASan and UBSan into
# build-fuzz/ (PARAPM_FUZZ_BUILD_DIR), then runs each for RUNS inputs (default 200000, about
# 20 s each here) from the committed corpus (fuzz/corpus/) plus the engine's own encodings
# (parapm-fuzz-seeds), with the random seed PARAPM_FUZZ_SEED (default 1): the same run every
# time, so that CI's verdict can be reproduced. PARAPM_FUZZ_SEED=0 picks a new seed.
# Exits non-zero when a target finds a crash, a leak or undefined behaviour; the input that
# did is left in build-fuzz/crashes/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${PARAPM_FUZZ_BUILD_DIR:-$root/build-fuzz}"
runs="${1:-200000}"
if ! command -v clang++ > /dev/null; then
  echo "fuzz: clang++ is missing (Debian: clang, libclang-rt-dev)" >&2
  exit 1
fi
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DPARAPM_FUZZ=ON -DPARAPM_BUILD_TESTS=OFF \
    -DPARAPM_BUILD_SERVICE=OFF > /dev/null
fi
targets=(fuzz_mesh_reader fuzz_pm_reader fuzz_job_codec)
cmake --build "$build" -j "${JOBS:-$(nproc)}" --target "${targets[@]}" parapm-fuzz-seeds >&2
seeds="$build/seeds"
rm -rf "$seeds" && "$build/bin/parapm-fuzz-seeds" "$seeds"
mkdir -p "$build/crashes"
declare -A seed_dirs=([fuzz_mesh_reader]=mesh [fuzz_pm_reader]=pm [fuzz_job_codec]=job_codec)
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target"
  rm -rf "$corpus" && mkdir -p "$corpus"
  cp "$root/fuzz/corpus/${seed_dirs[$target]}"/* "$corpus/"
  for seed in "$seeds/${seed_dirs[$target]}"/*; do cp "$seed" "$corpus/fresh-$(basename "$seed")"; done
  echo "[fuzz] $target: $runs runs from $(find "$corpus" -type f | wc -l) seeds" >&2
  "$build/bin/$target" -runs="$runs" -seed="${PARAPM_FUZZ_SEED:-1}" -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$build/crashes/$target-" -print_final_stats=1 "$corpus" 2>&1 |
    grep -E "^(#[0-9]+ +DONE|INFO: seed corpus|==[0-9]+==ERROR|SUMMARY|stat::number_of_executed_units)" >&2 ||
    true
  if compgen -G "$build/crashes/$target-*" > /dev/null; then
    echo "[fuzz] $target failed: $(ls "$build/crashes/$target-"*)" >&2
    exit 1
  fi
done
echo "[fuzz] no crash, leak or undefined behaviour found" >&2
