#!/usr/bin/env bash
# Runs the whole test suite on Debian 13 (ParaView 5.13, Qt 6, Python 3.13) from a clean clone
# of this repository's HEAD, in a debootstrap chroot, so that a Debian 12 machine can check the
# other release. Uncommitted changes are not tested: commit first.
#
#   sudo scripts/test-debian13.sh [CHROOT_DIR]
#
# CHROOT_DIR (or $RESMR_CHROOT; default /var/tmp/resmr-trixie) is made on the first run and
# reused after; it must lie outside the repository. The test data comes from $RESMR_DATA_DIR,
# else ../shared/data beside the repository, mounted read-only as ../shared/data beside the
# clone. $DEBIAN_MIRROR picks the mirror (default http://deb.debian.org/debian).
# The log of the last run is CHROOT_DIR/srv/test-debian13.log; the exit status is make's.
set -euo pipefail

if [ "$(id -u)" != 0 ]; then
  exec sudo --preserve-env=RESMR_CHROOT,RESMR_DATA_DIR,DEBIAN_MIRROR "$0" "$@"
fi

repo=$(git -C "$(dirname "$0")" rev-parse --show-toplevel)
head=$(git -C "$repo" rev-parse HEAD)
root=$(realpath -m "${1:-${RESMR_CHROOT:-/var/tmp/resmr-trixie}}")
data=$(realpath -m "${RESMR_DATA_DIR:-$repo/../shared/data}")
mirror=${DEBIAN_MIRROR:-http://deb.debian.org/debian}

case "$root/" in
  "$repo"/*) echo "test-debian13: the chroot ($root) must lie outside the repository" >&2; exit 2 ;;
esac
if [ ! -f "$data/reference-counts.jsonl" ]; then
  echo "test-debian13: no test data in $data: set RESMR_DATA_DIR" >&2
  exit 2
fi
if [ -n "$(git -C "$repo" status --porcelain --untracked-files=no)" ]; then
  echo "test-debian13: note: uncommitted changes are not tested (testing $head)"
fi

# Unmount in reverse order on any exit, so that a failed or interrupted run leaves no mount
# behind (a later rm -rf of the chroot would otherwise reach the host's /dev or the data).
mounts=()
cleanup() {
  local i
  for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do
    umount "${mounts[i]}" 2>/dev/null || umount -l "${mounts[i]}" || true
  done
}
trap cleanup EXIT
mount_in() {  # mount_in TARGET MOUNT-ARGS...
  local target="$root$1"
  shift
  mkdir -p "$target"
  if ! mountpoint -q "$target"; then
    mount "$@" "$target"
    mounts+=("$target")
  fi
}

# A minimal Debian 13; debootstrap leaves its /debootstrap folder behind when it did not finish.
if [ ! -x "$root/usr/bin/apt-get" ] || [ -d "$root/debootstrap" ]; then
  if ! command -v debootstrap >/dev/null; then
    apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends debootstrap
  fi
  if [ -d "$root/debootstrap" ]; then
    if grep -q " $root/" /proc/mounts; then
      echo "test-debian13: $root is half made and has mounts inside: unmount them first" >&2
      exit 2
    fi
    echo "test-debian13: removing the unfinished chroot $root"
    rm -rf --one-file-system "$root"
  fi
  echo "test-debian13: debootstrap trixie into $root"
  debootstrap --variant=minbase trixie "$root" "$mirror"
fi

# The chroot's / a mount point of its own: tests make private mount namespaces there (unshare -m
# sets the propagation of /, which must be a mount point).
if ! mountpoint -q "$root"; then
  mount --bind "$root" "$root"
  mounts+=("$root")
fi
mount_in /proc -t proc proc
mount_in /sys -t sysfs sysfs
mount_in /dev --bind /dev
mount_in /dev/pts --bind /dev/pts
# OpenMPI's shared-memory transport needs a tmpfs at /dev/shm; the chroot gets its own.
mount_in /dev/shm -t tmpfs -o mode=1777 tmpfs
# Inside the chroot the clone is /srv/ReservoirMultiresolution, the data beside it in
# /srv/shared/data, where the build looks for it (../shared/data).
mount_in /srv/shared/data --bind -o ro "$data"
cp -L /etc/resolv.conf "$root/etc/resolv.conf"

in_root() { chroot "$root" /usr/bin/env -i HOME=/root TERM="${TERM:-dumb}" LANG=C.UTF-8 \
  PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin "$@"; }

missing=$(in_root sh -c 'for p in git make ca-certificates; do
  dpkg-query -W -f="\${Status}" $p 2>/dev/null | grep -q "install ok installed" || echo $p; done')
if [ -n "$missing" ]; then
  in_root apt-get update
  in_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends $missing
fi

clone="$root/srv/ReservoirMultiresolution"
rm -rf --one-file-system "$clone"
git clone --quiet --no-checkout "$repo" "$clone"
git -C "$clone" checkout --quiet --detach "$head"
echo "test-debian13: testing $(git -C "$clone" log -1 --format='%h %s') in $root"

# The packages first (network needed), then the suite in a network namespace of its own: its
# Xvfb display, pvserver port and MPI sockets cannot meet those of tests run on the host.
log="$root/srv/test-debian13.log"
start=$(date +%s)
status=0
{
  in_root sh -c 'cd /srv/ReservoirMultiresolution && make deps' &&
  unshare --net sh -c 'ip link set lo up && exec "$@"' sh \
    chroot "$root" /usr/bin/env -i HOME=/root LANG=C.UTF-8 CI=true \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    nice -n 10 sh -c 'cd /srv/ReservoirMultiresolution && make test'
} 2>&1 | tee "$log" || status=$?
elapsed=$(( $(date +%s) - start ))

versions=$(in_root dpkg-query -W -f='${Package} ${Version}\n' paraview cmake python3 python3-numpy \
  qt6-base-dev libopenmpi-dev 2>/dev/null | tr '\n' ';' || true)
echo "test-debian13: $(in_root sh -c '. /etc/os-release && echo "$PRETTY_NAME"'); $versions"
echo "test-debian13: $(grep -E 'tests passed|tests failed' "$log" | tail -1)"
echo "test-debian13: commit $head, $((elapsed / 60)) min $((elapsed % 60)) s, exit status $status;" \
  "log in $log"
exit "$status"
