#!/usr/bin/env bash
# scenes/make_textures.sh: writes the texture maps the example scenes read
# (scenes/textures/, not kept in git): the terrain's height map, a
# periodic fBm of 1024 x 1024 texels with 8 octaves, as a tiled,
# mip-mapped OpenEXR with its min-max pyramid (aafarm-maketx --fbm;
# docs/textures.md).
#
#   scenes/make_textures.sh [BUILD_DIR]     (default: build)
#
# aafarm-maketx is BUILD_DIR/bin's, else the one on the PATH (an installed
# aafarm: copy share/aafarm/scenes somewhere writable and run it there).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-build}"
maketx="$build/bin/aafarm-maketx"
if [ ! -x "$maketx" ]; then
  if ! maketx=$(command -v aafarm-maketx); then
    echo "make_textures: $build/bin/aafarm-maketx not found and no aafarm-maketx on the PATH; build first (cmake --build $build --target aafarm-maketx)" >&2
    exit 1
  fi
fi
mkdir -p "$here/textures"
"$maketx" --fbm 1024 1024 --octaves 8 --seed 3 "$here/textures/terrain_height.exr"
