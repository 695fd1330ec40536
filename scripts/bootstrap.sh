#!/usr/bin/env bash
# Installs the Debian packages ParaPM needs (only those missing; apt-get, as root or through
# sudo), then configures and builds a Release build into build/ (ccache when present).
# PARAPM_WITH_FUZZ=1 also installs what the fuzz targets need (scripts/fuzz.sh).
# Safe to run again: it only does what is missing. JOBS=N limits the compile jobs.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${PARAPM_BUILD_DIR:-$root/build}"

pkgs=(cmake ninja-build g++ ccache libeigen3-dev libspdlog-dev libfmt-dev libcli11-dev
      nlohmann-json3-dev zlib1g-dev libdeflate-dev libgrpc++-dev libprotobuf-dev protobuf-compiler
      protobuf-compiler-grpc libsqlite3-dev libssl-dev libgtest-dev libgmock-dev
      pkg-config libcpp-httplib-dev prometheus-cpp-dev libopenmesh-dev python3 python3-grpcio
      python3-protobuf chromium)
# Node.js runs the viewer's tests (a machine may have its own Node.js, with npm, installed
# outside Debian's packages: then nothing is added).
if ! command -v node > /dev/null; then pkgs+=(nodejs npm)
elif ! command -v npm > /dev/null; then pkgs+=(npm); fi
# The fuzz targets (scripts/fuzz.sh) need clang and its libFuzzer runtime.
if [[ -n "${PARAPM_WITH_FUZZ:-}" ]]; then pkgs+=(clang libclang-rt-14-dev); fi
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [[ ${#missing[@]} -gt 0 ]]; then
  if [[ $(id -u) -eq 0 ]]; then sudo=()
  elif command -v sudo > /dev/null; then sudo=(sudo)
  else echo "bootstrap: missing packages ${missing[*]} and no root or sudo to install them" >&2; exit 1; fi
  echo "[bootstrap] installing ${missing[*]}" >&2
  "${sudo[@]}" apt-get update -qq > /dev/null
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" > /dev/null
fi

# The JavaScript test dependencies (the viewer's, the glTF validator), as the committed
# lockfiles pin them.
for js in viewer tests/gltf; do
  if [[ ! -d "$root/$js/node_modules" || "$root/$js/package-lock.json" -nt "$root/$js/node_modules" ]]; then
    echo "[bootstrap] npm ci in $js/" >&2
    (cd "$root/$js" && npm ci --no-audit --no-fund > /dev/null)
  fi
done

if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
fi
echo "[bootstrap] building into $build" >&2
cmake --build "$build" -j "${JOBS:-$(nproc)}" >&2
