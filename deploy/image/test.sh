#!/usr/bin/env bash
# Tests the built image for real: starts a coordinator and two workers from it (each on
# loopback, free ports, a token), submits a mesh with the image's own parapm client, and checks
# the Progressive Mesh: `parapm check` (it rebuilds the input exactly), the same bytes as
# `parapm simplify` with the same options (--parallel 4) run from the image, subsets run on
# the image's workers, a level cut from it; the viewer's page served; the coordinator's and a
# worker's /metrics (Prometheus text, with the token) and --log-format json (one object a
# line); each daemon exits cleanly on SIGTERM.
# Where `podman run` works the daemons run in containers (--network host); where it does not
# (no cgroups, as on these machines) the image's filesystem is exported and the programs run
# in it under chroot, as the image's user (uid 10001), in a private mount namespace, with
# /proc and device nodes of its own.
# Usage: deploy/image/test.sh [IMAGE [MESH]]   (default parapm:latest; the mesh: the shared
#   stanford-bunny-69k.ply beside the clone, else the bundled 10k-face bunny)
# Environment: PARAPM_IMAGE_TEST_MODE=chroot|podman forces one way. Root only.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
image="${1:-parapm:latest}"
mesh="${2:-}"
if [[ -z "$mesh" ]]; then
  mesh="$root/../shared/meshes/stanford-bunny-69k.ply"
  [[ -f "$mesh" ]] || mesh="$root/tests/data/pymeshlab-bunny-textured-10k.obj"
fi
# Subsets down to 2000 faces, so that a small mesh is cut into subsets for the workers too
# (by default the quadric builds a mesh under 8000 faces a subset in one pass).
build_opts=(--ratio 0.02 --parallel 4 --min-subset-faces 2000)
log() { echo "[image-test] $*" >&2; }
fail() { echo "[image-test] FAIL: $*" >&2; exit 1; }
[[ $(id -u) -eq 0 ]] || fail "run as root (podman, chroot)"
[[ -f "$mesh" ]] || fail "no mesh $mesh"
podman image exists "$image" || fail "no image $image: build it with deploy/image/build.sh"

# The mode, and the re-run inside a private mount namespace for chroot (its mount of /proc
# vanishes with the namespace, whatever happens to this script).
mode="${PARAPM_IMAGE_TEST_MODE:-}"
if [[ -z "$mode" ]]; then
  if timeout 120 podman run --rm --network host "$image" true > /dev/null 2>&1; then mode=podman
  else mode=chroot; log "podman run does not work here: running the image's filesystem under chroot"; fi
fi
if [[ "$mode" == chroot && -z "${PARAPM_IMAGE_TEST_NS:-}" ]]; then
  exec env PARAPM_IMAGE_TEST_NS=1 PARAPM_IMAGE_TEST_MODE=chroot \
    unshare --mount --propagation private -- "$0" "$image" "$mesh"
fi

start_s=$SECONDS
tmp="$(mktemp -d)"
pids=()
containers=()
cleanup() {
  local rc=$?
  for c in "${containers[@]}"; do podman rm -f -t 5 "$c" > /dev/null 2>&1 || true; done
  for p in "${pids[@]}"; do kill -TERM "$p" 2> /dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2> /dev/null || true; done
  if [[ $rc -ne 0 && -d "$tmp" ]]; then
    for f in "$tmp"/share/*.log; do [[ -f "$f" ]] && { echo "--- $f" >&2; tail -20 "$f" >&2; }; done
  fi
  if [[ -n "${rootfs:-}" ]] && mountpoint -q "$rootfs/proc"; then umount "$rootfs/proc" || true; fi
  # --one-file-system: never into a mount that is still there.
  rm -rf --one-file-system "$tmp"
  exit $rc
}
trap cleanup EXIT

# Inside the image, /srv/test is the folder shared with this script ($share here).
uid=10001
if [[ "$mode" == chroot ]]; then
  rootfs="$tmp/rootfs"
  mkdir -p "$rootfs"
  log "exporting $image's filesystem"
  cid="$(podman create "$image" true)"
  podman export "$cid" | tar -C "$rootfs" --numeric-owner -x
  podman rm "$cid" > /dev/null
  mount -t proc proc "$rootfs/proc"
  # A few device nodes of its own (as a container runtime gives), not the host's /dev.
  mkdir -p "$rootfs/dev"
  for node in null:1:3 zero:1:5 full:1:7 random:1:8 urandom:1:9 tty:5:0; do
    IFS=: read -r name major minor <<< "$node"
    rm -f "$rootfs/dev/$name"
    mknod -m 0666 "$rootfs/dev/$name" c "$major" "$minor"
  done
  share="$rootfs/srv/test"
  img_env=(env -i PATH=/usr/local/bin:/usr/bin:/bin HOME=/var/lib/parapm LANG=C.UTF-8)
  # in_image CMD...: runs CMD from the image, as its user, in the foreground.
  in_image() { chroot --userspec=$uid:$uid "$rootfs" "${img_env[@]}" "$@"; }
  # daemon NAME CMD...: starts CMD from the image in the background, its output in NAME.log.
  daemon() {
    local name="$1"; shift
    chroot --userspec=$uid:$uid "$rootfs" "${img_env[@]}" "$@" > "$share/$name.log" 2>&1 &
    pids+=($!)
  }
else
  share="$tmp/share"
  run_args=(--network host --user $uid:$uid -v "$share:/srv/test")
  in_image() { podman run --rm "${run_args[@]}" "$image" "$@"; }
  daemon() {
    local name="$1"; shift
    local c="parapm-image-test-$$-$name"
    podman run -d --name "$c" "${run_args[@]}" "$image" "$@" > /dev/null
    containers+=("$c")
    podman logs -f "$c" > "$share/$name.log" 2>&1 &
    pids+=($!)
  }
fi
mkdir -p "$share"
mesh_name="$(basename "$mesh")"
cp "$mesh" "$share/$mesh_name"
head -c 32 /dev/urandom | base64 > "$share/token"
chmod 0600 "$share/token"
chown -R $uid:$uid "$share"
auth=(--token-file /srv/test/token)
log "mode $mode; mesh $mesh_name"

# A coordinator and two workers, on free loopback ports: JSON logs from the coordinator and
# worker 2, worker 1's metrics on a port of its own.
in_image parapm-coordinator --help > /dev/null || fail "parapm-coordinator does not run in the image"
in_image parapm-worker --help > /dev/null || fail "parapm-worker does not run in the image"
json_log=(--log-format json)
worker_json_log=(--log-format json)
metrics_port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"

daemon coordinator parapm-coordinator --listen 127.0.0.1:0 --port-file /srv/test/port \
  --http 127.0.0.1:0 --http-port-file /srv/test/http-port --data /srv/test/data "${auth[@]}" \
  "${json_log[@]}"
for _ in $(seq 200); do [[ -s "$share/port" && -s "$share/http-port" ]] && break; sleep 0.1; done
[[ -s "$share/port" && -s "$share/http-port" ]] || fail "the coordinator did not start"
port="$(cat "$share/port")"
http_port="$(cat "$share/http-port")"
server=(--server "127.0.0.1:$port")
daemon worker1 parapm-worker --coordinator "127.0.0.1:$port" --listen 127.0.0.1:0 \
  --name image-w1 --threads 1 "${auth[@]}" --metrics-listen "127.0.0.1:$metrics_port"
daemon worker2 parapm-worker --coordinator "127.0.0.1:$port" --listen 127.0.0.1:0 \
  --name image-w2 --threads 1 "${auth[@]}" "${worker_json_log[@]}"
for _ in $(seq 200); do
  [[ $(grep -c 'registered' "$share/coordinator.log" || true) -ge 2 ]] && break
  sleep 0.1
done
[[ $(grep -c 'registered' "$share/coordinator.log" || true) -ge 2 ]] || fail "the workers did not register"
log "coordinator on 127.0.0.1:$port (viewer :$http_port), 2 workers registered"

# A job: upload, build on the workers, download.
t0=$SECONDS
job="$(in_image parapm --log-level warn submit "/srv/test/$mesh_name" "${build_opts[@]}" \
  -o /srv/test/service.pm --json "${server[@]}" "${auth[@]}")" \
  || fail "parapm submit failed"
job_id="$(sed -nE 's/.*"job_id":"([^"]+)".*/\1/p' <<< "$job")"
[[ -n "$job_id" ]] || fail "no job id in: $job"
log "job $job_id done in $((SECONDS - t0)) s"
in_image parapm watch "$job_id" "${server[@]}" "${auth[@]}" > "$share/events.txt" || fail "parapm watch"
grep -qE 'started on image-w[12]' "$share/events.txt" \
  || { cat "$share/events.txt" >&2; fail "no subset ran on the image's workers"; }
log "subsets on the workers: $(grep -cE 'collapses on image-w[12]' "$share/events.txt")"

# The PM: exact, the same bytes as a local parallel build, and a level from it.
in_image parapm --log-level warn check /srv/test/service.pm --against "/srv/test/$mesh_name" > /dev/null \
  || fail "parapm check: the PM does not rebuild the input"
in_image parapm --log-level warn simplify "/srv/test/$mesh_name" -o /srv/test/local.pm \
  "${build_opts[@]}" > /dev/null || fail "parapm simplify"
cmp "$share/service.pm" "$share/local.pm" \
  || fail "the service's PM differs from parapm simplify --parallel 4"
in_image parapm --log-level warn lod /srv/test/service.pm --faces 5000 -o /srv/test/lod.obj > /dev/null || fail "parapm lod"
[[ -s "$share/lod.obj" ]] || fail "parapm lod wrote nothing"
log "PM $(stat -c %s "$share/service.pm") bytes: exact (parapm check), same bytes as parapm simplify --parallel 4"

# The viewer's page (compiled into the coordinator) and /metrics, from outside the image.
curl -fsS "http://127.0.0.1:$http_port/" | grep -qi '<html' || fail "the viewer's page is not served"
bearer=(-H "Authorization: Bearer $(cat "$share/token")")
curl -fsS "${bearer[@]}" "http://127.0.0.1:$http_port/metrics" > "$share/metrics.txt" \
  || fail "the coordinator does not serve /metrics"
grep -q '^parapm_jobs_ended_total{state="done"} 1$' "$share/metrics.txt" \
  || fail "the coordinator's /metrics does not count the job done"
curl -fsS "${bearer[@]}" "http://127.0.0.1:$metrics_port/metrics" > "$share/worker-metrics.txt" \
  || fail "worker 1 does not serve /metrics on --metrics-listen"
grep -q '^# TYPE parapm_worker_subsets_total counter$' "$share/worker-metrics.txt" \
  || fail "a worker's /metrics is not in Prometheus' text format"
log "viewer page, the coordinator's and a worker's /metrics served"
# JSON logs: every line one object.
for name in coordinator worker2; do
  [[ -s "$share/$name.log" ]] || fail "$name logged nothing"
  if grep -qv '^{.*}$' "$share/$name.log"; then
    grep -v '^{.*}$' "$share/$name.log" | head -3 >&2; fail "$name's --log-format json log has lines that are not objects"
  fi
  log "$name logs JSON, $(wc -l < "$share/$name.log") lines"
done

# Stop: SIGTERM, as a container runtime does; each daemon must exit cleanly.
if [[ "$mode" == podman ]]; then
  for c in "${containers[@]}"; do
    podman stop -t 10 "$c" > /dev/null
    code="$(podman inspect --format '{{.State.ExitCode}}' "$c")"
    [[ "$code" == 0 ]] || fail "$c exited with status $code on SIGTERM"
  done
else
  for p in "${pids[@]}"; do kill -TERM "$p" 2> /dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" || fail "a daemon exited with status $? on SIGTERM"; done
  pids=()
fi
log "PASS in $((SECONDS - start_s)) s ($mode)"
