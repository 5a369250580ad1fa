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
# the efficiency (speed-up / T). Figures, never a verdict: on a machine
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

# wall seconds of one standalone render with $1 threads
one() {
    local t0 t1
    t0=$(date +%s.%N)
    timeout -k 5 900 "$BIN/aafarm-worker" --standalone "$SCENE" -o "$WORK/out$1.exr" \
        -t "$1" -q || { echo "thread_scaling.sh: render with $1 threads failed" >&2; kill -TERM $$; }
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f\n", b - a}'
}

# wall seconds of one farm render: a master and $1 local workers
farm() {
    local t0 t1
    t0=$(date +%s.%N)
    timeout -k 5 900 "$BIN/aafarm-master" "$SCENE" -o "$WORK/farm$1.exr" \
        --local-workers "$1" -q >"$WORK/farm.log" 2>&1 ||
        { echo "thread_scaling.sh: farm of $1 workers failed: $(tail -2 "$WORK/farm.log")" >&2; kill -TERM $$; }
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.4f\n", b - a}'
}

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

echo "thread_scaling: $(basename "$2" 2>/dev/null || echo "$SCENE") x$SCALE, $RUNS runs each, $CORES cores, load $(cut -d' ' -f1 /proc/loadavg) ($(date -u +%F))"
printf "%8s %12s %10s %9s %11s\n" threads how "wall s" speed-up efficiency
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
base=$(echo ${times[1]} | tr ' ' '\n' | median)
printf "%8d %12s %10.3f %9s %11s\n" 1 standalone "$base" "1.00" "100%"
row() {  # row T HOW TIMES
    local m
    m=$(echo $3 | tr ' ' '\n' | median)
    awk -v t="$1" -v h="$2" -v m="$m" -v b="$base" \
        'BEGIN {printf "%8d %12s %10.3f %9.2f %10.0f%%\n", t, h, m, b / m, 100 * b / m / t}'
}
for T in $THREADS; do
    [ "$T" = 1 ] || row "$T" standalone "${times[$T]}"
    if [ "$FARM" != 0 ]; then
        row "$T" "farm" "${ftimes[$T]}"
        if [ -x "$BIN/exrcmp" ] && ! "$BIN/exrcmp" "$WORK/out1.exr" "$WORK/farm$T.exr" 0 >/dev/null 2>&1; then
            echo "   the farm of $T workers' image DIFFERS from the standalone one"
        fi
    fi
done
