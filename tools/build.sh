#!/bin/sh
# Installs whatever Debian packages murk needs and are missing, then configures and builds murk in
# ./build (or $MURK_BUILD_DIR). Safe to run again: it only does what is not done yet.
set -eu
cd "$(dirname "$0")/.."
BUILD=${MURK_BUILD_DIR:-build}

# Build, test and data dependencies, all from Debian 12's own archive. chromium: the headless browser
# the comparison page's test (tests/test_report_page.c) opens report.html in. python3-numpy and
# python3-pytest: the Python module (python/murk) and its tests; python3-yaml: one of those tests.
PKGS="gcc meson ninja-build pkg-config cmake libembree-dev libopenexr-dev libyaml-dev libpng-dev
      libcmocka-dev libnanovdb-dev glmark2-data python3 python3-matplotlib python3-numpy python3-pytest python3-yaml clang libclang-rt-14-dev
      openmpi-bin libopenmpi-dev chromium g++ libopenvdb-dev libassimp-dev"
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "murk: installing Debian packages:$missing"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
fi

if [ ! -f "$BUILD/build.ninja" ]; then
  meson setup "$BUILD" --buildtype=release
fi
ninja -C "$BUILD"
