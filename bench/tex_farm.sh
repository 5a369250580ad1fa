#!/bin/bash
# bench/tex_farm.sh: a big displacement map on the farm (docs/textures.md,
# "Memory"): the time to the first tile and the worker's peak resident
# memory, with a cold and a warm file store.
#
#   bench/tex_farm.sh [BIN_DIR] [SIZE] [TEXTURE_BYTES]
#                     (defaults: build/bin, 16384, 256M)
#
# tex_bench --write makes a SIZE x SIZE one-channel float map as an
# aafarm-maketx file (mean, min, max; in a temporary folder, removed at the
# end). A terrain (a patch displaced by the map, 96x54 pixels, 16-pixel
# tiles) is rendered by a master and one worker (2 threads,
# --texture-bytes TEXTURE_BYTES) over tcp://127.0.0.1 twice:
#   cold: the worker's store is empty, the map is shipped from the master;
#   warm: another job (another Km) naming the same map, found in the store.
# Printed per run: seconds from the worker's start to its job being ready
# (files present, hashed, job compiled: "ready"), to its first tile sent
# ("first tile", read from its -v log every 50 ms) and to the end of the
# render ("done"); the map bytes the master sent; and the worker's peak
# resident memory (GNU time's %M), which shows the budget. The master hashes the map
# before it listens (not counted); a new worker process hashes a file it
# uses once (counted: it is part of the time to the first tile).
# Figures, never a pass/fail. Every process is bounded by timeout -k and
# reaped.
set -u
BIN=${1:-build/bin}
SIZE=${2:-16384}
TEXBYTES=${3:-256M}
BIN=$(cd "$BIN" && pwd) || exit 2
for p in aafarm-master aafarm-worker tex_bench; do
    [ -x "$BIN/$p" ] || { echo "tex_farm.sh: $BIN/$p not built" >&2; exit 2; }
done
[ -x /usr/bin/time ] || { echo "tex_farm.sh: needs GNU time (/usr/bin/time)" >&2; exit 2; }
WORK=$(mktemp -d /tmp/aafarm-texfarm-XXXXXX)
trap 'kill -9 $(jobs -p) 2> /dev/null; wait 2> /dev/null; rm -rf "$WORK"' EXIT
cd "$WORK" || exit 2
mkdir shaders maps
cat > shaders/hmap.sl <<'EOF'
displacement hmap(float Km = 0.2; string texname = "")
{
    float fw = max(abs(Du(s) * du) + abs(Dv(s) * dv), abs(Du(t) * du) + abs(Dv(t) * dv));
    P += Km * texture(texname[0], s, t, "blur", fw) * normalize(N);
    N = calculatenormal(P);
}
EOF
scene() {   # $1: Km (another Km, another job)
    cat > scene.rib <<EOF
Option "searchpath" "shader" ["shaders:&"] "texture" ["maps:&"]
Format 96 54 1
PixelSamples 1 1
Projection "perspective" "fov" [40]
Translate 0 -0.3 4.2
Rotate -30 1 0 0
WorldBegin
  LightSource "distantlight" 1 "from" [-2 3 -1] "to" [0 0 0]
  Attribute "displacementbound" "sphere" [0.45]
  Displacement "hmap" "float Km" [$1] "string texname" "big.exr"
  Rotate -90 1 0 0
  Patch "bilinear" "P" [-2 -2 0  2 -2 0  -2 2 0  2 2 0]
WorldEnd
EOF
}
t0=$EPOCHREALTIME
timeout -k 5 1200 "$BIN/tex_bench" --write "$SIZE" maps/big.exr || { echo "tex_farm.sh: cannot write the map" >&2; exit 1; }
gen=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }')
mib=$(( $(stat -c %s maps/big.exr) / 1048576 ))

json() {   # $1 file, $2 key: the first number after "key":
    sed -n "s/.*\"$2\": \([0-9.]*\).*/\1/p" "$1" | head -1
}

us() {   # microseconds now
    local t=${EPOCHREALTIME/./}
    echo $((10#$t))
}

since() {   # seconds since $1 (microseconds), 2 decimals
    local t=$(( ($(us) - $1) / 10000 ))
    printf '%d.%02d' $((t / 100)) $((t % 100))
}

render() {   # $1 tag -> stats-$1.json, worker-$1.log, rss-$1.txt, times-$1.txt
    timeout -k 5 900 "$BIN/aafarm-master" scene.rib -o "out-$1.exr" --bind 'tcp://127.0.0.1:*' \
        --tile 16 --stats-json "stats-$1.json" > "master-$1.log" 2>&1 &
    local m=$!
    local ep=""
    for _ in $(seq 1 1200); do
        ep=$(sed -n 's/.*listening on \(tcp:[^ ]*\).*/\1/p' "master-$1.log" | head -1)
        [ -n "$ep" ] && break
        sleep 0.1
    done
    [ -n "$ep" ] || { echo "tex_farm.sh: the master did not start" >&2; cat "master-$1.log" >&2; exit 1; }
    local start ready="-" first="-"
    start=$(us)
    /usr/bin/time -o "rss-$1.txt" -f '%M' timeout -k 5 900 "$BIN/aafarm-worker" --connect "$ep" \
        --threads 2 --file-cache "$WORK/store" --texture-bytes "$TEXBYTES" -v \
        > /dev/null 2> "worker-$1.log" &
    local w=$!
    # the worker's log, read every 50 ms: when its job was ready (files
    # present and the job compiled) and when it sent its first tile
    while kill -0 "$m" 2> /dev/null; do
        [ "$ready" = - ] && grep -qs ') ready$' "worker-$1.log" && ready=$(since "$start")
        [ "$first" = - ] && grep -qs 'tile [0-9]* sent' "worker-$1.log" && first=$(since "$start")
        sleep 0.05
    done
    wait "$m"
    echo "$ready $first $(since "$start")" > "times-$1.txt"
    local tpid
    tpid=$(pgrep -P "$w" | head -1)          # timeout, GNU time's child: it passes TERM on
    [ -n "$tpid" ] && kill -TERM "$tpid" 2> /dev/null
    wait "$w" 2> /dev/null
}

printf "map %d x %d floats: %d MiB file (mean, min, max), made in %s s; worker --texture-bytes %s\n" \
    "$SIZE" "$SIZE" "$mib" "$gen" "$TEXBYTES"
printf "%6s %8s %12s %8s %12s %16s\n" run "ready s" "first tile s" "done s" "bytes sent" \
    "worker peak MiB"
scene 0.2
render cold
scene 0.15
render warm
for r in cold warm; do
    read -r ready first done_s < "times-$r.txt"
    sent=$(json "stats-$r.json" file_bytes_sent)
    rss=$(tail -1 "rss-$r.txt" | awk '{ printf "%.0f", $1 / 1024 }')
    printf "%6s %8s %12s %8s %12s %16s\n" "$r" "$ready" "$first" "$done_s" "${sent:--}" "${rss:--}"
done
