#!/usr/bin/env bash
# deploy/ssh/farm.sh: one render on workers started over ssh, with CurveZMQ
# (docs/cluster.md, "Over ssh").
#
#   deploy/ssh/farm.sh HOSTS_FILE SCENE.rib -o OUT.exr [MASTER_OPTIONS...]
#
# HOSTS_FILE has one worker host per line ("host" or "host THREADS"; # starts
# a comment). The script
#   1. makes the keys it lacks in $AAFARM_KEYS (aafarm-keygen): master, and
#      one pair per host (named after the host), and puts the hosts' public
#      keys in $AAFARM_KEYS/allow;
#   2. copies each host's secret key and the master's public key to that host
#      ($AAFARM_RUN/HOST/keys, mode 0700) and starts aafarm-worker there
#      (nohup; worker.log and worker.pid in $AAFARM_RUN/HOST);
#   3. runs aafarm-master here, bound to port $AAFARM_PORT with CURVE;
#   4. stops every worker it started (SIGTERM by its pid file) at the end,
#      on failure, and on Ctrl-C, and removes the copied secret keys.
# Exit status: the master's.
#
# Environment:
#   AAFARM_BIN          folder with aafarm-master, aafarm-worker, aafarm-keygen
#                       here (default: on PATH)
#   AAFARM_REMOTE_BIN   folder with aafarm-worker on the hosts (default: PATH)
#   AAFARM_KEYS         key folder here (default ~/.config/aafarm/keys)
#   AAFARM_RUN          on the hosts: logs, pids and keys go to $AAFARM_RUN/HOST
#                       (default /tmp/aafarm)
#   AAFARM_PORT         the master's port (5555)
#   AAFARM_BIND_HOST    the address the master binds ("*": every interface)
#   AAFARM_MASTER_HOST  the name workers reach this host by (hostname -f)
#   AAFARM_WORKER_OPTS  more worker options, e.g. "--cache-bytes 400K"
#   SSH, SCP            the commands (ssh -o BatchMode=yes, scp -q -o BatchMode=yes)
set -euo pipefail

usage() {
  sed -n '5p' "$0" | sed 's/^# *//' >&2
  exit 2
}
[ $# -ge 2 ] || usage
hosts_file=$1
shift
[ -r "$hosts_file" ] || { echo "farm.sh: cannot read hosts file $hosts_file" >&2; exit 2; }

bin=${AAFARM_BIN:+$AAFARM_BIN/}
remote_bin=${AAFARM_REMOTE_BIN:+$AAFARM_REMOTE_BIN/}
keys=${AAFARM_KEYS:-$HOME/.config/aafarm/keys}
run=${AAFARM_RUN:-/tmp/aafarm}
port=${AAFARM_PORT:-5555}
bind_host=${AAFARM_BIND_HOST:-*}
master_host=${AAFARM_MASTER_HOST:-$(hostname -f 2>/dev/null || hostname)}
read -r -a ssh_cmd <<<"${SSH:-ssh -o BatchMode=yes}"
read -r -a scp_cmd <<<"${SCP:-scp -q -o BatchMode=yes}"
q() { printf '%q' "$1"; }   # one word for the remote shell
read -r -a worker_opts <<<"${AAFARM_WORKER_OPTS:-}"

hosts=()
threads=()
line_no=0
while IFS= read -r line || [ -n "$line" ]; do
  line_no=$((line_no + 1))
  line=${line%%#*}
  read -r host nthreads extra <<<"$line" || true
  [ -n "${host:-}" ] || continue
  if [ -n "${extra:-}" ] || { [ -n "${nthreads:-}" ] && ! [[ $nthreads =~ ^[0-9]+$ ]]; }; then
    echo "farm.sh: $hosts_file:$line_no: expected 'HOST [THREADS]', got '$line'" >&2
    exit 2
  fi
  hosts+=("$host")
  threads+=("${nthreads:-0}")
done <"$hosts_file"
[ ${#hosts[@]} -gt 0 ] || { echo "farm.sh: $hosts_file names no host" >&2; exit 2; }

# 1. keys
mkdir -p "$keys/allow"
chmod 700 "$keys"
[ -e "$keys/master.key_secret" ] || "${bin}aafarm-keygen" "$keys/master" >/dev/null
for host in "${hosts[@]}"; do
  [ -e "$keys/$host.key_secret" ] || "${bin}aafarm-keygen" "$keys/$host" >/dev/null
  cp "$keys/$host.key" "$keys/allow/$host.key"
done

# 4. (armed before anything starts) stop what was started
started=()
# shellcheck disable=SC2317  # called by the traps
stop_workers() {
  local host
  for host in "${started[@]}"; do
    local rdir="$run/$host"
    "${ssh_cmd[@]}" "$host" "pid=\$(cat $(q "$rdir")/worker.pid 2>/dev/null) &&
      kill -TERM \"\$pid\" 2>/dev/null && echo \"$host: stopped worker \$pid\";
      rm -f $(q "$rdir")/worker.pid; rm -rf $(q "$rdir")/keys" ||
      echo "farm.sh: $host: ssh failed; stop its worker by hand" >&2
  done
  started=()
}
# shellcheck disable=SC2317  # called by the traps
on_signal() {
  trap - INT TERM
  if [ -n "${master_pid:-}" ]; then
    kill -TERM "$master_pid" 2>/dev/null || true
    wait "$master_pid" || true
  fi
  stop_workers
  exit 130
}
trap stop_workers EXIT
trap on_signal INT TERM

# 2. workers
for i in "${!hosts[@]}"; do
  host=${hosts[$i]}
  opts=""
  [ "${threads[$i]}" -gt 0 ] && opts="--threads ${threads[$i]}"
  for o in "${worker_opts[@]}"; do opts+=" $(q "$o")"; done
  rdir="$run/$host"
  "${ssh_cmd[@]}" "$host" "mkdir -p $(q "$rdir")/keys && chmod 700 $(q "$rdir")/keys"
  "${scp_cmd[@]}" "$keys/$host.key_secret" "$keys/master.key" "$host:$rdir/keys/"
  started+=("$host")
  "${ssh_cmd[@]}" "$host" "chmod 600 $(q "$rdir")/keys/$(q "$host").key_secret &&
    nohup $(q "${remote_bin}aafarm-worker") --connect $(q "tcp://$master_host:$port") \
      --name $(q "$host") $opts \
      --curve-secret $(q "$rdir")/keys/$(q "$host").key_secret \
      --master-key $(q "$rdir")/keys/master.key \
      >>$(q "$rdir")/worker.log 2>&1 </dev/null & echo \$! >$(q "$rdir")/worker.pid;
    echo \"$host: worker \$(cat $(q "$rdir")/worker.pid)\""
done

# 3. the master
set +e
"${bin}aafarm-master" "$@" --bind "tcp://$bind_host:$port" --curve-secret "$keys/master.key_secret" \
  --allow-keys "$keys/allow" &
master_pid=$!
wait "$master_pid"
rc=$?
set -e
master_pid=""
exit "$rc"
