#!/usr/bin/env bash
# deploy/ssh/farm.sh: one render on workers started over ssh, with CurveZMQ
# (docs/cluster.md, "Over ssh").
#
#   deploy/ssh/farm.sh [--master-host NAME] HOSTS_FILE SCENE.rib -o OUT.exr [MASTER_OPTIONS...]
#
# HOSTS_FILE has one worker host per line ("host" or "host THREADS"; # starts
# a comment). The script
#   1. makes the keys it lacks in $AAFARM_KEYS (aafarm-keygen): master, and
#      one pair per host (named after the host), and puts the hosts' public
#      keys in $AAFARM_KEYS/allow;
#   2. asks each host how it resolves the master host (--master-host NAME:
#      the name or address the workers reach this machine by; default
#      $AAFARM_MASTER_HOST, else `hostname -f`): a name a host cannot
#      resolve is an error, and so is one that resolves to a loopback
#      address there when that host is another machine (its workers would
#      connect to themselves);
#   3. copies each host's secret key and the master's public key to that host
#      ($AAFARM_RUN/HOST/keys, mode 0700) and starts aafarm-worker there:
#      the worker alone in the background (nohup, so ssh returns at once),
#      its own PID in $AAFARM_RUN/HOST/worker.pid, its log in worker.log,
#      checked to be running a second later (deploy/ssh/remote.sh);
#   4. runs aafarm-master here, bound to port $AAFARM_PORT with CURVE;
#   5. stops every worker it started (SIGTERM by its PID, SIGKILL 5 s later)
#      at the end, on failure, and on Ctrl-C, and removes the copied keys.
# A host that fails (ssh or scp, the master host, a missing aafarm-worker, a
# worker that exits at once) is named with the reason on stderr; then the
# workers already started are stopped and nothing renders (exit 1): fix the
# host or take it out of HOSTS_FILE.
# Exit status: the master's; 1 when a host failed; 2 for usage errors.
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
#   AAFARM_MASTER_HOST  the default of --master-host
#   AAFARM_WORKER_OPTS  more worker options, e.g. "--cache-bytes 400K"
#   SSH, SCP            the commands (ssh -o BatchMode=yes, scp -q -o BatchMode=yes)
set -euo pipefail

usage() {
  sed -n '5p' "$0" | sed 's/^# *//' >&2
  exit 2
}
# shellcheck source=deploy/ssh/remote.sh
. "$(dirname "$0")/remote.sh"

master_host=${AAFARM_MASTER_HOST:-}
while [ $# -gt 0 ]; do
  case $1 in
    --master-host) if [ $# -lt 2 ] || [ -z "$2" ]; then usage; fi; master_host=$2; shift 2 ;;
    --master-host=*) master_host=${1#*=}; [ -n "$master_host" ] || usage; shift ;;
    --help|-h) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) break ;;
  esac
done
[ $# -ge 2 ] || usage
hosts_file=$1
shift
[ -r "$hosts_file" ] || { echo "farm.sh: cannot read hosts file $hosts_file" >&2; exit 2; }
[ -n "$master_host" ] || master_host=$(hostname -f 2>/dev/null || hostname)

bin=${AAFARM_BIN:+$AAFARM_BIN/}
remote_bin=${AAFARM_REMOTE_BIN:+$AAFARM_REMOTE_BIN/}
keys=${AAFARM_KEYS:-$HOME/.config/aafarm/keys}
run=${AAFARM_RUN:-/tmp/aafarm}
port=${AAFARM_PORT:-5555}
bind_host=${AAFARM_BIND_HOST:-*}
read -r -a ssh_cmd <<<"${SSH:-ssh -o BatchMode=yes}"
read -r -a scp_cmd <<<"${SCP:-scp -q -o BatchMode=yes}"
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

# 5. (armed before anything starts) stop what was started
started=()
# shellcheck disable=SC2317  # called by the traps
stop_workers() {
  local host out
  for host in "${started[@]}"; do
    local rdir="$run/$host"
    if out=$("${ssh_cmd[@]}" "$host" "$(remote_stop "$rdir/worker.pid")
      rm -rf $(q "$rdir")/keys" </dev/null); then
      echo "$host: $out"
    else
      echo "farm.sh: $host: ssh failed; stop its worker by hand (pid in $rdir/worker.pid there)" >&2
    fi
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

host_failed() {   # HOST MESSAGE: name it, stop the others, exit 1
  echo "farm.sh: $1: $2" >&2
  echo "farm.sh: not rendering: fix $1 or take it out of $hosts_file" >&2
  exit 1
}

# 2. how each host resolves the master host
here_id=$(sh -c "$machine_id_cmd")
is_loopback() { [[ $1 =~ ^127\. || $1 == ::1 || $1 == 0:0:0:0:0:0:0:1 ]]; }
for host in "${hosts[@]}"; do
  probe=$("${ssh_cmd[@]}" "$host" "id=\$($machine_id_cmd); echo \"id \$id\"
    if command -v getent >/dev/null 2>&1; then
      a=\$(getent hosts $(q "$master_host") | awk '{ print \$1; exit }'); echo \"addr \${a:-none}\"
    else echo 'addr unknown'; fi" </dev/null) ||
    host_failed "$host" "ssh failed (exit $?): check that '${ssh_cmd[*]} $host true' works without a prompt"
  there_id=$(sed -n 's/^id //p' <<<"$probe")
  addr=$(sed -n 's/^addr //p' <<<"$probe")
  if [ "$addr" = none ]; then
    host_failed "$host" "cannot resolve the master host '$master_host' there; pass --master-host with a name or address $host resolves to this machine"
  fi
  if is_loopback "$addr" && [ "$there_id" != "$here_id" ]; then
    host_failed "$host" "the master host '$master_host' resolves to $addr there, a loopback address of $host itself; pass --master-host with a name or address $host reaches this machine by"
  fi
done

# 3. workers
for i in "${!hosts[@]}"; do
  host=${hosts[$i]}
  opts=()
  [ "${threads[$i]}" -gt 0 ] && opts=(--threads "${threads[$i]}")
  opts+=("${worker_opts[@]}")
  rdir="$run/$host"
  "${ssh_cmd[@]}" "$host" "mkdir -p $(q "$rdir")/keys && chmod 700 $(q "$rdir")/keys" </dev/null ||
    host_failed "$host" "ssh failed making $rdir/keys there"
  started+=("$host")   # from here on, stop_workers removes the keys
  "${scp_cmd[@]}" "$keys/$host.key_secret" "$keys/master.key" "$host:$rdir/keys/" </dev/null ||
    host_failed "$host" "scp of its keys to $rdir/keys failed"
  out=$("${ssh_cmd[@]}" "$host" "chmod 600 $(q "$rdir/keys/$host.key_secret") || exit 5
    $(remote_start "$rdir/worker.pid" "$rdir/worker.log" "${remote_bin}aafarm-worker" \
      --connect "tcp://$master_host:$port" --name "$host" "${opts[@]}" \
      --curve-secret "$rdir/keys/$host.key_secret" --master-key "$rdir/keys/master.key")" \
      </dev/null) || host_failed "$host" "${out#error: }"
  echo "$host: worker ${out#pid }"
done

# 4. the master
set +e
"${bin}aafarm-master" "$@" --bind "tcp://$bind_host:$port" --curve-secret "$keys/master.key_secret" \
  --allow-keys "$keys/allow" &
master_pid=$!
wait "$master_pid"
rc=$?
set -e
master_pid=""
exit "$rc"
