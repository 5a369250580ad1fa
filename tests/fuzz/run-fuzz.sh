#!/usr/bin/env bash
# tests/fuzz/run-fuzz.sh: builds the libFuzzer targets of tests/fuzz with
# clang (-DAAFARM_FUZZ=ON, ASan + UBSan) and fuzzes each one for a while,
# starting from a copy of its seed corpus (the corpus in the source tree is
# never written). A finding (crash, leak, timeout, out-of-memory) is kept
# under BUILD/findings/ and makes the script fail; copy it into
# tests/fuzz/regress/TARGET/NAME so that `make test` replays it.
#
#   tests/fuzz/run-fuzz.sh                       10 s per target (CTest's fuzz_brief)
#   tests/fuzz/run-fuzz.sh --time 1800           the long run: 30 min per target
#   tests/fuzz/run-fuzz.sh --time 60 rib sl      some targets only
# Options: --clang PATH (default clang), --build DIR (default build-fuzz),
# --unit-timeout S (default 10: an input running longer, in wall-clock
# seconds, is a finding; raise it on a loaded machine).
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../.." && pwd)"
clang=clang
build="$src/build-fuzz"
seconds=10
unit_timeout=10
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --clang) clang="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --time) seconds="$2"; shift 2 ;;
    --unit-timeout) unit_timeout="$2"; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    rib|sl|proto|tile) targets+=("$1"); shift ;;
    *) echo "run-fuzz: unknown argument '$1' (targets: rib sl proto tile)" >&2; exit 2 ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(rib sl proto tile)
case "$seconds" in ''|*[!0-9]*) echo "run-fuzz: --time wants whole seconds" >&2; exit 2 ;; esac
case "$unit_timeout" in ''|*[!0-9]*) echo "run-fuzz: --unit-timeout wants whole seconds" >&2; exit 2 ;; esac

cmake -S "$src" -B "$build" -DCMAKE_C_COMPILER="$clang" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DAAFARM_FUZZ=ON >/dev/null
names=()
for t in "${targets[@]}"; do names+=("fuzz_$t"); done
cmake --build "$build" -j "${AAFARM_FUZZ_JOBS:-2}" --target "${names[@]}" >/dev/null

mkdir -p "$build/findings"
failed=0
for t in "${targets[@]}"; do
  work="$build/corpus/$t"
  rm -rf "$work"
  mkdir -p "$work"
  cp "$here/corpus/$t/"* "$work/"
  echo "run-fuzz: $t for ${seconds}s"
  # the fuzzer stops itself after -max_total_time; timeout is the backstop
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
       timeout -k 10 $((seconds + 120 + unit_timeout)) "$build/bin/fuzz_$t" \
         -max_total_time="$seconds" -timeout="$unit_timeout" -rss_limit_mb=2048 -max_len=16384 \
         -print_final_stats=1 -artifact_prefix="$build/findings/$t-" "$work" \
         >"$build/findings/$t.log" 2>&1; then
    echo "run-fuzz: $t FAILED; the input is in $build/findings/ (log: $build/findings/$t.log):"
    grep -E "ERROR|SUMMARY|Test unit written|fuzz invariant" "$build/findings/$t.log" | head -20 || true
    failed=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/findings/$t.log" |
      sed "s/^/run-fuzz: $t /" || true
  fi
done
exit $failed
