# Makefile: the two commands of the README's Quick start, and a few more.
#   make demo            install dependencies, build, run the demo
#   make test            install dependencies, build with -Werror and asserts on,
#                        run every test
#   make test-sanitize   the same tests under AddressSanitizer + UBSan
#   make check-release   a Release build without asserts, warnings as errors,
#                        compiled only (nothing run)
#   make bench           build and run the benchmarks (figures, not tests)
#   make bench-peers     aafarm against POV-Ray and Embree on the same surfaces:
#                        installs them, prints the table, writes it into
#                        docs/benchmarks.md (QUICK=1: a ~2 minute smoke run)
#                        MESHES=1: the displaced mesh and the terrain against
#                        Embree (their own table); WALLS=1: a brick wall
#                        against Embree (its own table)
# Everything else is plain CMake: cmake -S . -B build && cmake --build build
MAKEFLAGS += --no-print-directory
JOBS ?= $(shell nproc 2>/dev/null || echo 2)

.PHONY: all deps build demo test test-sanitize test-threads check-release bench bench-peers clean

all: build

deps:
	@bash deploy/install-deps.sh

build: deps
	@cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
	@cmake --build build -j $(JOBS)

# the demo builds only the two programs it runs (not the tests, fuzzers and
# benchmarks that `make build` adds)
demo: deps
	@cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
	@cmake --build build -j $(JOBS) --target aafarm-master aafarm-worker
	@bash deploy/demo.sh build

test: deps
	@cmake -S . -B build-test -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAAFARM_WERROR=ON -DAAFARM_ASSERTS=ON >/dev/null
	@cmake --build build-test -j $(JOBS)
	@cd build-test && ctest --output-on-failure -j $(JOBS)

test-sanitize: deps
	@cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAAFARM_WERROR=ON -DAAFARM_ASSERTS=ON -DAAFARM_SANITIZE=ON >/dev/null
	@cmake --build build-asan -j $(JOBS)
	@cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
		ctest --output-on-failure -j $(JOBS)

# the tests whose processes run threads against each other (the standalone
# renderer's tail blocks, a farm worker's pool, the scheduler, determinism
# across threads) under ThreadSanitizer: a data race in aafarm's code ends
# the process (halt_on_error) and fails its test. Not part of `make test`
# (CI runs ASan/UBSan); tests/tsan.supp names libzmq's internals.
TSAN_TESTS = test_worker_cli|test_farm_render|test_trace_determinism|test_tile_runs|test_farm_scheduler
test-threads: deps
	@cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAAFARM_WERROR=ON -DAAFARM_ASSERTS=ON -DAAFARM_TSAN=ON >/dev/null
	@cmake --build build-tsan -j $(JOBS)
	@cd build-tsan && TSAN_OPTIONS="halt_on_error=1 exitcode=66 suppressions=$(CURDIR)/tests/tsan.supp" \
		ctest --output-on-failure -j $(JOBS) -R '$(TSAN_TESTS)'

# what `make build` and the benchmarks compile (-DNDEBUG: no asserts), with
# warnings as errors: a variable only an assert() reads must still compile
# cleanly ((void)x), and the optimiser's maybe-uninitialized analysis must
# agree (Release is -O2, as the tests: CMakeLists.txt)
check-release: deps
	@cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DAAFARM_ASSERTS=OFF -DAAFARM_WERROR=ON >/dev/null
	@cmake --build build-release -j $(JOBS)

bench: build
	@build/bin/aa_bench
	@build/bin/render_bench

bench-peers: deps
	@QUICK=$(QUICK) MESHES=$(MESHES) WALLS=$(WALLS) bash bench/peers/run.sh

clean:
	rm -rf build build-test build-asan build-tsan build-bench build-release
