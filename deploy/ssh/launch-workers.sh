#!/usr/bin/env bash
# deploy/ssh/launch-workers.sh: start (or stop) one long-lived aafarm-worker per host over ssh
# (docs/cluster.md, "Over ssh"; for one render with CURVE keys, farm.sh).
#
#   deploy/ssh/launch-workers.sh ENDPOINT HOST... [-- WORKER_OPTIONS...]
#   deploy/ssh/launch-workers.sh --stop HOST...
#
# ENDPOINT is what the workers connect to, e.g. tcp://render-master:5555
# (start the master with --bind tcp://*:5555). Each worker runs in the
# background with nohup (alone, so ssh returns at once: deploy/ssh/remote.sh),
# uses all cores of its host, and is named after the host; its own pid goes
# to $AAFARM_RUN/aafarm-worker.pid on that host, its log to
# $AAFARM_RUN/aafarm-worker.log, and it is checked to be running a second
# later (a host where it is missing or exits at once is named, exit 1).
# --stop sends it SIGTERM by that pid (it says goodbye to the master, which
# requeues its tiles at once), SIGKILL if it still runs 5 s later.
#
# Environment: AAFARM_WORKER  aafarm-worker on the hosts (default: on PATH)
#              AAFARM_RUN     folder for pid and log files (default /tmp)
#              SSH            the ssh command (default: ssh -o BatchMode=yes)
set -euo pipefail
worker=${AAFARM_WORKER:-aafarm-worker}
run=${AAFARM_RUN:-/tmp}
ssh_cmd=${SSH:-ssh -o BatchMode=yes}

usage() {
  sed -n '5,6p' "$0" | sed 's/^# *//' >&2
  exit 2
}
# shellcheck source=deploy/ssh/remote.sh
. "$(dirname "$0")/remote.sh"   # q, remote_start, remote_stop

stop_hosts() {
  local host out
  for host in "$@"; do
    if out=$($ssh_cmd "$host" "$(remote_stop "$run/aafarm-worker.pid")" </dev/null); then
      echo "$host: $out"
    else
      echo "launch-workers.sh: $host: ssh failed" >&2
    fi
  done
}

start_hosts() {
  local endpoint=$1; shift
  local hosts=() host out rc=0
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do hosts+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  [ ${#hosts[@]} -gt 0 ] || usage
  for host in "${hosts[@]}"; do
    if out=$($ssh_cmd "$host" "$(remote_start "$run/aafarm-worker.pid" "$run/aafarm-worker.log" \
        "$worker" --connect "$endpoint" --name "$host" "$@")" </dev/null); then
      echo "$host: worker ${out#pid }"
    else
      echo "launch-workers.sh: $host: ${out:-ssh failed}" >&2
      rc=1
    fi
  done
  return "$rc"
}

[ $# -ge 2 ] || usage
if [ "$1" = "--stop" ]; then shift; stop_hosts "$@"; else start_hosts "$@"; fi
