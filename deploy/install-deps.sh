#!/usr/bin/env bash
# Installs viscera's build and test dependencies from Debian 12 packages.
# Idempotent: installs only what is missing; needs root (or sudo) when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev            # dense/sparse linear algebra (Eigen 3.4)
  libsuitesparse-dev       # CHOLMOD sparse Cholesky for the implicit integrator
  libopenblas0-serial      # CHOLMOD's dense kernels: halves the 96k liver's load (the reference BLAS is slow)
  libspdlog-dev            # logging in programs (never in the tissue hot loops)
  libgtest-dev googletest  # unit and integration tests
  libbenchmark-dev         # bench/
  cyclonedds-dev cyclonedds-tools   # DDS C API, idlc, ddsperf
  libflatbuffers-dev flatbuffers-compiler  # wire schemas, flatc
  nlohmann-json3-dev       # JSON for scene, material and data-set files
  python3                  # bench summary and test scripts that read JSON
  libpugixml-dev           # XML parsing of VTU meshes
  clang libclang-rt-14-dev # libFuzzer for the message-decoder fuzz target
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
