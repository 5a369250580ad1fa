#!/usr/bin/env bash
# scenes/make_textures.sh: writes the texture maps the example scenes read
# (scenes/textures/, not kept in git): the terrain's height map, a
# periodic fBm of 1024 x 1024 texels with 8 octaves, as a tiled,
# mip-mapped OpenEXR with its min-max pyramid (aafarm-maketx --fbm;
# docs/textures.md).
#
#   scenes/make_textures.sh [BUILD_DIR]     (default: build)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-build}"
maketx="$build/bin/aafarm-maketx"
if [ ! -x "$maketx" ]; then
  echo "make_textures: $maketx not found; build first (cmake --build $build --target aafarm-maketx)" >&2
  exit 1
fi
mkdir -p "$here/textures"
"$maketx" --fbm 1024 1024 --octaves 8 --seed 3 "$here/textures/terrain_height.exr"
