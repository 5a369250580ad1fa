#!/usr/bin/env bash
# deploy/install-bench-deps.sh: install the Debian packages of the peer
# benchmark (bench/peers/, `make bench-peers`): POV-Ray, Embree 3 and
# gnuplot. Not part of the build's packages on purpose: the build, the
# tests and CI never need them. The list and the installing live in
# deploy/install-deps.sh (--bench), idempotent like the build's.
set -euo pipefail
exec bash "$(dirname "$0")/install-deps.sh" --bench
