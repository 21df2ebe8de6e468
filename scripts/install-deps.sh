#!/usr/bin/env bash
# Installs every Debian 12 package that finecap's build, tests, benchmarks and demo need.
# Idempotent: packages already present are left alone and nothing is fetched.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libceres-dev libsuitesparse-dev
  libopencv-dev libopencv-contrib-dev libassimp-dev
  libpng-dev libjpeg62-turbo-dev libdeflate-dev  # finecap's own PNG and JPEG codecs (util)
  libgflags-dev libgoogle-glog-dev libyaml-cpp-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  gnuplot-nox clang-format
  libjs-three  # the report's 3D view; a test opens it in chromium (scripts/check-report.sh)
  chromium fonts-dejavu-core  # headless, for that test; without them it would skip
  clang-14 libclang-rt-14-dev
  colmap  # tests read the text and binary models COLMAP writes itself; 4 MB download, 16 MB installed
)

missing=()
for package in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
    missing+=("$package")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
