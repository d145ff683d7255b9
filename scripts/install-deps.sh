#!/usr/bin/env bash
# Installs the Debian 12 packages fieldrig needs, only those that are missing (apt-get as root).
set -euo pipefail

packages=(
  g++ cmake ninja-build pkg-config
  libboost-dev libboost-system-dev
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev libgeographiclib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libssl-dev zlib1g-dev  # recording: SHA-256 of the location map (EVP), CRC-32 per frame
  libdc1394-dev  # the dc1394 driver (IEEE-1394 IIDC cameras); optional: skipped when absent
  libyaml-cpp-dev  # the YAML configuration (config/); dc1394 tests read ROS camera1394 files
  socat          # serial tests run through real pseudo-terminals
  slurm-wlm munge  # `fieldrig batch` is tested against a real Slurm (slurmctld, slurmd, munged)
  clang libclang-rt-14-dev  # libFuzzer for the NMEA parser fuzz test
  # The aravis driver and its tests (arv-fake-gv-camera-0.8); Debian's aravis-0.8.pc also
  # needs libusb-1.0's .pc file, which libaravis-dev does not pull in.
  libaravis-dev aravis-tools libusb-1.0-0-dev
  # The feature pipeline: OpenCV with contrib (ximgproc's WLS filter), PCL with Qhull, Eigen.
  # Debian's PCL pulls VTK, whose CMake config wants MPI's C target.
  libopencv-dev libopencv-contrib-dev libpcl-dev libeigen3-dev mpi-default-dev
  # The mesh renderer of synthetic fields (sim/mesh_render): Intel Embree 3 ray tracing.
  libembree-dev
  # stem-ui's browser test drives Debian's headless Chromium (Playwright comes from npm).
  chromium
  # fieldrigd: sd_notify (READY, STATUS, WATCHDOG) from libsystemd; the systemd tests run
  # systemd-analyze verify on the unit and systemd-sysusers --dry-run (no systemd as PID 1 needed).
  systemd libsystemd-dev
  # The demo's traits-against-truth table and the whole-run daemon benchmark.
  python3
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if ((${#missing[@]})); then
  echo "fieldrig: installing ${missing[*]}" >&2
  if [[ $(id -u) -ne 0 ]]; then
    echo "fieldrig: missing packages and not root; run as root or install: ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -q
  apt-get install -y -q --no-install-recommends "${missing[@]}"
  # The downloaded .deb files (1.5 GB, most of it VTK, Chromium and LLVM) are not needed once
  # installed; CI's disk has run out with them kept.
  apt-get clean
fi
