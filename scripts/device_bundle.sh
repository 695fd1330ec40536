#!/usr/bin/env bash
# scripts/device_bundle.sh DIR MESH... : packs what issue 37's scaling benchmark needs into DIR,
# for a machine that has none of this project's packages (the tool library's many-core
# `device` machine): the parapm and parapm-tile programs and jq, with every shared library
# they load (the C library and its loader too, so that the machine's own do not matter), the
# MESHes, and the benchmark scripts. There, from the repository's root:
#
#   DIR/run bench/scaling.sh DIR/meshes/MESH ...
#
# runs the script with DIR's programs first on the PATH (PARAPM_BUILD_DIR pointing into DIR),
# each one started through DIR's loader with DIR's libraries. Needs the build/ programs
# (parapm, parapm-tile) and jq here. DIR is emptied first.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
[[ $# -ge 2 ]] || { echo "usage: $0 DIR MESH..." >&2; exit 2; }
dir="$1"
shift
build="${PARAPM_BUILD_DIR:-$root/build}"
programs=("$build/bin/parapm" "$build/bin/parapm-tile" "$(command -v jq)")
for p in "${programs[@]}"; do
  [[ -x "$p" ]] || { echo "$0: no $p (build parapm and parapm-tile; install jq)" >&2; exit 2; }
done
rm -rf --one-file-system "$dir"
mkdir -p "$dir/real" "$dir/lib" "$dir/bin/bin" "$dir/meshes"

# Every library the programs load, by ldd (the loader among them).
loader=""
for p in "${programs[@]}"; do
  cp "$p" "$dir/real/"
  while read -r lib; do
    [[ -n "$lib" ]] || continue
    cp -L "$lib" "$dir/lib/"
    [[ "$lib" == *ld-linux* ]] && loader="$(basename "$lib")"
  done < <(ldd "$p" | awk '/=>/ { print $3 } !/=>/ && /^[ \t]*\// { print $1 }')
done
[[ -n "$loader" ]] || { echo "$0: no dynamic loader among the libraries" >&2; exit 1; }

# Each program's wrapper: DIR's loader, DIR's libraries.
for p in "${programs[@]}"; do
  name="$(basename "$p")"
  cat > "$dir/bin/bin/$name" <<EOF
#!/usr/bin/env bash
here="\$(cd "\$(dirname "\$0")/../.." && pwd)"
exec "\$here/lib/$loader" --library-path "\$here/lib" "\$here/real/$name" "\$@"
EOF
  chmod +x "$dir/bin/bin/$name"
done
cat > "$dir/run" <<'EOF'
#!/usr/bin/env bash
# DIR/run COMMAND...: COMMAND with DIR's programs (PARAPM_BUILD_DIR=DIR/bin, jq on the PATH).
here="$(cd "$(dirname "$0")" && pwd)"
export PARAPM_BUILD_DIR="$here/bin" PATH="$here/bin/bin:$PATH"
exec "$@"
EOF
chmod +x "$dir/run"
for mesh in "$@"; do cp "$mesh" "$dir/meshes/"; done
du -sh "$dir"
