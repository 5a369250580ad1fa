#!/usr/bin/env bash
# deploy/install-bench-deps.sh: install the Debian packages of the peer
# benchmark (bench/peers/, `make bench-peers`): POV-Ray, Embree 3 and
# gnuplot. Not part of deploy/install-deps.sh on purpose: the build, the
# tests and CI never need them. Idempotent like install-deps.sh: quiet when
# everything is present, one apt transaction when something is missing.
set -euo pipefail

PACKAGES=(
  povray            # POV-Ray 3.7: isosurface peer
  povray-includes   # its functions.inc (f_noise3d of the dented scene)
  libembree-dev     # Embree 3 C API: tessellation peer
  gnuplot-nox       # the plot of docs/benchmarks.md
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

echo "install-bench-deps: missing Debian packages: ${missing[*]}"
if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-bench-deps: error: apt-get not found; this script supports Debian 12 and derivatives." >&2
  echo "install-bench-deps: install the packages above with your system's package manager, then re-run." >&2
  exit 1
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1 && { [ -t 0 ] || sudo -n true 2>/dev/null; }; then
    SUDO="sudo"
    echo "install-bench-deps: not root; using sudo"
  else
    echo "install-bench-deps: error: installing packages needs root (and sudo is not usable here)." >&2
    echo "  as root, run: apt-get install -y ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-bench-deps: installed ${#missing[@]} package(s)."
