#!/usr/bin/env bash
# deploy/install-deps.sh: install every Debian package that aafarm's build,
# tests and demo need. Idempotent: quiet when everything is present, one apt
# transaction when something is missing, a clear message when it cannot
# install (not root, no apt-get). Debian 12 (bookworm) is the reference.
#
#   deploy/install-deps.sh           the build, the tests, the demo, CI
#   deploy/install-deps.sh --bench   the peer benchmark's packages instead
#                                    (make bench-peers; never CI)
set -euo pipefail
NAME=install-deps

# One list, one place. Keep README and docs/building.md in step with it.
PACKAGES=(
  build-essential   # gcc, make, libc headers
  cmake             # the build
  pkg-config        # finds libzmq
  libzmq3-dev       # transport between master and workers
  libopenexr-dev    # OpenEXR 3 C API (OpenEXRCore) for tiles and images
  libpng-dev        # PNG previews and PNG textures
  libtiff-dev       # TIFF textures (common/tex)
  zlib1g-dev        # gzip-compressed RIB archives (ReadArchive)
  libcmocka-dev     # unit and property tests
  protobuf-c-compiler libprotobuf-c-dev  # wire protocol schema
  libsodium-dev     # CurveZMQ: Debian's libzmq5 has CURVE through libsodium
  libmicrohttpd-dev # the master's live monitor (--http)
  libsqlite3-dev    # the master's job queue (aafarm-master --serve)
  libcurl4-openssl-dev libjson-c-dev  # aafarm-submit (HTTP, JSON) and the monitor's tests
  chromium          # the monitor's page in a headless browser (test_monitor_browser)
  iproute2          # the multi-host test's network namespaces (ip netns)
  openssh-client openssh-server  # deploy/ssh/farm.sh over a real sshd (test_deploy)
  slurmctld slurmd slurm-client munge  # aafarm.sbatch on a real one-node Slurm (test_slurm)
  shellcheck        # lints deploy/'s scripts (test_deploy)
  python3-yaml      # checks deploy/'s compose and Kubernetes files (test_deploy)
  clang             # builds the fuzz targets (tests/fuzz, test fuzz_brief)
  libclang-rt-14-dev  # libFuzzer and the sanitizer runtimes for clang 14
)

if [ "${1:-}" = "--bench" ]; then
  NAME=install-bench-deps
  PACKAGES=(
    povray            # POV-Ray 3.7: isosurface peer
    povray-includes   # its functions.inc (f_noise3d of the dented scene)
    libembree-dev     # Embree 3 C API: tessellation peer
    gnuplot-nox       # the plot of docs/benchmarks.md
  )
elif [ $# -gt 0 ]; then
  echo "$NAME: usage: $0 [--bench]" >&2
  exit 2
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "$NAME: missing Debian packages: ${missing[*]}"
if ! command -v apt-get >/dev/null 2>&1; then
  echo "$NAME: error: apt-get not found; this script supports Debian 12 and derivatives." >&2
  echo "$NAME: install the packages above with your system's package manager, then re-run." >&2
  exit 1
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1 && { [ -t 0 ] || sudo -n true 2>/dev/null; }; then
    SUDO="sudo"
    echo "$NAME: not root; using sudo"
  else
    echo "$NAME: error: installing packages needs root (and sudo is not usable here)." >&2
    echo "  as root, run: apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "$NAME: installed ${#missing[@]} package(s)."
