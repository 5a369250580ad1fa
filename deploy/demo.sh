#!/usr/bin/env bash
# deploy/demo.sh BUILD_DIR: the demo behind `make demo`.
# Today aafarm has its arithmetic foundation only: the renderer (issue 4)
# and the farm (issue 5) are not built yet. The demo says so and shows what
# exists: the affine vs interval bounds the renderer will build its boxes
# from, measured on shader-like expressions (bench/aa_bench --quick).
set -euo pipefail
build=${1:-build}
if [ ! -x "$build/bin/aa_bench" ]; then
  echo "demo: $build/bin/aa_bench not found; run 'make build' first" >&2
  exit 1
fi
cat <<'MSG'
aafarm demo
-----------
Not yet here: the renderer and the farm (master, workers) are still being
built, so this demo cannot render a scene yet. What exists is the
rounding-safe interval and affine arithmetic that bounds displaced surfaces
(common/aa). Below: its speed, and how much tighter affine bounds are than
interval bounds on displacement-shader-like expressions.

MSG
"$build/bin/aa_bench" --quick
