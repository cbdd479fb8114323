#!/usr/bin/env bash
# Wingman's one entry point for a fresh Debian 12 machine:
#   bash setup.sh run    install packages, build wingman, run the default scenario (scenes/paper_synthetic.yaml)
#   bash setup.sh test   install packages, build, run every test (what CI runs)
#   bash setup.sh build  install packages and build only
#   bash setup.sh train  install packages and the lead detector's training packages, build
#                        (then tools/lead_data.py and tools/train_lead_detector.py, docs/frontend.md)
# Environment: BUILD_DIR (default build), JOBS (default: all cores), WINGMAN_SKIP_APT=1 to skip apt.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cd "$here"
mode=${1:-build}
build_dir=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc)}

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libyaml-cpp-dev libfmt-dev libspdlog-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev libopenblas-serial-dev
  libopencv-dev libopencv-contrib-dev libassimp-dev zlib1g-dev libpugixml-dev libxxhash-dev libzstd-dev
  libegl-dev libgl-dev libosmesa6-dev libegl-mesa0 libgl1-mesa-dri
  gnuplot-nox python3 python3-yaml
  librosbag-storage-dev libroscpp-core-dev libstd-msgs-dev libgeometry-msgs-dev libsensor-msgs-dev
  libnav-msgs-dev libtf2-msgs-dev
  python3-rosbag python3-std-msgs python3-geometry-msgs python3-sensor-msgs python3-nav-msgs python3-tf2-msgs
  slurm-wlm munge
)

# Only the lead detector's training (tools/train_lead_detector.py) and its test need these.
training_packages=(python3-torch python3-onnx python3-opencv python3-numpy)

install_packages() {
  [ "${WINGMAN_SKIP_APT:-0}" = 1 ] && return 0
  local missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "setup: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo=sudo
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# build [TARGET]: every target, or only TARGET (and what it needs).
build() {
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$build_dir" -j "$jobs" ${1:+--target "$1"}
}

case "$mode" in
  build)
    install_packages
    build
    ;;
  run)
    install_packages
    build wingman  # the tests and benchmarks are built by `test`
    shift || true
    "$build_dir/app/wingman" run scenes/paper_synthetic.yaml --out results/paper_synthetic "$@"
    ;;
  test)
    packages+=("${training_packages[@]}")
    install_packages
    build
    cd "$build_dir"
    ctest --output-on-failure -j "$jobs"
    ;;
  train)
    packages+=("${training_packages[@]}")
    install_packages
    build
    ;;
  *)
    echo "usage: bash setup.sh [build|run|test|train]" >&2
    exit 2
    ;;
esac
