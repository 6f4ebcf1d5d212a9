#!/usr/bin/env bash
# The image as users get it, built and started on a machine without an image registry or a
# container runtime (`make image-check`, root):
#
#   1. base    the Dockerfile's base images made from Debian's packages (scripts/image/base.sh,
#              cached)
#   2. build   `podman build --isolation chroot --pull=never -t mocapqa:test .` of the
#              repository's own Dockerfile; the machine's CA bundle is passed as the build secret
#              `ca-certificates` (a proxy that inspects TLS), never copied into the image
#   3. start   the image's file system (a container made, not run, and mounted) with /proc, /dev
#              and /sys, under chroot as the image's user, with the image's environment,
#              working directory and user
#   4. serve   the image's own start command (CMD) on a free port of 127.0.0.1: the first
#              start makes the admin, then /api/v1/health answers "ok" and the vendored three.js
#              is served; the server runs as uid 10001
#   5. batch   `mocapqa batch` of a folder of real takes (copied from the corpus into /takes):
#              every take done, every process of the batch (client, local cluster's workers) is
#              uid 10001, the results are the user's
#   6. dask    the compose file's dask-scheduler and dask-worker commands (ports made free), the
#              shipped Dask settings read by both, and a batch sent to that scheduler
#
# Prints each step's wall-clock time and the build time; exit status 0 only when every step
# passed. Everything mounted is unmounted and every process started in the image is stopped
# when the script ends, however it ends; the image (tag below) is kept for the next build's layers.
#
#   --no-build          steps 3-6 only, on the image already tagged (to check it again)
#   MOCAPQA_IMAGE_TAG   the built image's tag (mocapqa:test)
#   MOCAPQA_CORPUS_DIR  the real takes (default: shared/data beside the checkout)
#   CA_BUNDLE           the CA bundle passed to the build (default: the machine's, when present)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TAG=${MOCAPQA_IMAGE_TAG:-mocapqa:test}
CORPUS=${MOCAPQA_CORPUS_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}
# Four real takes of two rigs (Bandai Namco, CMU): short, so the batch is mostly start-up.
TAKES=(
  bvh/bandai/dataset-1_dash_normal_001.bvh
  bvh/bandai/dataset-2_raise-up-left-hand_active_001.bvh
  bvh/bandai/dataset-2_run_normal_001.bvh
  bvh/cmu/cmu_12_01_walk.bvh
)
UID_IMAGE=10001
BUILD=1
case "${1:-}" in
  --no-build) BUILD=0 ;;
  "") ;;
  *) printf 'usage: %s [--no-build]\n' "$0" >&2; exit 2 ;;
esac

log() { printf 'image-check: %s\n' "$*"; }
fail() { log "FAILED: $*"; exit 1; }
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }

[ "$(id -u)" = 0 ] || fail "Expected root (podman's storage, chroot, mounts), got uid $(id -u)"
for tool in podman debootstrap chroot mount umount python3; do
  command -v "$tool" >/dev/null || fail "Expected $tool on PATH (make image-check installs it), got none"
done
for take in "${TAKES[@]}"; do
  [ -f "$CORPUS/$take" ] || fail "Expected the take $CORPUS/$take (set MOCAPQA_CORPUS_DIR), got none"
done

work=$(mktemp -d "${TMPDIR:-/var/tmp}/mocapqa-image-check.XXXXXX")
ctr="" rootfs="" sampler="" timings=()
started_all=$(now)

in_rootfs_pids() {
  # Processes whose root directory is the image's file system: the ones this script started.
  local pid
  [ -n "$rootfs" ] || return 0
  for pid in /proc/[0-9]*; do
    [ "$(readlink "$pid/root" 2>/dev/null)" = "$rootfs" ] && printf '%s\n' "${pid#/proc/}"
  done
  return 0
}

cleanup() {
  local status=$? pids point
  set +e
  [ -n "$sampler" ] && kill "$sampler" 2>/dev/null && wait "$sampler" 2>/dev/null
  if [ -n "$rootfs" ]; then
    pids=$(in_rootfs_pids)
    # shellcheck disable=SC2086 # one argument per pid
    [ -n "$pids" ] && kill -TERM $pids 2>/dev/null && sleep 2
    pids=$(in_rootfs_pids)
    # shellcheck disable=SC2086 # one argument per pid
    [ -n "$pids" ] && kill -KILL $pids 2>/dev/null && sleep 1
    for point in $(awk -v r="$rootfs/" 'index($2, r) == 1 { print $2 }' /proc/mounts | sort -r); do
      umount "$point" 2>/dev/null || umount -l "$point"
    done
  fi
  if [ -n "$ctr" ]; then
    podman umount "$ctr" >/dev/null 2>&1
    podman rm --force "$ctr" >/dev/null 2>&1
  fi
  if [ -n "$rootfs" ] && awk -v r="$rootfs/" 'index($2, r) == 1 { found = 1 } END { exit !found }' /proc/mounts; then
    log "WARNING: still mounted under $rootfs:"
    awk -v r="$rootfs/" 'index($2, r) == 1 { print "  " $2 }' /proc/mounts
    status=1
  fi
  rm -rf --one-file-system "$work"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

step_start() { step_name=$1; step_t0=$(now); log "[$step_name] $2"; }
step_done() {
  local took
  took=$(since "$step_t0")
  timings+=("$step_name ${took}s")
  log "[$step_name] ok in ${took} s${1:+ ($1)}"
}

if [ "$BUILD" = 1 ]; then
# 1. The bases.
step_start base "base images from Debian's packages (scripts/image/base.sh)"
bash "$ROOT/scripts/image/base.sh" 2>&1 | sed 's/^/  /'
[ "${PIPESTATUS[0]}" = 0 ] || fail "base images"
step_done

# 2. The build.
secret=()
ca=${CA_BUNDLE:-}
if [ -z "$ca" ]; then
  for candidate in "${PIP_CERT:-}" "${REQUESTS_CA_BUNDLE:-}" "${SSL_CERT_FILE:-}" \
      /etc/ssl/certs/ca-certificates.crt; do
    [ -n "$candidate" ] && [ -s "$candidate" ] && { ca=$candidate; break; }
  done
fi
[ -n "$ca" ] && secret=(--secret "id=ca-certificates,src=$ca")
step_start build "podman build --isolation chroot --pull=never -t $TAG . ${ca:+(CA bundle: $ca)}"
# The docker image format keeps the Dockerfile's HEALTHCHECK (OCI's has no place for it).
# Each line of the log stamped with the second it came, for the steps' durations below.
podman build --isolation chroot --pull=never --format docker "${secret[@]}" -t "$TAG" "$ROOT" 2>&1 \
  | while IFS= read -r line; do printf '%(%s)T %s\n' -1 "$line"; done >"$work/build.log"
if [ "${PIPESTATUS[0]}" != 0 ]; then
  tail -n 40 "$work/build.log" | cut -d' ' -f2- | sed 's/^/  /'
  fail "podman build (log above)"
fi
awk '$2 ~ /^(\[[0-9]+\/[0-9]+\]|STEP|COMMIT)/ && ($0 ~ / STEP [0-9]+\/[0-9]+: / || $0 ~ /COMMIT/) {
       if (text != "" && $1 - start >= 1) printf "  %4d s  %s\n", $1 - start, text
       start = $1; text = substr($0, index($0, " ") + 1, 96)
     }
     { last = $1 }
     END { if (text != "" && last - start >= 1) printf "  %4d s  %s\n", last - start, text }' \
  "$work/build.log"
size=$(podman image inspect --format '{{.Size}}' "$TAG" | awk '{ printf "%.0f MB", $1 / 1e6 }')
step_done "image $TAG, $size"
build_s=${timings[-1]#build }
fi
healthcheck=$(podman image inspect --format '{{json .Config.Healthcheck}}' "$TAG" 2>/dev/null || true)
case "$healthcheck" in *api/v1/health*) ;; *)
  fail "Expected the image $TAG with the Dockerfile's HEALTHCHECK, got '$healthcheck'" ;; esac

# 3. The image's file system, mounted, with what a container gets from its runtime.
step_start start "image file system under chroot, as the image's user"
ctr=$(podman create --pull=never "$TAG")
rootfs=$(podman mount "$ctr")
[ -d "$rootfs/usr/bin" ] || fail "Expected the image's file system at '$rootfs', got no /usr/bin"
inspect() { podman image inspect --format "$1" "$TAG"; }
user=$(inspect '{{.Config.User}}')
workdir=$(inspect '{{.Config.WorkingDir}}')
[ "$user" = "$UID_IMAGE:$UID_IMAGE" ] || fail "Expected the image's USER $UID_IMAGE:$UID_IMAGE, got '$user'"
mapfile -t image_env < <(inspect '{{range .Config.Env}}{{println .}}{{end}}' | sed '/^$/d')
home=$(awk -F: -v u="$UID_IMAGE" '$3 == u { print $6 }' "$rootfs/etc/passwd")
[ -n "$home" ] || fail "Expected uid $UID_IMAGE in the image's /etc/passwd, got none"
mount -t proc proc "$rootfs/proc"
mount --rbind /dev "$rootfs/dev"
mount --make-rslave "$rootfs/dev"
mount -t sysfs -o ro sysfs "$rootfs/sys"
mount -t tmpfs -o mode=1777 tmpfs "$rootfs/tmp"
grep -qs localhost "$rootfs/etc/hosts" || printf '127.0.0.1\tlocalhost\n::1\tlocalhost\n' >"$rootfs/etc/hosts"
mkdir -p "$rootfs/takes"
for take in "${TAKES[@]}"; do cp "$CORPUS/$take" "$rootfs/takes/"; done
chmod -R a+rX "$rootfs/takes"

# A command in the image, as its user (no supplementary groups), with its environment only,
# in its working directory; every link execs the next, so a background job's pid is the command.
run=(chroot --userspec="$user" --groups="${user#*:}" "$rootfs"
  /usr/bin/env -i "${image_env[@]}" HOME="$home"
  /bin/sh -c 'cd "$1" && shift && exec "$@"' sh "$workdir")
in_image() { "${run[@]}" "$@"; }
in_image sh -c 'id; python --version; mocapqa --version 2>/dev/null || true' | sed 's/^/  /'
[ "$(in_image id -u)" = "$UID_IMAGE" ] || fail "Expected commands in the image to run as $UID_IMAGE"
step_done "user $user, home $home, workdir $workdir"

free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
get() { python3 - "$@" <<'EOF'
import sys, urllib.request
try:
    with urllib.request.urlopen(sys.argv[1], timeout=5) as answer:
        body = answer.read()
        print(answer.status, len(body), " ".join(body[:300].decode("utf-8", "replace").split()))
except Exception as error:  # noqa: BLE001 - a check's probe: any failure is "not yet"
    print("000", 0, error)
EOF
}
uid_of() { awk '/^Uid:/ { print $2 "/" $3 "/" $4 "/" $5 }' "/proc/$1/status" 2>/dev/null; }
# Every process in the image, its uid, sampled until a stop file appears.
sample_uids() {
  while [ -d "$work" ] && [ ! -e "$1.stop" ]; do
    for pid in $(in_rootfs_pids); do
      uid=$(uid_of "$pid") && cmdline=$(tr '\0' ' ' 2>/dev/null <"/proc/$pid/cmdline" | cut -c1-60) \
        && [ -n "$uid" ] && printf '%s %s %s\n' "$pid" "$uid" "$cmdline"
    done >>"$1" 2>/dev/null
    sleep 0.3
  done
}
check_uids() {
  # $1: the samples; all of them uid 10001 (real, effective, saved, file system).
  local seen wrong
  seen=$(awk '{ print $1 }' "$1" | sort -u | wc -l)
  wrong=$(awk -v u="$UID_IMAGE/$UID_IMAGE/$UID_IMAGE/$UID_IMAGE" '$2 != u' "$1" | sort -u -k1,1)
  [ "$seen" -gt 0 ] || fail "Expected processes in the image, sampled none"
  [ -z "$wrong" ] || { printf '  %s\n' "$wrong"; fail "Expected every process as uid $UID_IMAGE"; }
  log "  $seen process(es) seen in the image, all uid $UID_IMAGE:"
  awk '{ $1 = ""; print }' "$1" | sort | uniq -c | sort -rn | head -n 6 | sed 's/^/   /'
}

# 4. The server, started by the image's own command.
step_start serve "the image's CMD on 127.0.0.1, /api/v1/health"
port=$(free_port)
mapfile -t cmd_args < <(inspect '{{json .Config.Cmd}}' | python3 -c '
import json, sys
port = sys.argv[1]
args = json.load(sys.stdin)
text = args[-1]
for old, new in (("--host 0.0.0.0", "--host 127.0.0.1"), ("--port 8000", "--port " + port)):
    if old not in text:
        sys.exit(f"Expected {old!r} in the image CMD, got {text!r}")
    text = text.replace(old, new)
print("\n".join([*args[:-1], text]))' "$port")
"${run[@]}" "${cmd_args[@]}" >"$work/serve.log" 2>&1 &
serve_pid=$!
health=""
for _ in $(seq 1 240); do
  health=$(get "http://127.0.0.1:$port/api/v1/health")
  case "$health" in 200\ *) break ;; esac
  kill -0 "$serve_pid" 2>/dev/null || { sed 's/^/  /' "$work/serve.log"; fail "the server ended"; }
  sleep 0.5
done
log "  GET /api/v1/health -> ${health}"
case "$health" in 200\ *'"status":"ok"'* | 200\ *'"status": "ok"'*) ;; *)
  sed 's/^/  /' "$work/serve.log"; fail "Expected 200 with status ok from /api/v1/health, got '$health'" ;; esac
three=$(get "http://127.0.0.1:$port/static/vendor/three/three.module.min.js")
log "  GET /static/vendor/three/three.module.min.js -> $(printf '%s' "$three" | cut -d' ' -f1,2) bytes"
case "$three" in 200\ *) ;; *) fail "Expected the vendored three.js served, got '$three'" ;; esac
grep -q . "$work/serve.log" && grep -iE 'admin|sign-in|http://' "$work/serve.log" | head -n 3 \
  | cut -c1-100 | sed 's/^/  log: /'
log "  server pid $serve_pid: uid $(uid_of "$serve_pid") (real/effective/saved/fs)"
[ "$(uid_of "$serve_pid")" = "$UID_IMAGE/$UID_IMAGE/$UID_IMAGE/$UID_IMAGE" ] \
  || fail "Expected the server as uid $UID_IMAGE"
kill -TERM "$serve_pid"
wait "$serve_pid" 2>/dev/null || true
step_done

# 5. A batch of real takes on the image's local cluster.
step_start batch "mocapqa batch /takes (${#TAKES[@]} real takes, 2 workers)"
sample_uids "$work/batch.uids" &
sampler=$!
batch_status=0
in_image env COLUMNS=200 mocapqa batch /takes --workers 2 --output /data/image-check/batch.jsonl \
  >"$work/batch.log" 2>&1 || batch_status=$?
touch "$work/batch.uids.stop"; wait "$sampler" || true
grep -E 'file\(s\)|failed|Error' "$work/batch.log" | tail -n 5 | sed 's/^/  /'
[ "$batch_status" = 0 ] || { tail -n 30 "$work/batch.log" | sed 's/^/  /'; fail "mocapqa batch exited $batch_status"; }
summary=$(python3 - "$rootfs/data/image-check/batch.jsonl" "${#TAKES[@]}" <<'EOF'
import json, sys
rows = [json.loads(line) for line in open(sys.argv[1])]
done = [r for r in rows if r["status"] == "done"]
for r in rows:
    print(f"  {r['status']:5} {r['source']:48} {r['rig']:7} {r['n_frames']:4} frames  score {r['score']}")
if len(done) != int(sys.argv[2]):
    sys.exit(f"Expected {sys.argv[2]} takes done, got {len(done)} of {len(rows)}")
EOF
) || { printf '%s\n' "$summary"; fail "the batch's results"; }
printf '%s\n' "$summary"
owner=$(stat -c %u:%g "$rootfs/data/image-check/batch.jsonl")
[ "$owner" = "$user" ] || fail "Expected the results owned by $user, got $owner"
check_uids "$work/batch.uids"
step_done "results owned by $owner"

# 6. The compose file's scheduler and worker (its "dask" profile), and a batch sent there.
step_start dask "docker-compose.yml's dask-scheduler and dask-worker commands, a batch sent there"
sched_port=$(free_port)
mapfile -t commands < <(in_image python -c '
import json, sys, yaml
services = yaml.safe_load(sys.stdin)["services"]
for name in ("dask-scheduler", "dask-worker"):
    service = services[name]
    for same in ("image", "build"):  # same image as the app, same Dockerfile
        assert service.get(same) == services["app"].get(same), (name, same)
    print(json.dumps(service["command"]))' <"$ROOT/docker-compose.yml")
[ "${#commands[@]}" = 2 ] || fail "Expected the two dask services' commands, got ${#commands[@]}"
to_args() {
  printf '%s' "$1" | python3 -c '
import json, sys
args = json.load(sys.stdin)
swap = {"0.0.0.0": "127.0.0.1", "8786": sys.argv[1], ":8787": ":0", "tcp://dask-scheduler:8786": "tcp://127.0.0.1:" + sys.argv[1]}
print("\n".join(swap.get(a, a) for a in args))' "$sched_port"
}
mapfile -t scheduler_args < <(to_args "${commands[0]}")
mapfile -t worker_args < <(to_args "${commands[1]}")
log "  scheduler: ${scheduler_args[*]}"
log "  worker:    ${worker_args[*]}"
sample_uids "$work/dask.uids" &
sampler=$!
"${run[@]}" "${scheduler_args[@]}" >"$work/scheduler.log" 2>&1 &
for _ in $(seq 1 120); do
  python3 -c "import socket, sys; socket.create_connection(('127.0.0.1', $sched_port), 1)" 2>/dev/null && break
  sleep 0.5
done
"${run[@]}" "${worker_args[@]}" >"$work/worker.log" 2>&1 &
settings=$(in_image python - "$sched_port" <<'EOF'
import sys, dask
from distributed import Client
keys = ("distributed.scheduler.work-stealing", "distributed.worker.profile.enabled",
        "distributed.admin.tick.interval")
with Client(f"tcp://127.0.0.1:{sys.argv[1]}", timeout=60) as client:
    client.wait_for_workers(1, timeout=120)
    on_scheduler = client.run_on_scheduler(lambda: [dask.config.get(k) for k in keys])
    on_workers = list(client.run(lambda: [dask.config.get(k) for k in keys]).values())
shipped = [False, False, "1s"]
print(f"  scheduler: {dict(zip(keys, on_scheduler))}")
print(f"  worker:    {dict(zip(keys, on_workers[0]))}")
if on_scheduler != shipped or any(w != shipped for w in on_workers):
    sys.exit(f"Expected the shipped settings {shipped} on the scheduler and the workers")
EOF
) || { printf '%s\n' "$settings"; sed 's/^/  worker: /' "$work/worker.log" | tail -n 20; fail "the Dask settings"; }
printf '%s\n' "$settings"
dask_status=0
in_image env COLUMNS=200 MOCAPQA_DATA_DIR=/data/image-check/dask mocapqa batch /takes \
  --scheduler "tcp://127.0.0.1:$sched_port" --output /data/image-check/dask.jsonl \
  >"$work/dask-batch.log" 2>&1 || dask_status=$?
touch "$work/dask.uids.stop"; wait "$sampler" || true
grep -E 'file\(s\)' "$work/dask-batch.log" | sed 's/^/  /'
[ "$dask_status" = 0 ] || { tail -n 30 "$work/dask-batch.log" | sed 's/^/  /'; fail "the batch on the scheduler exited $dask_status"; }
check_uids "$work/dask.uids"
step_done

[ "$BUILD" = 1 ] && log "build time: ${build_s}"
log "steps: ${timings[*]}"
log "total: $(since "$started_all") s; all passed"
