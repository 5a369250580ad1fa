#!/bin/bash
# bench/pattern_bench.sh: issue 24, "walls and patterns": the corpus's brick,
# tile and slate-roof displacement shaders (step/mod/floor patterns in both
# directions) on the corpus sphere, rendered by the standalone renderer.
#
#   bench/pattern_bench.sh [BIN_DIR] [SHADER ... | all]
#       defaults: build/bin; bricks bricks_filtered slate_roof tiles_hex
#       tiles_pillow pnoise_tiles uv_quilt fwp_checks; "all": the whole
#       corpus (55 shaders; not the four tex_* ones, whose maps the test
#       suite writes)
#
# Three scenes (PATTERN_BENCH_SCENES, default "sphere wall mesh"): test_corpus_render's
# sphere (tests/corpus/corpus.c, CORPUS_SPHERE: Translate 0 0 5, Rotate 70
# 1 0 0, Sphere 1 -1 1 360, fov 35) at 96x72, and a flat wall (a 3 x 2
# polygon, s and t across it, turned 30 degrees about the vertical and
# seen from 3 units, fov 40, Km 0.03: the patterns' steps as real walls)
# at 256x192, and the same wall as production models it (a PointsPolygons
# mesh of 3 x 2 quads sharing their points, "st" per point); one thread, affine arithmetic, the default box cache. For
# each scene and shader one line: CPU seconds of the render (user + system, /usr/bin/time),
# and from `aafarm-worker --stats`: boxes per ray (box evaluations through
# the shader / rays), evals per ray (affine + dual + float evaluations /
# rays, as render_bench counts them), samplings (stagnant boxes sampled)
# and sampled_boxes (of them, boxes re-estimated from the samples,
# docs/renderer.md "Stagnant boxes"),
# wall_leaves, the largest walk (max_nodes_per_ray) and limited_rays. The
# issue's aim is <= 10 boxes per ray. Figures, never a verdict: the script
# fails only when a render fails. Every render is bounded by timeout -k
# (PATTERN_BENCH_LIMIT seconds, default 600). PATTERN_BENCH_KEEP=DIR keeps
# the images there (DIR/SCENE.SHADER.exr), to compare two builds with exrcmp.
set -u
BIN=${1:-build/bin}
[ $# -gt 0 ] && shift
SHADERS=("$@")
[ ${#SHADERS[@]} -eq 0 ] && SHADERS=(bricks bricks_filtered slate_roof tiles_hex tiles_pillow
                                      pnoise_tiles uv_quilt fwp_checks)
HERE=$(cd "$(dirname "$0")" && pwd)
CORPUS=$HERE/../tests/shaders/corpus
# "all": every displacement shader of the corpus but those that read the
# test suite's textures (tex_*)
if [ "${SHADERS[0]}" = all ]; then
  SHADERS=()
  for f in "$CORPUS"/*.sl; do
    n=$(basename "$f" .sl)
    case $n in tex_*) ;; *) SHADERS+=("$n") ;; esac
  done
fi
LIMIT=${PATTERN_BENCH_LIMIT:-600}
[ -x "$BIN/aafarm-worker" ] || { echo "pattern_bench.sh: $BIN/aafarm-worker not built" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "pattern_bench.sh: needs /usr/bin/time (Debian package time)" >&2; exit 2; }
WORK=$(mktemp -d /tmp/aafarm-patterns-XXXXXX)
trap 'rm -rf "$WORK"' EXIT

# the value of a --stats line
stat() { awk -v k="$1" '$1 == k {print $2; exit}' "$2"; }

# The wall scene for shader $1 with the geometry $2 (RIB text): the wall
# as a polygon, or as a mesh of quads
wall_rib() {
    cat <<EOF
Option "searchpath" "shader" ["$CORPUS:&"]
Format 256 192 1
Projection "perspective" "fov" [40]
Translate 0 0 3
Rotate -30 0 1 0
WorldBegin
LightSource "distantlight" 1 "from" [-1 2 -2] "to" [0 0 0]
Attribute "displacementbound" "sphere" [0.05]
Displacement "$1" "float Km" [0.03]
$2
WorldEnd
EOF
}

echo "pattern_bench: corpus sphere 96x72, a wall 256x192 (a polygon, a mesh), 1 thread, affine ($(date -u +%F), $(uname -m), $(nproc) cores)"
printf "%-6s %-16s %8s %10s %10s %9s %8s %7s %9s %7s\n" scene shader "CPU s" boxes/ray evals/ray samplings sampled \
    walls max_nodes limited
status=0
for scene in ${PATTERN_BENCH_SCENES:-sphere wall mesh}; do
for sh in "${SHADERS[@]}"; do
    [ -r "$CORPUS/$sh.sl" ] || { echo "pattern_bench.sh: no shader $CORPUS/$sh.sl" >&2; status=1; continue; }
    case $scene in
    sphere) cat > "$WORK/$sh.rib" <<EOF
Option "searchpath" "shader" ["$CORPUS:&"]
Format 96 72 1
Projection "perspective" "fov" [35]
WorldBegin
AttributeBegin
Translate 0 0 5
Rotate 70 1 0 0
Displacement "$sh"
Sphere 1 -1 1 360
AttributeEnd
WorldEnd
EOF
        ;;
    wall) wall_rib "$sh" 'Polygon "P" [-1.5 -1 0  1.5 -1 0  1.5 1 0  -1.5 1 0] "st" [0 0  1 0  1 1  0 1]' \
              > "$WORK/$sh.rib" ;;
    mesh) wall_rib "$sh" 'PointsPolygons [4 4 4 4 4 4] [0 1 5 4  1 2 6 5  2 3 7 6  4 5 9 8  5 6 10 9  6 7 11 10]
  "P" [-1.5 -1 0  -0.5 -1 0  0.5 -1 0  1.5 -1 0  -1.5 0 0  -0.5 0 0  0.5 0 0  1.5 0 0
       -1.5 1 0  -0.5 1 0  0.5 1 0  1.5 1 0]
  "st" [0 0  0.333333333333 0  0.666666666667 0  1 0  0 0.5  0.333333333333 0.5
        0.666666666667 0.5  1 0.5  0 1  0.333333333333 1  0.666666666667 1  1 1]' > "$WORK/$sh.rib" ;;
    *) echo "pattern_bench.sh: no scene $scene (sphere, wall, mesh)" >&2; status=1; continue ;;
    esac
    if ! /usr/bin/time -f "%U %S" -o "$WORK/time" timeout -k 5 "$LIMIT" \
            "$BIN/aafarm-worker" --standalone "$WORK/$sh.rib" -o "$WORK/$sh.exr" -t 1 \
            --stats 2> "$WORK/stats" > /dev/null; then
        echo "pattern_bench.sh: $sh: render failed:" >&2
        tail -5 "$WORK/stats" >&2
        status=1
        continue
    fi
    [ -n "${PATTERN_BENCH_KEEP:-}" ] && cp "$WORK/$sh.exr" "$PATTERN_BENCH_KEEP/$scene.$sh.exr"
    cpu=$(awk 'END {printf "%.2f", $1 + $2}' "$WORK/time")
    S=$WORK/stats
    awk -v sc="$scene" -v sh="$sh" -v cpu="$cpu" \
        -v p="$(stat primary_rays "$S")" -v s="$(stat shadow_rays "$S")" \
        -v b="$(stat boxes "$S")" -v ea="$(stat evals_affine "$S")" \
        -v ed="$(stat evals_dual "$S")" -v ef="$(stat evals_float "$S")" \
        -v sn="$(stat samplings "$S")" -v sb="$(stat sampled_boxes "$S")" \
        -v wl="$(stat wall_leaves "$S")" \
        -v mx="$(stat max_nodes_per_ray "$S")" -v lr="$(stat limited_rays "$S")" \
        'BEGIN {r = p + s; if (r < 1) r = 1;
                printf "%-6s %-16s %8s %10.2f %10.2f %9d %8d %7d %9d %7d\n",
                       sc, sh, cpu, b / r, (ea + ed + ef) / r, sn, sb, wl, mx, lr}'
done
done
exit $status
