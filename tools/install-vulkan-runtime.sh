#!/usr/bin/env bash
# Installs what alpenglow needs on Debian 12 (bookworm), when missing:
#   - the Vulkan loader and the Khronos validation layers,
#   - lavapipe from bookworm-backports (Mesa >= 23: descriptor indexing),
#   - the static shaderc / glslang / SPIRV-Tools libraries for the tools crate,
#   - image-diff and build prerequisites,
#   - a virtual X display (xvfb, xauth) for the viewer's tests (`alpenglow view`),
#   - GDAL's headers and library (libgdal-dev) for the feature `gdal`
#     (`alpenglow dem import` of any GDAL raster; the test suite enables it).
# Idempotent: does nothing when everything is already there. Run as root (or
# with sudo available).
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-vulkan-runtime: not root and no sudo; install the packages listed in $0 by hand" >&2
    exit 1
  fi
fi

have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

lavapipe_recent() {
  # Mesa's package version, e.g. 25.0.7-2~bpo12+1; we need >= 23.
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [ -n "$v" ] || return 1
  local major=${v%%.*}
  major=${major#*:}
  [ "$major" -ge 23 ] 2>/dev/null
}

# A Rust toolchain (rustup's stable), when cargo is missing.
if ! command -v cargo >/dev/null 2>&1 && [ ! -x "$HOME/.cargo/bin/cargo" ]; then
  echo "install-vulkan-runtime: installing Rust (rustup, stable)" >&2
  command -v curl >/dev/null 2>&1 || { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq curl ca-certificates build-essential >/dev/null; }
  curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal --component rustfmt,clippy >/dev/null
fi

need=()
for p in libvulkan1 vulkan-validationlayers libshaderc-dev glslang-dev spirv-tools pkg-config gcc g++ xvfb xauth libgdal-dev; do
  have_pkg "$p" || need+=("$p")
done
if ! lavapipe_recent; then need+=("mesa-vulkan-drivers(backports)"); fi

if [ ${#need[@]} -eq 0 ]; then
  exit 0
fi
echo "install-vulkan-runtime: installing ${need[*]}" >&2

if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  $SUDO tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null <<'SRC'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends \
  libvulkan1 vulkan-validationlayers libshaderc-dev glslang-dev spirv-tools pkg-config gcc g++ xvfb xauth >/dev/null
$SUDO apt-get install -y -qq --no-install-recommends -t bookworm-backports mesa-vulkan-drivers >/dev/null
lavapipe_recent || { echo "install-vulkan-runtime: mesa-vulkan-drivers from bookworm-backports did not install" >&2; exit 1; }
