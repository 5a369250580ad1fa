# deploy/ssh/remote.sh: sourced by farm.sh and launch-workers.sh: the shell
# text they run on a host over ssh (docs/cluster.md, "Over ssh"). Each
# function prints a POSIX sh script; ssh hands it to the host's login shell.
#
# Starting a worker so that ssh returns at once: the worker alone is put in
# the background (`nohup WORKER ... &` as a simple command, not the tail of
# an `&&` list, whose subshell would keep ssh's channel open), with stdin,
# stdout and stderr away from the channel; $! is then the worker's own PID,
# written to the pid file. One second later the script checks that this
# PID still runs (not exited, not a zombie) and prints "pid PID", or
# "error: ..." with the end of the worker's log and exits non-zero. A
# worker program missing there is such an error, before anything starts.
# shellcheck shell=bash

q() { printf '%q' "$1"; }   # one word for the remote shell

# The identity of a machine: the same on both ends of an ssh call means the
# "remote" host is this one (then a loopback master address is fine).
# shellcheck disable=SC2034  # used by the scripts that source this file
machine_id_cmd='cat /etc/machine-id 2>/dev/null || hostname'

# alive PID: true while PID runs (Linux: not a zombie either)
# shellcheck disable=SC2016  # expanded there, not here
remote_alive='alive() {
  if [ -d /proc/self ]; then
    st=$(sed -n "s/^State:[[:space:]]*\([A-Z]\).*/\1/p" "/proc/$1/status" 2>/dev/null)
    [ -n "$st" ] && [ "$st" != Z ]
  else
    kill -0 "$1" 2>/dev/null
  fi
}'

# remote_start PIDFILE LOGFILE WORKER ARG...: the script that starts WORKER
# (a path, or a name looked up on the host's PATH) with ARGs.
remote_start() {
  local pidfile=$1 log=$2 worker=$3 args="" a
  shift 3
  for a in "$@"; do args+=" $(q "$a")"; done
  cat <<EOF
$remote_alive
pidfile=$(q "$pidfile"); log=$(q "$log"); worker=$(q "$worker")
case \$worker in
  */*) [ -x "\$worker" ] || { echo "error: \$worker is not there or not executable (set AAFARM_REMOTE_BIN)"; exit 3; } ;;
  *) command -v "\$worker" >/dev/null 2>&1 || { echo "error: \$worker is not on the PATH there (\$PATH; set AAFARM_REMOTE_BIN)"; exit 3; } ;;
esac
nohup "\$worker"$args >>"\$log" 2>&1 </dev/null &
pid=\$!
echo "\$pid" >"\$pidfile"
sleep 1
if alive "\$pid"; then
  echo "pid \$pid"
else
  echo "error: the worker exited at once; \$log ends: \$(tail -n 2 "\$log" | tr '\n' ' ')"
  rm -f "\$pidfile"
  exit 4
fi
EOF
}

# remote_stop PIDFILE: the script that stops the worker of PIDFILE (SIGTERM,
# SIGKILL if it still runs AAFARM_STOP_GRACE seconds later, default 5) and
# prints "stopped worker PID", "killed worker PID" or "no worker running".
remote_stop() {
  local tenths=$(( ${AAFARM_STOP_GRACE:-5} * 10 ))
  cat <<EOF
$remote_alive
pidfile=$(q "$1")
pid=\$(cat "\$pidfile" 2>/dev/null) || pid=
rm -f "\$pidfile"
if [ -n "\$pid" ] && alive "\$pid" && kill -TERM "\$pid" 2>/dev/null; then
  i=0
  while alive "\$pid" && [ \$i -lt $tenths ]; do sleep 0.1; i=\$((i + 1)); done
  if alive "\$pid"; then kill -KILL "\$pid"; echo "killed worker \$pid"; else echo "stopped worker \$pid"; fi
else
  echo "no worker running"
fi
EOF
}
