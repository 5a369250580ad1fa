#!/usr/bin/env bash
# deploy/install-deps.sh: install every Debian package that aafarm's build,
# tests and demo need. Idempotent: quiet when everything is present, one apt
# transaction when something is missing, a clear message when it cannot
# install (not root, no apt-get). Debian 12 (bookworm) is the reference.
set -euo pipefail

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
  iproute2          # the multi-host test's network namespaces (ip netns)
  shellcheck        # lints deploy/'s scripts (test_deploy)
  python3-yaml      # checks deploy/'s compose and Kubernetes files (test_deploy)
  clang             # builds the fuzz targets (tests/fuzz, test fuzz_brief)
  libclang-rt-14-dev  # libFuzzer and the sanitizer runtimes for clang 14
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: missing Debian packages: ${missing[*]}"
if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-deps: error: apt-get not found; this script supports Debian 12 and derivatives." >&2
  echo "install-deps: install the packages above with your system's package manager, then re-run." >&2
  exit 1
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1 && { [ -t 0 ] || sudo -n true 2>/dev/null; }; then
    SUDO="sudo"
    echo "install-deps: not root; using sudo"
  else
    echo "install-deps: error: installing packages needs root (and sudo is not usable here)." >&2
    echo "  as root, run: apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: installed ${#missing[@]} package(s)."
