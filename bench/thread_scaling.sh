#!/bin/bash
# bench/thread_scaling.sh: how the standalone renderer scales with threads
# (issue 10: "2 threads reach >= 1.9x of 1 on 2 idle cores").
#
#   bench/thread_scaling.sh [BIN_DIR] [SCENE.rib] [RUNS]
#       defaults: build/bin, scenes/wave.rib, 5
#
# Renders SCENE with 1 thread and with T = 2, 4, ... up to the number of
# cores, RUNS times each in turn (1, T, 1, T, ...: a drift of the machine's
# speed hits both alike), and prints the median wall seconds of each, the
# speed-up over 1 thread and the efficiency (speed-up / T). Figures, never
# a verdict: on a machine with other work running the efficiency is low for
# reasons that are not the renderer's. Every render is bounded by
# timeout -k; nothing is left running.
set -u
BIN=${1:-build/bin}
SCENE=${2:-scenes/wave.rib}
RUNS=${3:-5}
[ -x "$BIN/aafarm-worker" ] || { echo "thread_scaling.sh: $BIN/aafarm-worker not built" >&2; exit 2; }
[ -r "$SCENE" ] || { echo "thread_scaling.sh: cannot read $SCENE" >&2; exit 2; }
CORES=$(nproc 2>/dev/null || echo 2)
WORK=$(mktemp -d /tmp/aafarm-threads-XXXXXX)
trap 'rm -rf "$WORK"' EXIT

# wall seconds of one render with $1 threads
one() {
    local t0 t1
    t0=$(date +%s.%N)
    timeout -k 5 600 "$BIN/aafarm-worker" --standalone "$SCENE" -o "$WORK/out.exr" \
        -t "$1" -q || { echo "thread_scaling.sh: render with $1 threads failed" >&2; kill -TERM $$; }
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f\n", b - a}'
}

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

echo "thread_scaling: $SCENE, $RUNS runs each, $CORES cores ($(date -u +%F))"
printf "%8s %10s %9s %11s\n" threads "wall s" speed-up efficiency
T=2
declare -A times
while [ "$T" -le "$CORES" ]; do
    for ((r = 0; r < RUNS; r++)); do
        times[1]+="$(one 1) "
        times[$T]+="$(one "$T") "
    done
    T=$((T * 2))
done
base=$(echo ${times[1]} | tr ' ' '\n' | median)
printf "%8d %10.3f %9s %11s\n" 1 "$base" "1.00" "100%"
T=2
while [ "$T" -le "$CORES" ]; do
    m=$(echo ${times[$T]} | tr ' ' '\n' | median)
    awk -v t="$T" -v m="$m" -v b="$base" \
        'BEGIN {printf "%8d %10.3f %9.2f %10.0f%%\n", t, m, b / m, 100 * b / m / t}'
    T=$((T * 2))
done
