#!/usr/bin/env bash
# deploy/ssh/launch-workers.sh: start (or stop) one long-lived aafarm-worker per host over ssh
# (docs/cluster.md, "Over ssh"; for one render with CURVE keys, farm.sh).
#
#   deploy/ssh/launch-workers.sh ENDPOINT HOST... [-- WORKER_OPTIONS...]
#   deploy/ssh/launch-workers.sh --stop HOST...
#
# ENDPOINT is what the workers connect to, e.g. tcp://render-master:5555
# (start the master with --bind tcp://*:5555). Each worker runs in the
# background with nohup, uses all cores of its host, and is named after the
# host; its pid goes to $AAFARM_RUN/aafarm-worker.pid on that host, its log
# to $AAFARM_RUN/aafarm-worker.log. --stop sends it SIGTERM by that pid (it
# says goodbye to the master, which requeues its tiles at once).
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
q() { printf '%q' "$1"; }   # quote one word for the remote shell

stop_hosts() {
  for host in "$@"; do
    $ssh_cmd "$host" "pid=\$(cat $(q "$run")/aafarm-worker.pid 2>/dev/null) &&
      kill -TERM \"\$pid\" 2>/dev/null && rm -f $(q "$run")/aafarm-worker.pid && echo \"$host: stopped worker \$pid\" ||
      echo \"$host: no worker running\"" || echo "$host: ssh failed" >&2
  done
}

start_hosts() {
  local endpoint=$1; shift
  local hosts=() opts=""
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do hosts+=("$1"); shift; done
  [ $# -gt 0 ] && shift
  for o in "$@"; do opts+=" $(q "$o")"; done
  [ ${#hosts[@]} -gt 0 ] || usage
  for host in "${hosts[@]}"; do
    $ssh_cmd "$host" "nohup $(q "$worker") --connect $(q "$endpoint") --name $(q "$host")$opts \
      >>$(q "$run")/aafarm-worker.log 2>&1 </dev/null & echo \$! >$(q "$run")/aafarm-worker.pid;
      echo \"$host: worker \$(cat $(q "$run")/aafarm-worker.pid)\"" || echo "$host: ssh failed" >&2
  done
}

[ $# -ge 2 ] || usage
if [ "$1" = "--stop" ]; then shift; stop_hosts "$@"; else start_hosts "$@"; fi
