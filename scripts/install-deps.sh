#!/usr/bin/env bash
# Installs what wul3d needs to build, test and benchmark on Debian 12 (bookworm).
# Idempotent: when every package is already installed it touches nothing (no apt-get update),
# so repeat runs take well under a second. Must run as root when something is missing.
#
#   build-essential ninja-build cmake pkg-config   compiler (GCC 12, with OpenMP), build tools
#   git                                            source control
#   libopencv-dev                                  pixel containers and image processing (core,
#                                                  imgproc); the only package with OpenCVConfig.cmake
#   libpng-dev libjpeg-dev                         PNG reading and writing, JPEG reading (libpng,
#                                                  libjpeg-turbo; not OpenCV's imgcodecs)
#   libdeflate-dev                                 the PNG reader's inflate of the common kinds, the
#                                                  checksums of reading and writing (src/io/png_*.cpp)
#   libeigen3-dev libtbb-dev                       linear algebra; parallel loops (STYLE.md: TBB or OpenMP)
#   libcli11-dev nlohmann-json3-dev                command line, JSON (header-only)
#   libgtest-dev libgmock-dev                      the test suite (tests/)
#   libbenchmark-dev                               the benchmarks (bench/)
#   python3 python3-matplotlib                     helper scripts; the bench plot (scripts/plot-bench.py)
#   python3-numpy python3-pil                      eval/scenegen.py (generated scenes) and its test;
#                                                  named, though python3-matplotlib brings them
#   libglfw3-dev libgl-dev libimgui-dev            `wul3d view` (GLFW 3, OpenGL, Dear ImGui with its
#                                                  GLFW/OpenGL 3 backends); built only when found
#   xvfb xauth libgl1-mesa-dri                     the viewer's test: a virtual X server (xvfb-run)
#                                                  and Mesa's software OpenGL
#   libfreenect-dev libopenni2-dev                 live cameras: Kinect v1 (libfreenect), OpenNI2 devices
#                                                  and .oni files; each backend built only when found
#   libfreenect-bin                                fakenect: the capture tests replay a Kinect v1 dump
#   pybind11-dev python3-dev python3-numpy         the Python module (python/, docs/PYTHON.md), built
#                                                  for Debian's /usr/bin/python3
#   python3-pytest                                 its test suite (tests/python, scripts/run-tests.sh)
#   python3-open3d                                 examples/python/to_open3d.py and its test
#   python3-dask python3-distributed               batch runs over many sequences (wul3d.batch,
#                                                  docs/SCALE.md)
#   clang libclang-rt-14-dev libomp-14-dev         the fuzzers (fuzz/, .ci/run): clang 14's libFuzzer
#                                                  (-fsanitize=fuzzer), its sanitizer runtimes, OpenMP
#   zlib1g-dev                                     the tests' PNG files, chunks and streams written by
#                                                  hand (tests/support, tests/io)
#   librosbag-dev                                  ROS 1 bags as input (src/bag/, docs/INPUTS.md); built
#                                                  only when found
#   libclass-loader-dev librcpputils-dev           headers that Debian's rosbag/bag.h includes (through
#   librcutils-dev libament-index-cpp-dev          its ROS 2 pluginlib) but librosbag-dev does not bring
#   libsensor-msgs-dev libstd-msgs-dev             the messages of bags and of the node
#   libroscpp-dev libmessage-filters-dev           the ROS 1 node wul3d_ros (docs/ROS.md): roscpp, the
#                                                  colour/depth/camera_info synchronizer; built only when found
#   libvisualization-msgs-dev libdiagnostic-msgs-dev  its boxes (MarkerArray) and its /diagnostics
#   python3-roslaunch python3-rosmaster rosout     roscore and roslaunch: the node's tests start a roscore
#   python3-rosbag python3-sensor-msgs             the batch's bag test writes its bags with rosbag's
#                                                  own Python writer (tests/python/test_batch_bags.py)
#   (`run --video` uses libopencv-dev's videoio, whose FFmpeg backend Debian builds in)
set -euo pipefail

packages=(
  build-essential
  cmake
  ninja-build
  pkg-config
  git
  libopencv-dev
  libpng-dev
  libdeflate-dev
  libjpeg-dev
  libeigen3-dev
  libcli11-dev
  nlohmann-json3-dev
  libgtest-dev
  libgmock-dev
  libbenchmark-dev
  libtbb-dev
  python3
  python3-matplotlib
  python3-numpy
  python3-pil
  libglfw3-dev
  libgl-dev
  libimgui-dev
  xvfb
  xauth
  libgl1-mesa-dri
  libfreenect-dev
  libfreenect-bin
  libopenni2-dev
  pybind11-dev
  python3-dev
  python3-pytest
  python3-open3d
  python3-dask
  python3-distributed
  clang
  libclang-rt-14-dev
  libomp-14-dev
  zlib1g-dev
  librosbag-dev
  libclass-loader-dev
  librcpputils-dev
  librcutils-dev
  libament-index-cpp-dev
  libsensor-msgs-dev
  libstd-msgs-dev
  libroscpp-dev
  libmessage-filters-dev
  libvisualization-msgs-dev
  libdiagnostic-msgs-dev
  python3-roslaunch
  python3-rosbag
  python3-sensor-msgs
  python3-rosmaster
  rosout
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  if [[ "$status" != "installed" ]]; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

if [[ $(id -u) -ne 0 ]]; then
  echo "install-deps: missing packages: ${missing[*]}" >&2
  echo "install-deps: run as root (e.g. sudo $0) to install them" >&2
  exit 1
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends "${packages[@]}"
