#!/usr/bin/env bash
# bench/scale.sh: production scale (issue 23), the aims' figures:
#   1. mesh_bench: a torus of PointsPolygons quads to FACES (default
#      1,000,000; 10000000 is the opt-in row): parse, world, parse+world
#      (the aim), render seconds, bytes per face, peak RSS; the same torus as a
#      SubdivisionMesh cage to SUBDIV_FACES (default 100,000)
#   2. a production-style asset (bench/asset_gen: a displaced, textured
#      terrain of ASSET_FACES quads from a gzip archive and ROCKS instanced
#      subdivision rocks; ROCK_KINDS=R: R recorded rocks scattered by rigid
#      motions, references to them) rendered at ASSET_W x ASSET_H by a master with
#      two workers on this host (their peak RSS each) and standalone (the
#      farm image must equal it)
#   3. INSTANCES (default 1,000,000) instances of a 1000-face undisplaced
#      mesh (bench/asset_gen --instances: references, docs/renderer.md
#      "Instances as references") rendered standalone at 256 x 256: wall
#      seconds (parse + world + render) and peak RSS
# Usage: bash bench/scale.sh [BUILD_DIR]   (default build; a Release or
# RelWithDebInfo build of the whole tree). Prints tables; never fails on
# timing. Environment: FACES, SUBDIV_FACES, ASSET_FACES, ROCKS, ROCK_KINDS, ASSET_W,
# ASSET_H, THREADS (per worker, default 1), INSTANCES, PARTS (which of
# 1 2 3 to run, default all; the SubdivisionMesh row is part 1).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:-$here/build}" && pwd)"
FACES=${FACES:-1000000}
SUBDIV_FACES=${SUBDIV_FACES:-100000}
ASSET_FACES=${ASSET_FACES:-1000000}
ROCKS=${ROCKS:-200}
ROCK_KINDS=${ROCK_KINDS:-0}
ASSET_W=${ASSET_W:-640}
ASSET_H=${ASSET_H:-480}
THREADS=${THREADS:-1}
INSTANCES=${INSTANCES:-1000000}
PARTS=" ${PARTS:-1 2 3} "
for p in mesh_bench asset_gen aafarm-master aafarm-worker exrcmp; do
  [ -x "$build/bin/$p" ] || { echo "scale.sh: $build/bin/$p missing: build the tree first" >&2; exit 1; }
done
echo "== machine: $(nproc) cores, $(free -g | awk '/Mem:/{print $2}') GiB, load $(cut -d' ' -f1 /proc/loadavg); aafarm $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?')"
if [[ "$PARTS" == *" 1 "* ]]; then
echo "== 1. mesh_bench (PointsPolygons torus)"
/usr/bin/time -f "   (whole process: %e s wall, peak %M KB)" "$build/bin/mesh_bench" "$FACES"
echo "== 1b. mesh_bench (SubdivisionMesh torus)"
/usr/bin/time -f "   (whole process: %e s wall, peak %M KB)" "$build/bin/mesh_bench" "$SUBDIV_FACES" subdiv
fi

work=$(mktemp -d)
# child_of PID: the first process whose parent is PID (from /proc, so that
# no procps is needed)
child_of() {
  local st
  for st in /proc/[0-9]*/stat; do
    awk -v p="$1" '$4 == p {print $1; found = 1} END {exit !found}' "$st" 2>/dev/null && return 0
  done
  return 0
}
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; rm -rf "$work"; }
trap cleanup EXIT
if [[ "$PARTS" == *" 2 "* ]]; then
echo "== 2. asset: $ASSET_FACES terrain faces, $ROCKS rocks (kinds: $ROCK_KINDS), ${ASSET_W}x${ASSET_H}"
if [ ! -f "$here/scenes/textures/terrain_height.exr" ]; then
  bash "$here/scenes/make_textures.sh" "$build" >/dev/null
fi
"$build/bin/asset_gen" --faces "$ASSET_FACES" --rocks "$ROCKS" --rock-kinds "$ROCK_KINDS" --format "$ASSET_W" "$ASSET_H" \
  --shaders "$here/scenes/shaders" --textures "$here/scenes/textures" "$work/asset"
ls -l "$work/asset" | awk 'NR>1 {printf "   %s %d bytes\n", $9, $5}'
cd "$work/asset"
/usr/bin/time -f "standalone (1 process, $((2 * THREADS)) threads): %e s wall, %U s user, peak %M KB" \
  timeout -k 10 3600 "$build/bin/aafarm-worker" --standalone asset.rib -o "$work/standalone.exr" \
  -t $((2 * THREADS)) 2>&1 | tail -1
port=$((20000 + RANDOM % 20000))
timeout -k 10 3600 "$build/bin/aafarm-master" asset.rib -o "$work/farm.exr" \
  --bind "tcp://127.0.0.1:$port" --local-workers 0 --insecure \
  --stats-json "$work/stats.json" >"$work/master.log" 2>&1 &
master=$!
pids+=("$master")
wpids=()
for w in 1 2; do
  (cd "$work" && exec timeout -k 10 3600 "$build/bin/aafarm-worker" --connect "tcp://127.0.0.1:$port" \
     -t "$THREADS" --name "w$w" --file-cache "$work/store$w" >"$work/w$w.log" 2>&1) &
  wpids+=("$!")
  pids+=("$!")
done
start=$(date +%s.%N)
rc=0
wait "$master" || rc=$?
echo "farm (master + 2 workers of $THREADS thread(s)): exit $rc, $(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.2f", b - a}') s wall"
for w in 1 2; do
  # the worker (timeout's child): its peak resident memory, then stop it
  wp=$(child_of "${wpids[$((w - 1))]}")
  peak=$(awk '/VmHWM/ {print $2 " " $3}' "/proc/${wp:-0}/status" 2>/dev/null || echo "?")
  echo "worker $w: peak RSS $peak"
  grep -i -E "files are here|archive" "$work/w$w.log" | head -2 | sed 's/^/   /'
  kill -TERM "${wpids[$((w - 1))]}" 2>/dev/null || true
  wait "${wpids[$((w - 1))]}" 2>/dev/null || true
done
if [ "$rc" -eq 0 ] && "$build/bin/exrcmp" "$work/standalone.exr" "$work/farm.exr" 0 >/dev/null; then
  echo "farm image = standalone image (exrcmp, tolerance 0)"
else
  echo "farm image differs from the standalone one, or the farm failed: see $work (kept)"
  tail -5 "$work/master.log"
  trap - EXIT
fi

fi

if [[ "$PARTS" == *" 3 "* ]]; then
echo "== 3. $INSTANCES instances of a 1000-face mesh, 256x256"
"$build/bin/asset_gen" --instances "$INSTANCES" --format 256 256 \
  --shaders "$here/scenes/shaders" --textures "$here/scenes/textures" "$work/inst"
ls -l "$work/inst" | awk 'NR>1 {printf "   %s %d bytes\n", $9, $5}'
(cd "$work/inst" && /usr/bin/time -f "standalone ($((2 * THREADS)) threads): %e s wall, %U s user, peak %M KB" \
  timeout -k 10 3600 "$build/bin/aafarm-worker" --standalone instances.rib -o "$work/inst.exr" \
  -t $((2 * THREADS)) 2>&1 | tail -2)
fi
