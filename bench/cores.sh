#!/usr/bin/env bash
# bench/cores.sh: the figures only a machine of many cores gives, in one
# run (a lent 16-core machine: docs/benchmarks.md "Many cores"):
#   1. issue 24's scaling: gallery, vase and wave at twice their size, the
#      standalone renderer at 1 and at all cores' threads, and a master
#      with as many local workers (bench/thread_scaling.sh FARM=1 SCALE=2)
#   2. issue 23's asset: a 1M-face displaced terrain with instanced rocks
#      at 640x480, standalone and on 2 workers of half the cores each,
#      each worker's peak memory (bench/scale.sh part 2)
#   3. mesh_bench 1,000,000 quads, RUNS times (parse + world over all cores)
#   4. the opt-in 10,000,000-quad row and the subdivision torus (scale.sh
#      part 1)
# Usage: bash bench/cores.sh [BUILD_DIR] [LOG]   (default build; LOG: also
# append everything to this file). Each part is bounded by timeout -k;
# figures only, nothing fails on time.
#   ONLY="1 3"   run these parts alone (a lent machine's 15 minutes hold
#                parts 1 and 3: about 5 minutes; parts 2 and 4 take up to
#                5 minutes each)
#   PEER=DIR     part 1 also renders each frame with DIR's aafarm-worker
#                and aafarm-master (an older build, carried beside this
#                one), in the same run: the change's effect on one machine
set -u
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:-$here/build}" && pwd)"
LOG=${2:-/dev/null}
RUNS=${RUNS:-3}
N=$(nproc)
cd "$here"
say() { echo "$@" | tee -a "$LOG"; }
part() {  # part SECONDS CMD...: one bounded part, its output kept in LOG
    local limit=$1
    shift
    timeout -k 5 "$limit" "$@" 2>&1 | tee -a "$LOG"
    local rc=${PIPESTATUS[0]}
    [ "$rc" = 0 ] || say "   (exit $rc$([ "$rc" = 124 ] && echo ": stopped at ${limit} s"))"
}
# physical cores and hardware threads per core (a vCPU may be a
# hyperthread: 16 vCPUs of 8 cores cannot give 16x), from sysfs
topology() {
    local d cores
    cores=$(for d in /sys/devices/system/cpu/cpu[0-9]*/topology; do
                [ -r "$d/core_id" ] && echo "$(cat "$d/physical_package_id" 2>/dev/null):$(cat "$d/core_id")"
            done | sort -u | wc -l)
    if [ "$cores" -gt 0 ]; then
        echo "$cores physical cores, $(awk -v n="$N" -v c="$cores" 'BEGIN {printf "%g", n / c}') hardware threads a core"
    else
        echo "topology unknown"
    fi
}
say "== cores.sh: $N cores ($(topology)), $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-), load $(cut -d' ' -f1 /proc/loadavg)"
ONLY=${ONLY:-1 2 3 4}
PEER=${PEER:-}
wanted() { case " $ONLY " in *" $1 "*) return 0;; esac; return 1; }
if wanted 1; then
    say "== 1. threads and local workers (the standalone's tail_blocks: blocks of a tile traced by threads with no tile left)"
    for s in gallery vase wave; do
        THREADS="$N" FARM=1 SCALE=2 part 240 bash bench/thread_scaling.sh "$build/bin" "scenes/$s.rib" "$RUNS"
        [ -z "$PEER" ] || { say "   the same with $PEER:"
            THREADS="$N" FARM=1 SCALE=2 part 240 bash bench/thread_scaling.sh "$PEER" "scenes/$s.rib" "$RUNS"; }
        part 60 "$build/bin/aafarm-worker" --standalone "scenes/$s.rib" -o /tmp/cores-$$.exr \
            -t "$N" --stats -q 2>&1 | grep -E "tail_blocks" | sed "s/^/   $s, $N threads:/"
        rm -f /tmp/cores-$$.exr
    done
fi
if wanted 2; then
    say "== 2. the 1M-face asset at 640x480"
    PARTS=2 THREADS=$((N / 2)) part 300 bash bench/scale.sh "$build"
fi
if wanted 3; then
    say "== 3. mesh_bench 1000000, $RUNS runs"
    for ((r = 0; r < RUNS; r++)); do
        part 120 /usr/bin/time -f "   (whole process: %e s wall, %U s user, peak %M KB)" "$build/bin/mesh_bench" 1000000
    done
fi
if wanted 4; then
    say "== 4. mesh_bench 10000000 and the subdivision torus"
    PARTS=1 FACES=10000000 part 300 bash bench/scale.sh "$build"
fi
