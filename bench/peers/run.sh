#!/usr/bin/env bash
# bench/peers/run.sh: aafarm against its peers on the same surfaces
# (`make bench-peers`; docs/benchmarks.md "Peers" says what and why).
#
#   bash bench/peers/run.sh            the full run (wave, nail, dented)
#   QUICK=1 bash bench/peers/run.sh    the smoke run: wave only, 1 run each,
#                                      coarser reference, Embree N <= 512
#   SCENES="wave nail" RUNS=7 ...      override the scenes / runs
#   RUNS_dented=1 ...                  the runs of one scene (the table's
#                                      "runs" column says what was done)
#   MESHES=1 bash bench/peers/run.sh   the displaced mesh (issue 14) and the
#                                      terrain (issue 16) against Embree:
#                                      scenes mesh terrain, no POV-Ray (no
#                                      isosurface), N per face NS_mesh, over
#                                      the patch NS_terrain; its own table
#                                      (marker "bench-peers-meshes"); QUICK=1
#                                      with it: fewer N, one run
#   MESH1M=1 bash bench/peers/run.sh   issue 23's 1M-face displaced mesh
#                                      against Embree: bench/asset_gen's
#                                      terrain of 1,000,000 quads (a height
#                                      map through texture(), no rocks) as
#                                      the peer scenes are set up, at
#                                      MESH1M_W x MESH1M_H (320 x 240), N per
#                                      face NS_mesh1m (1 2 4); its own table
#                                      (marker "bench-peers-mesh1m")
#   WALLS=1 bash bench/peers/run.sh    issue 24's walls against Embree: a
#                                      brick wall (bench/peers/scenes/
#                                      wall.rib: the corpus's bricks.sl on
#                                      a polygon), no POV-Ray (no gradient
#                                      bound for a step), N over the
#                                      polygon NS_wall; its own table
#                                      (marker "bench-peers-walls"); QUICK=1
#                                      with it: fewer N, one run
#
# It installs the peers (deploy/install-bench-deps.sh), builds aafarm and
# the helpers in build-bench/, and for each scene of bench/peers/scenes/:
#
#   reference   aafarm's renderer at a fine setting (peers_aafarm --leaf:
#               boxes of 1/16 pixel; QUICK: 1/4), one ray per pixel centre:
#               the only method here that cannot miss surface (the nail's
#               walls included), with shading within 1/32 pixel of the hit
#   aafarm      aafarm-worker --standalone --threads 1 (timed), and the same
#               renderer at pixel centres (peers_aafarm, compared)
#   POV-Ray     bench/peers/pov/SCENE.pov, an isosurface of the same
#               function, at max_gradient G, G/2, G/4, accuracy 1e-3 (and,
#               for the nail, at the gradient POV-Ray itself reports)
#   Embree      peers_embree at N = 128 .. 4096 (one run each), and again
#               with the others at N*, the smallest N whose image differs
#               from the reference in no more pixels than aafarm's does
#
# The timed runs alternate: RUNS rounds of (aafarm, each peer once); each
# figure is the median of its RUNS runs, CPU seconds of the whole process
# (user + system, all threads) and its peak RSS (peers_rusage). It prints
# one table and writes it into docs/benchmarks.md between the markers
# "<!-- bench-peers:begin -->" and "<!-- bench-peers:end -->", the plot
# docs/peers.png, and the headline line of README.md between
# "<!-- bench-peers-headline:begin -->" and its end marker. A benchmark
# prints figures: nothing here fails on time.
set -euo pipefail

MESHES=${MESHES:-0}
[ "$MESHES" = "0" ] && MESHES=""
MESH1M=${MESH1M:-0}
[ "$MESH1M" = "0" ] && MESH1M=""
WALLS=${WALLS:-0}
[ "$WALLS" = "0" ] && WALLS=""
if [ $(( ${MESHES:+1} + ${MESH1M:+1} + ${WALLS:+1} + 0 )) -gt 1 ]; then
  echo "bench-peers: MESHES=1, MESH1M=1 and WALLS=1 each make their own table: run one at a time" >&2
  exit 2
fi
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
QUICK=${QUICK:-0}
[ "$QUICK" = "0" ] && QUICK=""
BUILD=${BUILD:-$ROOT/build-bench}
WORK=$BUILD/peers-work
LIMIT=${LIMIT:-1200}            # seconds: a run past this is killed and reported
DOC_BLOCK=bench-peers
RSS=${RSS:-1}
if [ -n "$MESHES" ]; then
  # a mesh of 2304 faces: N cells per face; the terrain: N per side
  SCENES=${SCENES:-mesh terrain}
  CACHE_SCENES=${CACHE_SCENES-}      # set (empty: no box cache rounds)
  RSS=0
  DOC_BLOCK=bench-peers-meshes
  if [ -n "$QUICK" ]; then
    NS_mesh=${NS_mesh:-"1 2 4"}
    NS_terrain=${NS_terrain:-"128 256 512"}
  else
    NS_mesh=${NS_mesh:-"1 2 4 8 16 32"}
    NS_terrain=${NS_terrain:-"128 256 512 1024 2048 4096"}
  fi
fi
if [ -n "$WALLS" ]; then
  # a brick wall: N x N cells over its polygon
  SCENES=${SCENES:-wall}
  CACHE_SCENES=${CACHE_SCENES-}
  RSS=0
  DOC_BLOCK=bench-peers-walls
  if [ -n "$QUICK" ]; then
    NS_wall=${NS_wall:-"128 256 512"}
  else
    NS_wall=${NS_wall:-"128 256 512 1024 2048 4096"}
  fi
fi
if [ -n "$MESH1M" ]; then
  SCENES=mesh1m
  CACHE_SCENES=""
  RSS=0
  DOC_BLOCK=bench-peers-mesh1m
  MESH1M_W=${MESH1M_W:-320}
  MESH1M_H=${MESH1M_H:-240}
  if [ -n "$QUICK" ]; then NS_mesh1m=${NS_mesh1m:-"1 2"}; else NS_mesh1m=${NS_mesh1m:-"1 2 4"}; fi
  RUNS=${RUNS:-3}
fi
# the maps a scene reads, shipped to each worker host once (issue 16)
TEX_terrain=$ROOT/scenes/textures/terrain_height.exr
TEX_mesh1m=$TEX_terrain
if [ -n "$QUICK" ]; then
  SCENES=${SCENES:-wave}
  RUNS=${RUNS:-1}
  NS=${NS:-"128 256 512"}
  REF_LEAF=0.25
  CACHE_SCENES=${CACHE_SCENES-}
  BIG=${BIG:-0}
else
  SCENES=${SCENES:-wave nail dented}
  RUNS=${RUNS:-5}
  NS=${NS:-"128 256 512 1024 2048 4096"}
  REF_LEAF=0.0625
  CACHE_SCENES=${CACHE_SCENES-wave nail ufo}
  BIG=${BIG:-1}
fi

say() { printf 'bench-peers: %s\n' "$*" >&2; }

# ---- peers and build ----
bash "$ROOT/deploy/install-bench-deps.sh"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAAFARM_TESTS=OFF >/dev/null
cmake --build "$BUILD" -j "$(nproc 2>/dev/null || echo 2)" \
  --target aafarm-worker aafarm-maketx asset_gen peers_aafarm peers_compare peers_rusage peers_embree >/dev/null
BIN=$BUILD/bin
for b in aafarm-worker peers_aafarm peers_compare peers_rusage peers_embree; do
  if [ ! -x "$BIN/$b" ]; then
    say "error: $BIN/$b was not built (Embree 3 missing? run deploy/install-bench-deps.sh as root)"
    exit 1
  fi
done
rm -rf "$WORK"
mkdir -p "$WORK"
case " $SCENES " in
  *" terrain "*|*" mesh1m "*) [ -f "$TEX_terrain" ] || bash "$ROOT/scenes/make_textures.sh" "$BUILD" >&2 ;;
esac
DATE=$(date -u +%Y-%m-%d)
HOST="$(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo), load $(cut -d' ' -f1 /proc/loadavg) at start"

# run NAME LOG CMD...: one bounded run; appends "NAME cpu rss status" to
# $WORK/times and prints the run's status line
run() {
  local name=$1 log=$2
  shift 2
  local line
  line=$("$BIN/peers_rusage" "$LIMIT" "$log" "$@" || true)
  echo "$name $(echo "$line" | awk '{print $2, $4, $6}')" >>"$WORK/times"
  case "$line" in *"status 0") ;; *) say "warning: $name: $line (log: $log)";; esac
}

# field NAME LOG: the number after NAME in LOG (first match)
field() { awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) {print $(i + 1); exit}}' "$2"; }

# median NAME [COL]: median of column COL (2: cpu, 3: rss) of $WORK/times rows NAME
median() {
  awk -v n="$1" -v c="${2:-2}" '$1 == n && $4 == 0 {print $c}' "$WORK/times" | sort -g |
    awk -v c="${2:-2}" '{v[NR] = $1} END {
      if (NR == 0) {print "-"; exit}
      m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
      if (c == 2) printf "%.3f\n", m; else print m}'
}
count() { awk -v n="$1" '$1 == n && $4 == 0' "$WORK/times" | wc -l; }

# compare TEST REF: "differ holes extra colour"
compare() {
  if [ -f "$1" ] && [ -f "$2" ]; then
    "$BIN/peers_compare" "$1" "$2" --diff "${1%.png}.diff.png" | awk '{print $2, $4, $6, $8}'
  else
    echo "- - - -"
  fi
}

pov() { # pov SCENE MG ACC OUT.png LOG -> timed through run by the caller
  local s=$1 mg=$2 acc=$3 out=$4
  local w h
  w=$(awk '/^Format/ {print $2}' "$ROOT/bench/peers/scenes/$s.rib")
  h=$(awk '/^Format/ {print $3}' "$ROOT/bench/peers/scenes/$s.rib")
  echo povray "+I$s.pov" "+O$out" "+W$w" "+H$h" +FN16 +UA -A +WT1 -D -V File_Gamma=1.0 \
    "Declare=MG=$mg" "Declare=ACC=$acc"
}

: >"$WORK/times"
: >"$WORK/table"      # scene|renderer|setting|cpu|runs|ratio|rss MiB|data MiB|differ (holes/extra/colour)
: >"$WORK/sweep"      # scene N cpu tess build trace vertexMiB bvhMiB differ aafarm_cpu aafarm_data
: >"$WORK/headline"
: >"$WORK/leaves"

for s in $SCENES; do
  D=$WORK/$s
  mkdir -p "$D"
  has_pov=""
  if [ -f "$ROOT/bench/peers/pov/$s.pov" ]; then
    has_pov=1
    cp "$ROOT/bench/peers/pov/$s.pov" "$ROOT/bench/peers/pov/peers_common.inc" "$D/"
  fi
  RIB=$ROOT/bench/peers/scenes/$s.rib
  if [ "$s" = mesh1m ]; then
    # asset_gen's terrain (1M quads from a gzip archive, displaced by
    # heightmap.sl) set up as terrain.rib is: one sample per pixel, a box
    # filter, matte shading, no shadows
    say "$s: writing the asset (bench/asset_gen --faces 1000000 --rocks 0)"
    "$BIN/asset_gen" --faces 1000000 --rocks 0 --format "$MESH1M_W" "$MESH1M_H" \
      --shaders "$ROOT/scenes/shaders" --textures "$ROOT/scenes/textures" "$D" >&2
    sed -e 's/^PixelSamples .*/PixelSamples 1 1\nPixelFilter "box" 1 1\nExposure 1 1/' \
      -e 's/^WorldBegin$/WorldBegin\n  Attribute "light" "shadows" ["off"]/' \
      -e 's/Surface "plastic" .*/Surface "matte" "Ka" [1] "Kd" [0.7]/' "$D/asset.rib" >"$D/mesh1m.rib"
    RIB=$D/mesh1m.rib
  fi
  leaf=$REF_LEAF
  say "$s: reference (aafarm, boxes of $leaf pixel)"
  run "$s.ref" "$D/ref.log" "$BIN/peers_aafarm" "$RIB" "$D/ref.png" --leaf "$leaf"
  say "$s: aafarm at pixel centres"
  run "$s.aacentre" "$D/aa.log" "$BIN/peers_aafarm" "$RIB" "$D/aa.png"
  read -r aa_d aa_h aa_e aa_c < <(compare "$D/aa.png" "$D/ref.png")
  aa_data=$(awk -v b="$(field cache_peak_bytes "$D/aa.log")" 'BEGIN {printf "%.1f", b / 1048576}')
  tex_var=TEX_$s
  tex_note=""
  if [ -n "${!tex_var:-}" ] && [ -f "${!tex_var}" ]; then
    tex_note=" + $(stat -c %s "${!tex_var}" | awk '{printf "%.1f", $1 / 1048576}') texture, once per host"
  fi

  # POV-Ray's max_gradient: the analytic bound, or for dented (POV-Ray's
  # own noise, no closed form) the largest gradient POV-Ray reports
  case $s in
    wave) G=1.61 ;;
    nail) G=4.12 ;;
    *) G="" ;;
  esac
  povref=$D/ref.png
  found=""
  if [ -n "$has_pov" ] && [ "$s" != wave ]; then
    # shellcheck disable=SC2046
    (cd "$D" || exit 1; "$BIN/peers_rusage" "$LIMIT" probe.log $(pov "$s" 20 0.001 probe.png) >/dev/null) || true
    found=$(tr '\n' ' ' <"$D/probe.log" | sed -n 's/.*maximum gradient found was \([0-9.]*\).*/\1/p')
    if [ -z "$found" ]; then
      say "warning: $s: POV-Ray reported no gradient (log: $D/probe.log)"
      found=20
    fi
    if [ -z "$G" ]; then
      G=$found
      # its surface is not aafarm's: holes against POV-Ray at 4x G, 1e-6
      # shellcheck disable=SC2046
      (cd "$D" || exit 1; "$BIN/peers_rusage" "$LIMIT" povref.log $(pov "$s" "$(awk -v g="$G" 'BEGIN {print 4 * g}')" 1e-6 povref.png) >/dev/null) || true
      povref=$D/povref.png
    fi
  fi
  povs=("$G" "$(awk -v g="$G" 'BEGIN {printf "%.3g", g / 2}')" "$(awk -v g="$G" 'BEGIN {printf "%.3g", g / 4}')")
  povnames=("max_gradient $G (analytic)" "max_gradient ${povs[1]} (1/2)" "max_gradient ${povs[2]} (1/4)")
  [ "$s" = dented ] && povnames[0]="max_gradient $G (POV-Ray's found)"
  if [ "$s" = nail ]; then
    povs+=("$found")
    povnames+=("max_gradient $found (POV-Ray's found)")
  fi
  if [ -z "$has_pov" ]; then
    povs=()
    povnames=()
  fi
  ns_var=NS_$s
  ns=${!ns_var:-$NS}

  # Embree sweep
  nstar=""
  for n in $ns; do
    say "$s: Embree N=$n"
    run "$s.embree$n" "$D/embree$n.log" "$BIN/peers_embree" "$RIB" "$n" "$D/embree$n.png"
    read -r d h e c < <(compare "$D/embree$n.png" "$D/ref.png")
    echo "$s $n $d $h $e $c" >>"$WORK/embree_diff"
    if [ -z "$nstar" ] && [ "$d" != "-" ] && [ "$d" -le "$aa_d" ]; then nstar=$n; fi
  done
  nstar_note="smallest N matching"
  if [ -z "$nstar" ]; then
    nstar=$(echo "$ns" | awk '{print $NF}')
    nstar_note="largest N; none matched"
  fi

  # the timed rounds: aafarm, then each peer once
  runs_var=RUNS_$s
  runs=${!runs_var:-$RUNS}
  for ((r = 1; r <= runs; r++)); do
    say "$s: round $r of $runs"
    run "$s.aafarm" "$D/worker.log" "$BIN/aafarm-worker" --standalone "$RIB" -o "$D/worker.exr" \
      --threads 1 --stats -q
    for i in "${!povs[@]}"; do
      # shellcheck disable=SC2046
      (cd "$D" && run "$s.pov$i" "$D/pov$i.log" $(pov "$s" "${povs[$i]}" 0.001 "pov$i.png"))
    done
    # N*'s first run was the sweep's
    if [ "$r" -gt 1 ]; then
      run "$s.embree$nstar" "$D/embree$nstar.log" "$BIN/peers_embree" "$RIB" "$nstar" "$D/embree$nstar.png"
    fi
  done

  # ---- rows ----
  aa_cpu=$(median "$s.aafarm")
  ratio() { awk -v a="$aa_cpu" -v p="$1" 'BEGIN {if (p == "-" || a == "-" || p <= 0) print "-"; else printf "%.2fx", a / p}'; }
  mib() { awk -v k="$1" 'BEGIN {if (k == "-") print "-"; else printf "%.1f", k / 1024}'; }
  echo "$s $leaf" >>"$WORK/leaves"
  echo "$s|aafarm|worker, 1 thread; image: same renderer at pixel centres|$aa_cpu|$(count "$s.aafarm")|1.00x|$(mib "$(median "$s.aafarm" 3)")|$aa_data (box cache)$tex_note|$aa_d ($aa_h/$aa_e/$aa_c)" >>"$WORK/table"
  for i in "${!povs[@]}"; do
    read -r d h e c < <(compare "$D/pov$i.png" "$povref")
    p=$(median "$s.pov$i")
    echo "$s|POV-Ray|${povnames[$i]}|$p|$(count "$s.pov$i")|$(ratio "$p")|$(mib "$(median "$s.pov$i" 3)")|-|$d ($h/$e/$c)" >>"$WORK/table"
    if [ "$i" = 0 ]; then echo "$s|POV-Ray|$(ratio "$p")|$d" >>"$WORK/headline"; fi
  done
  for n in $ns; do
    L=$D/embree$n.log
    p=$(median "$s.embree$n")
    read -r d h e c < <(awk -v s="$s" -v n="$n" '$1 == s && $2 == n {print $3, $4, $5, $6}' "$WORK/embree_diff")
    tess=$(field tess_cpu_s "$L"); build=$(field build_cpu_s "$L"); trace=$(field trace_cpu_s "$L")
    vb=$(field vertex_bytes "$L"); bb=$(field bvh_bytes "$L")
    phases=$(awk -v a="$tess" -v b="$build" -v c="$trace" 'BEGIN {if (a == "") print "-"; else printf "%.3f", a + b + c}')
    data=$(awk -v v="$vb" -v b="$bb" 'BEGIN {if (v == "") print "-"; else printf "%.1f", (v + b) / 1048576}')
    data_cell="$data (vertices+BVH)"
    [ -n "$tex_note" ] && data_cell="$data_cell; mesh to ship $(awk -v v="$vb" 'BEGIN {if (v == "") print "-"; else printf "%.1f", v / 1048576}')"
    mark=""
    [ "$n" = "$nstar" ] && mark=" **N\\***"
    [ "$n" = "$nstar" ] && [ "$nstar_note" != "smallest N matching" ] && mark=" (largest; none matched)"
    echo "$s|Embree|N=$n$mark (tess+build+trace $phases s)|$p|$(count "$s.embree$n")|$(ratio "$p")|$(mib "$(median "$s.embree$n" 3)")|$data_cell|$d ($h/$e/$c)" >>"$WORK/table"
    echo "$s $n $p $phases $data $d $aa_cpu $aa_data" >>"$WORK/sweep"
    if [ "$n" = "$nstar" ]; then
      echo "$s|Embree|N=$n ($nstar_note)|$(ratio "$p")|$data|$aa_data" >>"$WORK/headline"
    fi
  done
done

# ---- box cache: 400K against unlimited, and memory as the image grows ----
: >"$WORK/cache"
for s in $CACHE_SCENES; do
  D=$WORK/cache-$s
  mkdir -p "$D"
  # the paper's setting: one ray per pixel (scenes/ use PixelSamples 2 2)
  sed -e 's/^PixelSamples .*/PixelSamples 1 1/' -e "s|\\[\"shaders:&\"\\]|[\"$ROOT/scenes/shaders:\\&\"]|" \
    "$ROOT/scenes/$s.rib" >"$D/$s.rib"
  for ((r = 1; r <= RUNS; r++)); do
    say "cache $s: round $r of $RUNS"
    run "cache.$s.unl" "$D/unl.log" "$BIN/aafarm-worker" --standalone "$D/$s.rib" -o "$D/o.exr" --threads 1 --stats -q
    run "cache.$s.400K" "$D/400K.log" "$BIN/aafarm-worker" --standalone "$D/$s.rib" -o "$D/o.exr" --threads 1 --stats -q --cache-bytes 400K
  done
  bu=$(field boxes_per_ray "$D/unl.log"); b4=$(field boxes_per_ray "$D/400K.log")
  cu=$(median "cache.$s.unl"); c4=$(median "cache.$s.400K")
  echo "$s|$(awk '/^Format/ {print $2 "x" $3}' "$D/$s.rib")|$bu|$b4|$(awk -v a="$bu" -v b="$b4" 'BEGIN {printf "%+.1f %%", 100 * (b / a - 1)}')|$cu|$c4|$(awk -v a="$cu" -v b="$c4" 'BEGIN {printf "%+.1f %%", 100 * (b / a - 1)}')|$RUNS" >>"$WORK/cache"
done
: >"$WORK/rss"
sizes="512 256"
[ "$BIG" = 1 ] && sizes="512 256 2048 1024"
[ "$RSS" = 1 ] || sizes=""
# shellcheck disable=SC2086
set -- $sizes
while [ $# -ge 2 ]; do
  w=$1 h=$2
  shift 2
  D=$WORK/rss-${w}x$h
  mkdir -p "$D"
  sed -e "s/^Format .*/Format $w $h 1/" -e "s|\\[\"\\.\\./\\.\\./\\.\\./scenes/shaders:&\"\\]|[\"$ROOT/scenes/shaders:\\&\"]|" \
    "$ROOT/bench/peers/scenes/wave.rib" >"$D/wave.rib"
  for cache in 400K 0; do
    say "memory: wave ${w}x$h, cache $cache"
    run "rss.$w.$cache" "$D/$cache.log" "$BIN/aafarm-worker" --standalone "$D/wave.rib" -o "$D/o.exr" --threads 1 --stats -q --cache-bytes "$cache"
    cname=$cache
    [ "$cache" = 0 ] && cname=unlimited
    echo "wave|${w}x$h|$cname|$(awk -v k="$(median "rss.$w.$cache" 3)" 'BEGIN {printf "%.1f", k / 1024}')|$(field cache_peak_bytes "$D/$cache.log" | awk '{printf "%.1f", $1 / 1048576}')|$(median "rss.$w.$cache")" >>"$WORK/rss"
  done
done

# ---- the table ----
{
  echo "Measured $DATE on this machine ($HOST); aafarm $(git -C "$ROOT" describe --always --dirty 2>/dev/null || echo '?')."
  echo "One thread each, one ray per pixel. CPU s: median of \"runs\" runs (alternating"
  echo "rounds: aafarm, then each peer), whole process, user + system. Ratio: aafarm"
  echo "CPU / peer CPU (above 1: aafarm is slower). Differ: pixels whose hit mask or"
  echo "colour (> 8/255) differs from the reference, as (holes/extra/colour); POV-Ray's"
  echo "dented against its own render at 4x the gradient, accuracy 1e-6 (its noise is"
  echo "not aafarm's). N\\*: the smallest N whose differ is at most aafarm's."
  echo "Reference: aafarm (peers_aafarm) with boxes down to $(awk '{printf "%s%s %s", (NR > 1 ? ", " : ""), $1, $2}' "$WORK/leaves") pixel."
  echo
  echo "| scene | renderer | setting | CPU s | runs | aafarm / peer | peak RSS MiB | data MiB | differ (holes/extra/colour) |"
  echo "|---|---|---|---|---|---|---|---|---|"
  awk -F'|' '{printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8, $9}' "$WORK/table"
  if [ -s "$WORK/cache" ]; then
    echo
    echo "Box cache, 400K against unlimited (aafarm-worker --cache-bytes; the paper's"
    echo "scenes at the paper's sizes, one ray per pixel; CPU s median of the runs):"
    echo
    echo "| scene | pixels | boxes/ray unlimited | boxes/ray 400K | change | CPU s unlimited | CPU s 400K | change | runs |"
    echo "|---|---|---|---|---|---|---|---|---|"
    awk -F'|' '{printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8, $9}' "$WORK/cache"
  fi
  if [ -s "$WORK/rss" ]; then
    echo
    echo "Worker memory as the image grows (wave, 1 thread):"
    echo
    echo "| scene | pixels | cache | peak RSS MiB | box cache peak MiB | CPU s |"
    echo "|---|---|---|---|---|---|"
    awk -F'|' '{printf "| %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6}' "$WORK/rss"
  fi
} >"$WORK/table.md"
cat "$WORK/table.md"

# ---- docs/benchmarks.md, the plot, README ----
if [ -z "$QUICK" ] || [ -n "${WRITE_DOCS:-}" ]; then
  doc=$ROOT/docs/benchmarks.md
  if grep -q "<!-- $DOC_BLOCK:begin -->" "$doc"; then
    awk -v f="$WORK/table.md" -v b="<!-- $DOC_BLOCK:begin -->" -v e="<!-- $DOC_BLOCK:end -->" '
      $0 == b {print; while ((getline l < f) > 0) print l; skip = 1; next}
      $0 == e {skip = 0}
      !skip' "$doc" >"$WORK/doc.md" && cp "$WORK/doc.md" "$doc"
    say "wrote the table into $doc"
  fi
  if [ "$DOC_BLOCK" = bench-peers ] && command -v gnuplot >/dev/null; then
    awk '$3 != "-" && $4 != "-"' "$WORK/sweep" >"$WORK/sweep.dat"
    gnuplot -e "datafile='$WORK/sweep.dat'; outfile='$ROOT/docs/peers.png'; scenes='$SCENES'" \
      "$ROOT/bench/peers/plot.gp" && say "wrote $ROOT/docs/peers.png"
  fi
  readme=$ROOT/README.md
  if [ "$DOC_BLOCK" = bench-peers ] && grep -q '<!-- bench-peers-headline:begin -->' "$readme"; then
    line=$(awk -F'|' -v d="$DATE" '
      $2 == "POV-Ray" {pov[$1] = $3; holes[$1] = $4; order[++n] = $1}
      $2 == "Embree" {emb[$1] = $4 " at " $3; mem[$1] = "Embree vertices+BVH " $5 " MiB, aafarm box cache " $6 " MiB"}
      END {
        printf "Measured on %s, this machine, one thread each; aafarm CPU / peer CPU (above 1x: aafarm is slower):", d
        for (i = 1; i <= n; i++) {
          s = order[i]
          printf " **%s**: POV-Ray at its max_gradient %s (%s of its pixels differ), Embree %s (%s)%s", s, pov[s], holes[s], emb[s], mem[s], (i < n ? ";" : ".")
        }
        print ""
      }' "$WORK/headline")
    awk -v l="$line" '
      /<!-- bench-peers-headline:begin -->/ {print; print l; skip = 1; next}
      /<!-- bench-peers-headline:end -->/ {skip = 0}
      !skip' "$readme" >"$WORK/readme.md" && cp "$WORK/readme.md" "$readme"
    say "wrote the headline into $readme"
  fi
fi
say "done; images and logs in $WORK"
