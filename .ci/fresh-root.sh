# Helpers for the checks in a fresh Debian 12 root (sourced by .ci/fresh-debian and
# .ci/fresh-install-deb; needs root). The caller sets `mirror` and calls `trap unmount_roots
# EXIT` once.
#   make_root ROOT              removes ROOT if it exists, then debootstrap --variant=minbase
#                               bookworm into it, with the security and updates suites
#   mount_root ROOT             binds /proc, /sys, /dev, /dev/pts (and a /dev/shm tmpfs) into it
#   run_in_root ROOT NAME CMD   runs CMD (bash, from /root/fresco when it exists) in ROOT with a
#                               clean environment; prints exit code and time, keeps the log in
#                               ROOT/root/NAME.log; returns CMD's exit code
mounted=()

unmount_roots() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    umount -l "${mounted[i]}" 2>/dev/null || true
  done
}

make_root() {
  local root=$1 start
  if ! command -v debootstrap >/dev/null; then
    echo "fresh root: installing debootstrap"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq debootstrap >/dev/null
  fi
  if [ -e "$root" ]; then
    # Anything still mounted below the old root (an interrupted run) first.
    grep -o " $root/[^ ]*" /proc/mounts | sort -r | while read -r m; do umount -l "$m" || true; done
    rm -rf --one-file-system "$root"
  fi
  echo "fresh root: debootstrap --variant=minbase bookworm $root ($mirror)"
  start=$(date +%s)
  debootstrap --variant=minbase bookworm "$root" "$mirror" > /tmp/fresco-fresh-debootstrap.log 2>&1 || {
    tail -n 20 /tmp/fresco-fresh-debootstrap.log >&2
    echo "fresh root: debootstrap failed (log: /tmp/fresco-fresh-debootstrap.log)" >&2
    return 1
  }
  echo "fresh root: made in $(( $(date +%s) - start )) s"
  # The security and updates suites, as a Debian 12 installation has them.
  cat > "$root/etc/apt/sources.list" <<EOF
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb ${mirror%/debian}/debian-security bookworm-security main
EOF
  cp /etc/resolv.conf "$root/etc/resolv.conf"
}

mount_root() {
  local root=$1 m
  for m in proc sys dev dev/pts; do
    mkdir -p "$root/$m"
    mount --bind "/$m" "$root/$m"
    mounted+=("$root/$m")
  done
  mount -t tmpfs tmpfs "$root/dev/shm" 2>/dev/null && mounted+=("$root/dev/shm") || true
}

run_in_root() {
  local root=$1 name=$2 cmd=$3 t0 code
  t0=$(date +%s)
  set +e
  chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 TERM=dumb /bin/bash -c "cd /root/fresco 2>/dev/null || cd /root; $cmd" \
    > "$root/root/$name.log" 2>&1
  code=$?
  set -e
  # A one-line command is shown as it is; a script by its name.
  [[ $cmd == *$'\n'* ]] && cmd="($name)"
  echo "fresh root: '$cmd' exit $code in $(( $(date +%s) - t0 )) s (log: $root/root/$name.log)"
  tail -n 12 "$root/root/$name.log" | sed 's/^/    /'
  return $code
}
