#!/usr/bin/env bash
# deploy/demo.sh BUILD_DIR: the demo behind `make demo`: renders the paper's
# wave scene (scenes/wave.rib, 512x256) through the farm with the embedded
# default: aafarm-master starts local worker processes (one per core) on a
# private ipc:// endpoint, ships them the job, stitches their EXR tiles and
# stops them. Output: demo-out/wave.exr (tiled OpenEXR, RGBA + Z) and
# demo-out/wave.png (sRGB preview). AAFARM_DEMO_OUT overrides the folder.
set -euo pipefail
build=${1:-build}
out=${AAFARM_DEMO_OUT:-demo-out}
master="$build/bin/aafarm-master"
if [ ! -x "$master" ]; then
  echo "demo: $master not found; run 'make build' first" >&2
  exit 1
fi
mkdir -p "$out"
echo "aafarm demo: rendering scenes/wave.rib through the farm with local workers"
"$master" scenes/wave.rib -o "$out/wave.exr" --preview "$out/wave.png"
echo "demo: wrote $out/wave.exr and $out/wave.png"
echo "demo: more scenes: scenes/{nail,ufo,gallery,surfaces}.rib; see README.md"
