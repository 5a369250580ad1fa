#!/bin/bash
# bench/reliability.sh: the fault suite of docs/reliability.md, repeated.
#
#   bench/reliability.sh [BIN_DIR] [RUNS]      (defaults: build/bin, 10)
#
# Renders a small scene (64x48, 48 tiles of 8) with the embedded master
# and prints one table row per scenario: runs, renders completed, images
# identical to the standalone render (exrcmp, every sample), and tiles
# lost (tiles the master had taken before it died that were in neither the
# journal nor the image afterwards). Moments of failure are chosen at
# random by tiles taken, never by time. The disk-full rows need root
# (a small tmpfs is mounted in a private mount namespace); without root
# they are skipped. Every process is bounded by timeout -k and reaped.
set -u
BIN=${1:-build/bin}
RUNS=${2:-10}
BIN=$(cd "$BIN" && pwd) || exit 2
for p in aafarm-master aafarm-worker exrcmp; do
    [ -x "$BIN/$p" ] || { echo "reliability.sh: $BIN/$p not built" >&2; exit 2; }
done
WORK=$(mktemp -d /tmp/aafarm-rel-XXXXXX)
KEEP=${AAFARM_REL_KEEP:-$WORK/failed}   # logs of failed runs (kept when set)
mkdir -p "$KEEP"
trap 'kill -9 $(jobs -p) 2> /dev/null; rm -rf "$WORK"' EXIT
export TMPDIR=$WORK
cd "$WORK" || exit 2

mkdir shaders
cat > shaders/twave.sl <<'EOF'
displacement twave(float Km = 0.1; float frequency = 4; float decay = 2)
{
    float ds = s - 0.5, dt = t - 0.5;
    float r = sqrt(ds * ds + dt * dt);
    P += Km * exp(-decay * r) * sin(2 * PI * frequency * r) * normalize(N);
    N = calculatenormal(P);
}
EOF
cat > shaders/tmatte.sl <<'EOF'
surface tmatte(float Ka = 1; float Kd = 1)
{
    normal Nf = faceforward(normalize(N), I);
    Oi = Os;
    Ci = Os * Cs * (Ka * ambient() + Kd * diffuse(Nf));
}
EOF
cat > scene.rib <<'EOF'
Option "searchpath" "shader" ["shaders:&"]
Format 64 48 1
PixelSamples 2 2
Projection "perspective" "fov" [25]
Translate 0 0.08 3.5
Rotate -35 1 0 0
WorldBegin
  LightSource "ambientlight" 1 "intensity" [0.15]
  LightSource "distantlight" 2 "intensity" [1.0] "from" [-1 2 -2] "to" [0 0 0]
  AttributeBegin
    Color [0.8 0.75 0.6]
    Surface "tmatte"
    Displacement "twave"
    Sides 2
    Polygon "P" [-1 0 -1  -1 0 1  1 0 1  1 0 -1]
  AttributeEnd
WorldEnd
EOF
printf '#!/bin/sh\nexec %s --tile-delay 50 "$@"\n' "$BIN/aafarm-worker" > slow-worker.sh
chmod +x slow-worker.sh
timeout -k 5 120 "$BIN/aafarm-worker" --standalone scene.rib -o ref.exr --tile 8 -q || exit 2
TILES=48

count() { grep -c -- "$2" "$1" 2>/dev/null || true; }

# wait_tiles LOG N PID: until LOG shows N taken tiles (or PID ended)
wait_tiles() {
    local i
    for ((i = 0; i < 3000; i++)); do
        [ "$(count "$1" 'took tile ')" -ge "$2" ] && return 0
        kill -0 "$3" 2>/dev/null || return 1
        sleep 0.01
    done
    return 1
}

master() {   # master OUT LOG [options...]: in the background, pid in $MPID
    local out=$1 log=$2
    shift 2
    : > "$log"   # empty now: the child truncating it later would race with wait_tiles
    "$BIN/aafarm-master" scene.rib -o "$out" --tile 8 --local-workers 2 \
        --worker-binary ./slow-worker.sh --duplicates 0 -v "$@" >> "$log" 2>&1 &
    MPID=$!
}

master_fg() {   # master_fg OUT LOG [options...]: bounded, returns its exit status
    local out=$1 log=$2
    shift 2
    timeout -k 5 120 "$BIN/aafarm-master" scene.rib -o "$out" --tile 8 --local-workers 2 \
        --worker-binary ./slow-worker.sh --duplicates 0 -v "$@" > "$log" 2>&1
}

resumed_of() { sed -n 's/.*resuming: \([0-9]*\) of.*/\1/p' "$1" | head -1; }

identical() { "$BIN/exrcmp" ref.exr "$1" > /dev/null 2>&1; }

ROWS=()
row() { ROWS+=("| $1 | $2 | $3 | $4 | $5 |"); }

# ---- the master killed (SIGKILL) at a random moment, then --resume ----
kill_and_resume() {   # kill_and_resume CORRUPT(0/1): sets C I L; 1: not killed in time
    local n=$((1 + RANDOM % (TILES - 16))) out=k.exr took resumed rc
    rm -f k.exr*
    master "$out" k1.log
    if ! wait_tiles k1.log "$n" "$MPID"; then wait "$MPID"; return 1; fi
    kill -9 "$MPID"
    wait "$MPID" 2>/dev/null
    [ $? = 137 ] || return 1   # it finished before the kill: not a run of this scenario
    took=$(count k1.log 'took tile ')
    if [ "$1" = 1 ]; then   # flip the last byte of the last record, add a torn one
        local size
        size=$(stat -c %s "$out.journal")
        printf '\x55' | dd of="$out.journal" bs=1 seek=$((size - 1)) conv=notrunc 2> /dev/null
        printf 'TILE\x05\x00\x00\x00\xff\x0f\x00\x00torn' >> "$out.journal"
        took=$((took - 1))   # that record is damaged on purpose
    fi
    master_fg "$out" k2.log --resume --stats-json k2.json
    rc=$?
    resumed=$(resumed_of k2.log)
    [ "$rc" = 0 ] && C=$((C + 1))
    [ "$rc" = 0 ] && identical "$out" && I=$((I + 1))
    [ -z "$resumed" ] && resumed=0
    [ "$resumed" -lt "$took" ] && L=$((L + took - resumed))
    # no tile rendered twice: the resumed master granted only the missing ones
    local grants
    grants=$(sed -n 's/.*"grants": \([0-9]*\).*/\1/p' k2.json)
    [ -n "$resumed" ] && [ "$grants" != $((TILES - resumed)) ] && TWICE=$((TWICE + 1))
    [ "$(ls -d aafarm-?????? 2> /dev/null | wc -l)" != 0 ] && LEFT=$((LEFT + 1))
    [ "$(ls k.exr.* 2> /dev/null | wc -l)" != 0 ] && LEFT=$((LEFT + 1))
    [ "$rc" = 0 ] && identical "$out" || cp k1.log k2.log "$KEEP/" 2> /dev/null
    return 0
}

for corrupt in 0 1; do
    C=0 I=0 L=0 TWICE=0 LEFT=0
    tries=0
    for ((r = 0; r < RUNS && tries < 3 * RUNS; r++, tries++)); do
        kill_and_resume "$corrupt" || r=$((r - 1))
    done
    [ "$r" -lt "$RUNS" ] && echo "  (only $r runs: the others finished before the kill)" >&2
    name="master kill -9 at a random tile, then --resume"
    [ "$corrupt" = 1 ] && name="same, journal tail torn and last record corrupted"
    row "$name" "$r" "$C" "$I" "$L"
    echo "  ($name: $TWICE runs granted an already taken tile, $LEFT left files behind)" >&2
done

# ---- a worker killed (SIGKILL) mid-render ----
C=0 I=0 L=0 tries=0
for ((r = 0; r < RUNS && tries < 3 * RUNS; r++, tries++)); do
    rm -f w.exr*
    : > w.log
    "$BIN/aafarm-master" scene.rib -o w.exr --tile 8 --bind tcp://127.0.0.1:* --heartbeat 250 \
        --liveness 4 -v >> w.log 2>&1 &
    MPID=$!
    for ((i = 0; i < 500; i++)); do grep -q 'listening on ' w.log && break; sleep 0.01; done
    ep=$(sed -n 's/.*listening on \(.*\)/\1/p' w.log | head -1)
    "$BIN/aafarm-worker" --connect "$ep" --name victim --threads 1 --tile-delay 40 -q &
    V=$!
    "$BIN/aafarm-worker" --connect "$ep" --name other --threads 1 --tile-delay 20 -q &
    O=$!
    n=$((1 + RANDOM % 6))
    for ((i = 0; i < 3000; i++)); do
        [ "$(count w.log ' from victim (lease')" -ge "$n" ] && break
        kill -0 "$MPID" 2> /dev/null || break
        sleep 0.01
    done
    if ! kill -0 "$MPID" 2> /dev/null || [ "$(count w.log 'took tile ')" -ge "$TILES" ]; then
        kill -9 "$V" "$O" 2> /dev/null   # finished before the kill: not a run of this scenario
        wait "$MPID" "$V" "$O" 2> /dev/null
        r=$((r - 1))
        continue
    fi
    kill -9 "$V" 2> /dev/null
    for ((i = 0; i < 12000; i++)); do kill -0 "$MPID" 2> /dev/null || break; sleep 0.01; done
    kill -9 "$MPID" 2> /dev/null   # only if it ran past 120 s
    wait "$MPID"
    rc=$?
    kill -9 "$V" 2> /dev/null
    kill "$O" 2> /dev/null
    wait "$V" "$O" 2> /dev/null
    [ "$(count w.log 'worker victim missed')" -ge 1 ] || [ "$(count w.log 'worker victim disconnected')" -ge 1 ] ||
        echo "  (worker run $r: the victim's loss was not logged)" >&2
    [ "$rc" = 0 ] && identical w.exr || cp w.log "$KEEP/w-$r.log"
    [ "$rc" = 0 ] && C=$((C + 1))
    [ "$rc" = 0 ] && identical w.exr && I=$((I + 1))
done
row "worker kill -9 mid-render (--bind, 2 workers)" "$r" "$C" "$I" "$L"

# ---- the output's disk full mid-render, --resume once there is space ----
if [ "$(id -u)" = 0 ] && unshare --mount true 2> /dev/null; then
    cat > diskfull.sh <<'EOF'
set -u
BIN=$1 RUNS=$2
mkdir -p mnt
mount --make-rprivate / 2> /dev/null
C=0 I=0 L=0 H=0
for ((r = 0; r < RUNS; r++)); do
    size=$((8 + RANDOM % 16))k   # the image needs about 25 KB
    mount -t tmpfs -o size=$size tmpfs mnt || exit 2
    timeout -k 5 120 "$BIN/aafarm-master" scene.rib -o mnt/d.exr --tile 8 --local-workers 2 -v \
        > d1.log 2>&1
    rc1=$?
    took=$(grep -c 'took tile ' d1.log)
    mount -o remount,size=256k mnt
    timeout -k 5 120 "$BIN/aafarm-master" scene.rib -o mnt/d.exr --tile 8 --local-workers 2 \
        --resume > d2.log 2>&1
    rc=$?
    resumed=$(sed -n 's/.*resuming: \([0-9]*\) of.*/\1/p' d2.log | head -1)
    [ "$rc1" = 1 ] && [ "$rc" = 0 ] && C=$((C + 1))
    [ "$rc" = 0 ] && "$BIN/exrcmp" ref.exr mnt/d.exr > /dev/null 2>&1 && I=$((I + 1))
    [ -n "$resumed" ] && [ "$resumed" -lt "$took" ] && L=$((L + took - resumed))
    [ "$(ls mnt)" = d.exr ] || echo "  leftovers: $(ls mnt)" >&2
    umount -l mnt
    # full before the header: a clean failure within the time limit
    mount -t tmpfs -o size=8k tmpfs mnt
    head -c 8192 /dev/zero > mnt/filler 2> /dev/null
    timeout -k 5 60 "$BIN/aafarm-master" scene.rib -o mnt/h.exr --tile 8 --local-workers 2 \
        > h.log 2>&1
    [ $? = 1 ] && [ "$(ls mnt)" = filler ] && grep -q 'No space left' h.log && H=$((H + 1))
    umount -l mnt
done
echo "$C $I $L $H"
EOF
    read -r C I L H < <(unshare --mount bash diskfull.sh "$BIN" "$RUNS")
    row "output disk full mid-render (exit 1), --resume after space is back" "$RUNS" "$C" "$I" "$L"
    row "output disk full at the header (completed = exit 1 within 60 s, nothing left)" "$RUNS" "$H" "n/a" "n/a"
else
    echo "  (disk-full rows skipped: need root and mount namespaces)" >&2
fi

echo "| scenario | runs | completed | identical | tiles lost |"
echo "|---|---|---|---|---|"
for r in "${ROWS[@]}"; do echo "$r"; done
