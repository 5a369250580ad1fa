#!/bin/bash
# bench/file_transfer.sh: job files on the farm (docs/textures.md, "The wire
# and the cache"): how long shipping a data file to a worker takes, and
# what a second job with the same file costs.
#
#   bench/file_transfer.sh [BIN_DIR] [SIZE_MIB]      (defaults: build/bin, 256)
#
# A tiny scene (16x16, one tile) whose shader names a SIZE_MIB data file is
# rendered by a master and one worker over tcp://127.0.0.1, once with an
# empty store (cold: the file is fetched) and once more with another job
# naming the same file (warm: a store hit), for a few --file-chunk /
# --file-inflight settings. Printed per row: the seconds from the first
# chunk the master sent to the worker's FilesReady (the worker's hash of the
# whole file included; --stats-json "file_seconds"), the rate that makes,
# the wall seconds of each render (--stats-json "seconds": process starts,
# the worker hashing the file on first use, ...) and the file bytes sent.
# Figures, never a pass/fail. Every process is bounded by timeout -k and
# reaped.
set -u
BIN=${1:-build/bin}
SIZE=${2:-256}
BIN=$(cd "$BIN" && pwd) || exit 2
for p in aafarm-master aafarm-worker; do
    [ -x "$BIN/$p" ] || { echo "file_transfer.sh: $BIN/$p not built" >&2; exit 2; }
done
WORK=$(mktemp -d /tmp/aafarm-ftb-XXXXXX)
trap 'kill -9 $(jobs -p) 2> /dev/null; wait 2> /dev/null; rm -rf "$WORK"' EXIT
cd "$WORK" || exit 2
mkdir shaders maps
cat > shaders/hmap.sl <<'EOF'
displacement hmap(float Km = 0.1; string texname = "")
{
    P += Km * sin(10 * s) * normalize(N);
    N = calculatenormal(P);
}
EOF
scene() {   # $1: Km (another Km, another job)
    cat > scene.rib <<EOF
Option "searchpath" "shader" ["shaders:&"] "texture" ["maps:&"]
Format 16 16 1
PixelSamples 1 1
Projection "perspective" "fov" [25]
Translate 0 0 3.5
WorldBegin
  Displacement "hmap" "float Km" [$1] "string texname" "big.dat"
  Patch "bilinear" "P" [-1 -1 0  1 -1 0  -1 1 0  1 1 0]
WorldEnd
EOF
}
head -c $((SIZE * 1048576)) /dev/urandom > maps/big.dat

json() {   # $1 file, $2 key: the first number after "key":
    sed -n "s/.*\"$2\": \([0-9.]*\).*/\1/p" "$1" | head -1
}

render() {   # $1 tag, $2 cache, $3 chunk, $4 inflight -> stats-$1.json
    timeout -k 5 300 "$BIN/aafarm-master" scene.rib -o "out-$1.exr" --bind 'tcp://127.0.0.1:*' \
        --tile 16 --stats-json "stats-$1.json" > "master-$1.log" 2>&1 &
    local m=$!
    local ep=""
    for _ in $(seq 1 300); do
        ep=$(sed -n 's/.*listening on \(tcp:[^ ]*\).*/\1/p' "master-$1.log" | head -1)
        [ -n "$ep" ] && break
        sleep 0.05
    done
    timeout -k 5 300 "$BIN/aafarm-worker" --connect "$ep" --threads 1 --file-cache "$2" \
        --file-chunk "$3" --file-inflight "$4" -q > "worker-$1.log" 2>&1 &
    local w=$!
    wait $m
    kill -TERM $w 2> /dev/null
    wait $w 2> /dev/null
}

printf "file of %d MiB, master and one worker on 127.0.0.1\n" "$SIZE"
printf "%8s %9s %9s %9s %8s %8s %12s %12s\n" chunk inflight "fetch s" "MiB/s" "cold s" \
    "warm s" "bytes cold" "bytes warm"
for setting in "256K 2M" "1M 8M" "4M 16M" "16M 64M"; do
    set -- $setting
    cache="$WORK/cache-$1"
    scene 0.1
    render "cold-$1" "$cache" "$1" "$2"
    scene 0.05
    render "warm-$1" "$cache" "$1" "$2"
    cold=$(json "stats-cold-$1.json" seconds)
    warm=$(json "stats-warm-$1.json" seconds)
    bc=$(json "stats-cold-$1.json" file_bytes_sent)
    bw=$(json "stats-warm-$1.json" file_bytes_sent)
    fetch=$(json "stats-cold-$1.json" file_seconds)
    rate=$(awk -v s="$SIZE" -v f="$fetch" 'BEGIN { if (f > 0) printf "%.0f", s / f; else print "-" }')
    printf "%8s %9s %9.2f %9s %8.2f %8.2f %12s %12s\n" "$1" "$2" "$fetch" "$rate" "$cold" "$warm" \
        "$bc" "$bw"
done
