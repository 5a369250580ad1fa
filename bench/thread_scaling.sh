#!/bin/bash
# bench/thread_scaling.sh: how the standalone renderer scales with threads,
# and the farm with local workers (issue 10: "2 threads reach >= 1.9x of 1
# on 2 idle cores"; issue 24: ">= 14x on 16 cores, the farm of 16 local
# workers >= 13x on the same frame").
#
#   bench/thread_scaling.sh [BIN_DIR] [SCENE.rib] [RUNS]
#       defaults: build/bin, scenes/wave.rib, 5
#   environment:
#       THREADS="1 2 4 16"  the thread counts (default 1, 2, 4, ... up to
#                           the number of cores; 1 is always measured)
#       FARM=1              also render each frame with aafarm-master
#                           --local-workers T (T worker processes of one
#                           thread each, over loopback), against the same
#                           one-thread standalone render
#       SCALE=2             render SCENE with its Format multiplied by 2
#                           (a copy of the RIB beside it, removed at the end)
#
# Renders SCENE with 1 thread and with each T, RUNS times each in turn
# (1, T, 1, T, ...: a drift of the machine's speed hits both alike), and
# prints the median wall seconds of each, the speed-up over 1 thread and
# the efficiency (speed-up / T), and where the rest went: the CPU seconds
# (user + system of the render's processes), their ratio to the one-thread
# render's (each thread slower) and the share of the T cores kept busy
# (idle threads). Figures, never a verdict: on a machine
# with other work running the efficiency is low for reasons that are not
# the renderer's. Every render is bounded by timeout -k; nothing is left
# running. With FARM=1 the farm's image must equal the standalone one
# (exrcmp, tolerance 0): a difference is reported.
set -u
BIN=${1:-build/bin}
SCENE=${2:-scenes/wave.rib}
RUNS=${3:-5}
FARM=${FARM:-0}
SCALE=${SCALE:-1}
[ -x "$BIN/aafarm-worker" ] || { echo "thread_scaling.sh: $BIN/aafarm-worker not built" >&2; exit 2; }
[ "$FARM" = 0 ] || [ -x "$BIN/aafarm-master" ] || { echo "thread_scaling.sh: $BIN/aafarm-master not built" >&2; exit 2; }
[ -r "$SCENE" ] || { echo "thread_scaling.sh: cannot read $SCENE" >&2; exit 2; }
case "$SCALE" in ''|*[!0-9]*|0) echo "thread_scaling.sh: SCALE must be a positive integer" >&2; exit 2;; esac
CORES=$(nproc 2>/dev/null || echo 2)
if [ -z "${THREADS:-}" ]; then
    THREADS=""
    for ((t = 2; t <= CORES; t *= 2)); do THREADS+="$t "; done
fi
WORK=$(mktemp -d /tmp/aafarm-threads-XXXXXX)
COPY=""
trap 'rm -rf "$WORK"; [ -n "$COPY" ] && rm -f "$COPY"' EXIT
trap 'exit 143' TERM INT
if [ "$SCALE" != 1 ]; then
    # the copy stays beside the scene: its search paths are relative to it
    COPY=$(dirname "$SCENE")/.scaled-$$-$(basename "$SCENE")
    awk -v k="$SCALE" '$1 == "Format" {$2 *= k; $3 *= k} {print}' "$SCENE" >"$COPY"
    SCENE=$COPY
fi

# CPU seconds (user + system) of process $1's reaped children so far:
# /proc/PID/stat's cutime and cstime, in clock ticks (no procps needed)
child_cpu() {
    local f
    f=$(sed 's/.*) //' "/proc/$1/stat")   # the fields after "(comm) "
    echo "$f" | awk -v hz="$(getconf CLK_TCK 2>/dev/null || echo 100)" '{printf "%.2f\n", ($14 + $15) / hz}'
}

# "wall CPU" seconds of one standalone render with $1 threads
one() {
    local t0 t1 c0 c1 me=$BASHPID
    c0=$(child_cpu "$me")
    t0=$(date +%s.%N)
    timeout -k 5 900 "$BIN/aafarm-worker" --standalone "$SCENE" -o "$WORK/out$1.exr" \
        -t "$1" -q || { echo "thread_scaling.sh: render with $1 threads failed" >&2; kill -TERM $$; }
    t1=$(date +%s.%N)
    c1=$(child_cpu "$me")
    awk -v a="$t0" -v b="$t1" -v c="$c0" -v d="$c1" 'BEGIN {printf "%.4f:%.2f\n", b - a, d - c}'
}

# "wall CPU" seconds of one farm render: a master and $1 local workers
# (the workers' CPU counts: the master reaps them)
farm() {
    local t0 t1 c0 c1 me=$BASHPID
    c0=$(child_cpu "$me")
    t0=$(date +%s.%N)
    timeout -k 5 900 "$BIN/aafarm-master" "$SCENE" -o "$WORK/farm$1.exr" \
        --local-workers "$1" -q >"$WORK/farm.log" 2>&1 ||
        { echo "thread_scaling.sh: farm of $1 workers failed: $(tail -2 "$WORK/farm.log")" >&2; kill -TERM $$; }
    t1=$(date +%s.%N)
    c1=$(child_cpu "$me")
    awk -v a="$t0" -v b="$t1" -v c="$c0" -v d="$c1" 'BEGIN {printf "%.4f:%.2f\n", b - a, d - c}'
}

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
# field $1 (1: wall, 2: CPU) of each "wall:CPU" word on stdin, one a line
field() { tr ' ' '\n' | grep . | cut -d: -f"$1"; }

echo "thread_scaling: $(basename "$2" 2>/dev/null || echo "$SCENE") x$SCALE, $RUNS runs each, $CORES cores, load $(cut -d' ' -f1 /proc/loadavg) ($(date -u +%F))"
printf "%8s %12s %10s %9s %11s %8s %7s %6s\n" threads how "wall s" speed-up efficiency \
    "CPU s" "CPU x" busy
declare -A times ftimes
for T in $THREADS; do
    [ "$T" = 1 ] && [ "$FARM" = 0 ] && continue
    for ((r = 0; r < RUNS; r++)); do
        times[1]+="$(one 1) "
        [ "$T" = 1 ] || times[$T]+="$(one "$T") "
        [ "$FARM" = 0 ] || ftimes[$T]+="$(farm "$T") "
    done
done
[ -n "${times[1]:-}" ] || for ((r = 0; r < RUNS; r++)); do times[1]+="$(one 1) "; done
base=$(echo ${times[1]} | field 1 | median)
cbase=$(echo ${times[1]} | field 2 | median)
# CPU x: the CPU the render took over the one-thread render's (above 1:
# each thread got slower: shared caches, memory, hyperthreads, the farm's
# messages); busy: CPU / (T x wall), the share of the T cores kept working
# (below 1: idle threads, the tail of the tiles, start and finish). The
# speed-up is about T x busy / (CPU x).
row() {  # row T HOW TIMES
    local m c
    m=$(echo $3 | field 1 | median)
    c=$(echo $3 | field 2 | median)
    awk -v t="$1" -v h="$2" -v m="$m" -v b="$base" -v c="$c" -v cb="$cbase" \
        'BEGIN {x = cb > 0 ? c / cb : 0; u = m > 0 ? 100 * c / (t * m) : 0;
                printf "%8d %12s %10.3f %9.2f %10.0f%% %8.2f %7.2f %5.0f%%\n", t, h, m, b / m, 100 * b / m / t, c, x, u}'
}
row 1 standalone "${times[1]}"
for T in $THREADS; do
    [ "$T" = 1 ] || row "$T" standalone "${times[$T]}"
    if [ "$FARM" != 0 ]; then
        row "$T" "farm" "${ftimes[$T]}"
        if [ -x "$BIN/exrcmp" ] && ! "$BIN/exrcmp" "$WORK/out1.exr" "$WORK/farm$T.exr" 0 >/dev/null 2>&1; then
            echo "   the farm of $T workers' image DIFFERS from the standalone one"
        fi
    fi
done
