#!/usr/bin/env bash
# deploy/systemd/install.sh: installs a long-lived worker on this host under
# systemd (docs/cluster.md, "systemd"). As root:
#
#   deploy/systemd/install.sh NAME tcp://render-master:5555 MASTER.key [BIN_DIR]
#
# Copies aafarm-worker and aafarm-keygen from BIN_DIR (default build/bin) to
# /usr/local/bin, the template unit to /etc/systemd/system, writes
# /etc/aafarm/NAME.conf, makes the key pair /etc/aafarm/keys/NAME (unless it
# exists), copies the master's public key, enables and (re)starts
# aafarm-worker@NAME, and prints the public key the master must allow.
# Run again (an upgrade, another master): an existing NAME.conf is kept
# (your options stay); when the new default differs, it is written beside
# it as NAME.conf.new and the script says so. The worker's store of job
# files is /var/lib/aafarm (the unit's StateDirectory=).
# Environment: AAFARM_ROOT (default /: install under another root, for
# tests; then systemctl is not called).
set -euo pipefail
[ $# -ge 3 ] || { sed -n '5p' "$0" | sed 's/^# *//' >&2; exit 2; }
name=$1 master=$2 master_key=$3 bin=${4:-build/bin}
root=${AAFARM_ROOT:-/}
here=$(cd "$(dirname "$0")" && pwd)
[[ $name =~ ^[A-Za-z0-9_.-]+$ ]] || { echo "install.sh: NAME may hold letters, digits, _ . - only" >&2; exit 2; }
[ -r "$master_key" ] || { echo "install.sh: cannot read the master's key $master_key" >&2; exit 2; }

install -d "$root/usr/local/bin" "$root/etc/systemd/system" "$root/etc/aafarm"
install -d -m 700 "$root/etc/aafarm/keys"
install -m 755 "$bin/aafarm-worker" "$bin/aafarm-keygen" "$root/usr/local/bin/"
install -m 644 "$here/aafarm-worker@.service" "$root/etc/systemd/system/"
conf=$root/etc/aafarm/$name.conf
printf 'AAFARM_MASTER=%s\nAAFARM_WORKER_OPTS=\n' "$master" >"$conf.new"
if [ ! -e "$conf" ]; then
  mv "$conf.new" "$conf"
elif cmp -s "$conf" "$conf.new"; then
  rm -f "$conf.new"
else
  echo "install.sh: kept your $conf; the new default (AAFARM_MASTER=$master) is in $conf.new: merge it by hand"
fi
install -m 644 "$master_key" "$root/etc/aafarm/keys/master.key"
[ -e "$root/etc/aafarm/keys/$name.key_secret" ] ||
  "$root/usr/local/bin/aafarm-keygen" "$root/etc/aafarm/keys/$name" >/dev/null
if [ "$root" = / ]; then
  systemctl daemon-reload
  systemctl enable "aafarm-worker@$name"
  systemctl restart "aafarm-worker@$name"   # a running one picks up the new program
fi
echo "installed aafarm-worker@$name; the master must allow this public key"
echo "(copy it into its --allow-keys folder): $root/etc/aafarm/keys/$name.key"
