#!/usr/bin/env bash
# Checks what deploy/ ships, offline (CI runs it after scripts/test.sh):
# 1. Kubernetes: `kubectl kustomize` renders the base and every overlay, and every object
#    validates against the Kubernetes schemas, strictly (deploy/tools/validate-k8s.mjs:
#    kubernetes-models, pinned by deploy/tools/package-lock.json).
# 2. systemd: `systemd-analyze verify` is clean on both units (a copy whose ExecStart names the
#    programs built in build/bin, since verify needs them to exist).
# 3. compose: docker-compose (Debian's) validates deploy/compose.yaml.
# 4. the image: deploy/image/build.sh builds it (podman build --isolation chroot) and
#    deploy/image/test.sh runs a real job with it; skipped, saying so, where podman cannot be
#    had or does not work (or PARAPM_SKIP_IMAGE=1).
# Installs what is missing through apt-get (root) and npm ci, as scripts/bootstrap.sh does.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${PARAPM_BUILD_DIR:-$root/build}"
passed=0; failed=0; skipped=0
say() { echo "[deploy] $*" >&2; }
pass() { say "PASS $1 ($(( SECONDS - t0 )) s)"; passed=$((passed + 1)); }
fail() { say "FAIL $1"; failed=$((failed + 1)); }
skip() { say "SKIP $1"; skipped=$((skipped + 1)); }
apt_install() {
  [[ $(id -u) -eq 0 ]] || { say "cannot install $* (not root)"; return 1; }
  say "installing $*"
  apt-get update -qq > /dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
    --no-install-recommends "$@" > /dev/null
}
tmp="$(mktemp -d)"
trap 'rm -rf --one-file-system "$tmp"' EXIT

# 1. Kubernetes manifests.
t0=$SECONDS
tools="$root/deploy/tools"
if [[ ! -d "$tools/node_modules" || "$tools/package-lock.json" -nt "$tools/node_modules" ]]; then
  (cd "$tools" && npm ci --no-audit --no-fund --loglevel=error > /dev/null)
fi
k8s_ok=1
command -v kubectl > /dev/null \
  || { say "kubectl is absent (this kind of machine comes with it; Debian 12 does not package it)"; k8s_ok=0; }
for dir in "$root/deploy/kubernetes/base" "$root"/deploy/kubernetes/overlays/*/; do
  name="${dir#"$root/deploy/kubernetes/"}"; name="${name%/}"
  out="$tmp/$(tr / - <<< "$name").yaml"
  if ! kubectl kustomize "$dir" > "$out"; then say "kubectl kustomize $name failed"; k8s_ok=0; continue; fi
  if node "$tools/validate-k8s.mjs" "$out" > "$tmp/validate.log" 2>&1; then
    say "  $name: $(tail -1 "$tmp/validate.log")"
  else
    cat "$tmp/validate.log" >&2; k8s_ok=0
  fi
done
if [[ $k8s_ok -eq 1 ]]; then pass "kubernetes: rendered and valid"; else fail "kubernetes manifests"; fi

# 2. systemd units.
t0=$SECONDS
units="$tmp/units"
mkdir -p "$units"
units_ok=1
for f in parapm-coordinator.service parapm-worker@.service; do
  sed "s#/usr/local/bin/#$build/bin/#" "$root/deploy/systemd/$f" > "$units/$f"
  grep -q "^ExecStart=$build/bin/parapm-" "$units/$f" || { say "$f: no ExecStart in /usr/local/bin"; units_ok=0; }
done
ln -s parapm-worker@.service "$units/parapm-worker@1.service"
if [[ $units_ok -eq 0 ]]; then
  fail "systemd: units"
elif [[ ! -x "$build/bin/parapm-coordinator" || ! -x "$build/bin/parapm-worker" ]]; then
  fail "systemd: no $build/bin/parapm-coordinator and parapm-worker to verify against (build first)"
elif verify="$(cd "$units" && systemd-analyze verify ./parapm-coordinator.service ./parapm-worker@1.service 2>&1)" \
    && [[ -z "$verify" ]]; then
  pass "systemd: units verify clean"
else
  echo "$verify" >&2; fail "systemd-analyze verify"
fi

# 3. compose file.
t0=$SECONDS
if command -v docker-compose > /dev/null || apt_install docker-compose; then
  if PARAPM_TOKEN=check docker-compose -f "$root/deploy/compose.yaml" config -q; then
    pass "compose: deploy/compose.yaml valid (docker-compose $(docker-compose version --short))"
  else
    fail "compose: docker-compose config"
  fi
else
  skip "compose: docker-compose could not be installed: deploy/compose.yaml not validated"
fi

# 4. The image: build and a real job.
t0=$SECONDS
if [[ -n "${PARAPM_SKIP_IMAGE:-}" ]]; then
  skip "image: PARAPM_SKIP_IMAGE is set: the image is neither built nor tested"
elif [[ $(id -u) -ne 0 ]]; then
  skip "image: needs root (podman build --isolation chroot, debootstrap, chroot): not built, not tested"
elif ! { command -v podman > /dev/null && command -v debootstrap > /dev/null \
    && command -v curl > /dev/null && command -v python3 > /dev/null; } \
    && ! apt_install podman debootstrap curl python3; then
  skip "image: podman, debootstrap, curl or python3 could not be installed: not built, not tested"
elif ! podman info > /dev/null 2>&1; then
  skip "image: podman does not work here (podman info fails): not built, not tested"
else
  if "$root/deploy/image/build.sh" parapm:latest; then
    say "  image built in $(( SECONDS - t0 )) s"
    t1=$SECONDS
    if "$root/deploy/image/test.sh" parapm:latest; then
      say "  image tested in $(( SECONDS - t1 )) s"
      pass "image: built, $(podman image inspect --format '{{.Size}}' parapm:latest \
        | awk '{ printf "%.1f MB", $1 / 1e6 }'), a real job passes"
    else
      fail "image: deploy/image/test.sh"
    fi
  else
    fail "image: deploy/image/build.sh"
  fi
fi

echo "deploy checks: $passed passed, $failed failed, $skipped skipped"
[[ $failed -eq 0 ]]
