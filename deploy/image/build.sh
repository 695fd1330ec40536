#!/usr/bin/env bash
# Builds the ParaPM container image (deploy/image/Containerfile) with podman.
# No registry serves base images here, so the base is made from Debian's own packages: when
# the local image parapm-base:bookworm is missing, `debootstrap --variant=minbase bookworm`
# fills a folder that is imported as that image (trimmed like Debian's slim images: no docs,
# man pages or locales). Installs podman and debootstrap through apt-get when missing (root).
# The build stage compiles with ccache in a build cache (RUN --mount=type=cache), which
# podman keeps between builds on this machine.
# Usage: deploy/image/build.sh [IMAGE]   (default parapm:latest; --base-only: the base alone)
# Environment: PARAPM_IMAGE_BASE (default localhost/parapm-base:bookworm),
#   PARAPM_DEBIAN_MIRROR (default http://deb.debian.org/debian), JOBS (compile jobs, default nproc).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
base_only=""
if [[ "${1:-}" == --base-only ]]; then base_only=1; shift; fi
image="${1:-parapm:latest}"
base="${PARAPM_IMAGE_BASE:-localhost/parapm-base:bookworm}"
mirror="${PARAPM_DEBIAN_MIRROR:-http://deb.debian.org/debian}"
log() { echo "[image] $*" >&2; }

# Tools: podman and debootstrap from Debian.
missing=()
command -v podman > /dev/null || missing+=(podman)
command -v debootstrap > /dev/null || missing+=(debootstrap)
if [[ ${#missing[@]} -gt 0 ]]; then
  [[ $(id -u) -eq 0 ]] || { echo "image: missing ${missing[*]} and not root to install them" >&2; exit 1; }
  log "installing ${missing[*]}"
  apt-get update -qq > /dev/null
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" > /dev/null
fi

# The base image, from Debian's packages.
if ! podman image exists "$base"; then
  [[ $(id -u) -eq 0 ]] || { echo "image: debootstrap needs root" >&2; exit 1; }
  rootfs="$(mktemp -d)"
  trap 'rm -rf --one-file-system "$rootfs"' EXIT
  log "debootstrap --variant=minbase bookworm ($mirror) for $base"
  start=$SECONDS
  debootstrap --variant=minbase bookworm "$rootfs" "$mirror" > "$rootfs.log" 2>&1 \
    || { tail -20 "$rootfs.log" >&2; rm -f "$rootfs.log"; exit 1; }
  rm -f "$rootfs.log"
  # Sources with updates and security fixes; what Debian's slim images leave out.
  rm -f "$rootfs/etc/apt/sources.list"
  cat > "$rootfs/etc/apt/sources.list.d/debian.sources" << EOF
Types: deb
URIs: $mirror
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  cat > "$rootfs/etc/dpkg/dpkg.cfg.d/slim" << 'EOF'
# Leave out documentation, man pages and translations (as Debian's slim images do).
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/info/*
path-exclude /usr/share/locale/*
path-exclude /usr/share/lintian/*
EOF
  cat > "$rootfs/etc/apt/apt.conf.d/90parapm" << 'EOF'
APT::Install-Recommends "false";
APT::Install-Suggests "false";
DPkg::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/*.bin || true"; };
EOF
  find "$rootfs/usr/share/doc" -mindepth 1 -not -name copyright -not -type d -delete
  rm -rf "$rootfs"/usr/share/{man,info,locale,lintian}/* "$rootfs"/var/cache/apt/* \
    "$rootfs"/var/lib/apt/lists/* "$rootfs"/var/log/*.log "$rootfs"/var/cache/debconf/*-old
  log "importing it as $base"
  tar --numeric-owner -C "$rootfs" -c . | podman import --quiet \
    --change 'CMD ["/bin/bash"]' --change 'ENV LANG=C.UTF-8' - "$base" > /dev/null
  rm -rf --one-file-system "$rootfs"
  trap - EXIT
  log "base ready in $((SECONDS - start)) s"
fi
[[ -n "$base_only" ]] && exit 0

# The build stage's -dev packages must cover scripts/bootstrap.sh's (less the test-only ones:
# the browser, GoogleTest, Node.js, the Python client's interpreter and its gRPC),
# so that the image builds whatever the project's own build needs.
bootstrap_pkgs="$(sed -n '/^pkgs=(/,/)/p' "$root/scripts/bootstrap.sh" | tr -d '()' | sed 's/pkgs=//' | tr -s ' \n' '\n' | grep -v '^$')"
image_pkgs=" $(sed -nE 's/^ +([a-z0-9][a-z0-9.+-]*) \\$/\1/p' "$here/Containerfile" | tr '\n' ' ') "
not_in_image=" chromium libgtest-dev libgmock-dev nodejs npm python3 python3-grpcio python3-protobuf "
for p in $bootstrap_pkgs; do
  [[ "$not_in_image" == *" $p "* || "$image_pkgs" == *" $p "* ]] && continue
  echo "image: scripts/bootstrap.sh installs $p but the Containerfile's build stage does not: add it there" >&2
  exit 1
done

# The build context: the files git knows (tracked, or untracked and not ignored) less what
# the image does not build from, so that no build output or local data goes in.
context="$(mktemp -d)"
trap 'rm -rf "$context"' EXIT
(cd "$root" && git ls-files -z --cached --others --exclude-standard) \
  | tr '\0' '\n' | grep -vE '^(tests|fuzz|docs|deploy|scripts|bench-out[^/]*|\.ci)/|^viewer/(node_modules|test|bench)/' \
  | while IFS= read -r f; do [[ -f "$root/$f" ]] && printf '%s\0' "$f"; done \
  | tar -C "$root" --null -T - -c | tar -C "$context" -x
cp "$here/Containerfile" "$context/Containerfile"

log "podman build $image (base $base)"
start=$SECONDS
build_args=(--isolation chroot --layers -f "$context/Containerfile" --build-arg BASE="$base"
            --build-arg JOBS="${JOBS:-$(nproc)}")
# The build stage is tagged too (parapm-build:latest), so that it stays as the next build's
# cache; what earlier builds left untagged (images labelled parapm.image) is then removed.
podman build "${build_args[@]}" --target build -t localhost/parapm-build:latest "$context"
podman build "${build_args[@]}" -t "$image" "$context"
for stage in build runtime; do
  podman image prune -f --filter "label=parapm.image=$stage" > /dev/null || true
done
log "built $image in $((SECONDS - start)) s; size $(podman image inspect --format '{{.Size}}' "$image" \
  | awk '{ printf "%.1f MB", $1 / 1e6 }')"
