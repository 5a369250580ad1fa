#!/usr/bin/env bash
# bench/tail_replay.sh: how much of a many-core render's idle time is the
# frame's tail, on a machine of any size. Renders SCENE once on one local
# worker of one thread (aafarm-master --local-workers 1 -v: each tile's
# seconds), then replays those seconds through the standalone renderer's
# scheduling for THREADS threads (worker/tile_runs.c: contiguous runs, a
# thread whose run is done takes the back half of the largest run left),
# in event order, and prints when the last thread ends against the work a
# thread has (busy = work / (threads x end)); and the same with the tail
# shared by all threads (worker/tile_share.h; blocks taken as fluid, so an
# upper bound). Figures, never a verdict.
#
#   bash bench/tail_replay.sh [BIN_DIR] [SCENE.rib] [THREADS] [SCALE]
#       defaults: build/bin, scenes/gallery.rib, 16, 2 (SCALE multiplies
#       the scene's Format, as thread_scaling.sh's SCALE does)
set -u
BIN=${1:-build/bin}
SCENE=${2:-scenes/gallery.rib}
THREADS=${3:-16}
SCALE=${4:-2}
[ -x "$BIN/aafarm-master" ] || { echo "tail_replay.sh: $BIN/aafarm-master not built" >&2; exit 2; }
[ -r "$SCENE" ] || { echo "tail_replay.sh: cannot read $SCENE" >&2; exit 2; }
case "$THREADS$SCALE" in *[!0-9]*) echo "tail_replay.sh: THREADS and SCALE are numbers" >&2; exit 2;; esac
WORK=$(mktemp -d /tmp/aafarm-tail-XXXXXX)
COPY=$(dirname "$SCENE")/.tail-$$-$(basename "$SCENE")   # beside it: its search paths
trap 'rm -rf "$WORK"; rm -f "$COPY"' EXIT
awk -v k="$SCALE" '$1 == "Format" {$2 *= k; $3 *= k} {print}' "$SCENE" >"$COPY"
timeout -k 5 900 "$BIN/aafarm-master" "$COPY" -o "$WORK/out.exr" --local-workers 1 -v \
    >"$WORK/log" 2>&1 || { echo "tail_replay.sh: the render failed: $(tail -2 "$WORK/log")" >&2; exit 1; }
# "tile N sent (lease L, B bytes, S s, ..." -> "N S"
sed -n 's/.*tile \([0-9]*\) sent (lease [0-9]*, [0-9]* bytes, \([0-9.]*\) s.*/\1 \2/p' \
    "$WORK/log" >"$WORK/times"
echo "tail_replay: $(basename "$SCENE") x$SCALE, $(wc -l <"$WORK/times") tiles, $THREADS threads"
python3 - "$WORK/times" "$THREADS" <<'PY'
import heapq, sys
times = {}
for line in open(sys.argv[1]):
    i, s = line.split()
    times[int(i)] = float(s)
n, T = max(times) + 1, int(sys.argv[2])
t = [times.get(i, 0.0) for i in range(n)]
runs = [[n * k // T, n * (k + 1) // T] for k in range(T)]
def take(k):                      # tile_runs_take
    r = runs[k]
    if r[0] >= r[1]:
        v = max(range(T), key=lambda j: runs[j][1] - runs[j][0])
        left = runs[v][1] - runs[v][0]
        if left <= 0:
            return None
        mid = runs[v][0] if left == 1 else runs[v][0] + (left + 1) // 2
        r[0], r[1] = mid, runs[v][1]
        runs[v][1] = mid
    i = r[0]
    r[0] += 1
    return i
events, end = [], [0.0] * T
for k in range(T):
    i = take(k)
    if i is not None:
        heapq.heappush(events, (t[i], k))
while events:
    e, k = heapq.heappop(events)
    i = take(k)
    if i is None:
        end[k] = e
    else:
        heapq.heappush(events, (e + t[i], k))
work = sum(t) / T
last, first = max(end), min(end)
shared = first + sum(x - first for x in end) / T
print("tile seconds: mean %.4f, slowest %.4f (%.1fx the mean)" % (sum(t) / n, max(t), max(t) * n / sum(t)))
print("work a thread %.3f s; tile runs alone: the last thread ends at %.3f s, busy %.1f %%"
      % (work, last, 100 * work / last))
print("the tail shared (fluid): ends at %.3f s, busy %.1f %%" % (shared, 100 * work / shared))
PY
