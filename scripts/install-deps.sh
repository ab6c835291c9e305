#!/usr/bin/env bash
# Installs every Debian 12 package stentsim needs to build, run and test.
# Idempotent and non-interactive; run as root (or with sudo available).
set -euo pipefail

PKGS=(
  # toolchain
  build-essential cmake ninja-build ccache pkg-config git
  # MPI
  openmpi-bin libopenmpi-dev
  # Trilinos 13.2 and the third-party libraries its CMake config names
  trilinos-all-dev libptscotch-dev libscotch-dev libmumps-dev libhdf5-openmpi-dev
  liblapack-dev libblas-dev zlib1g-dev libsuitesparse-dev
  # optimised BLAS/LAPACK behind libblas.so.3 (Debian's alternatives pick it over the
  # reference BLAS): UMFPACK's dense frontal kernels run ~1.6x faster (Case 1 artery);
  # the serial build, so MPI ranks and cohort workers do not oversubscribe the cores
  libopenblas0-serial
  # geometry, meshing, visualization I/O
  libgmsh-dev libvtk9-dev libcgal-dev libgmp-dev libmpfr-dev libeigen3-dev
  # configuration, CLI, logging, hashing, XML, threading
  libyaml-cpp-dev libcli11-dev libfmt-dev libspdlog-dev libxxhash-dev libpugixml-dev libtbb-dev
  # plots (headless PNG/SVG)
  libplplot-dev plplot-driver-cairo
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # headless browser: the report test renders report.html to a screenshot
  chromium
  # Slurm back-end of `stentsim cohort` (its tests start a private single-node cluster)
  slurmctld slurmd slurm-client munge
)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PKGS[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
