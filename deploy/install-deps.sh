#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs viscera's build and test dependencies from Debian 12 packages.
# Idempotent: installs only what is missing; needs root (or sudo) when something is missing.
# DEPS=demo installs only what the demo's programs need to build and run (deploy/run.sh): not the
# compilers of the fuzz targets, the linters, the browser or the test packages of Python and npm.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  ccache                   # compiled objects kept between builds and clones: a warm test run rebuilds only what changed
  libeigen3-dev            # dense/sparse linear algebra (Eigen 3.4)
  libsuitesparse-dev       # CHOLMOD sparse Cholesky for the implicit integrator
  libopenblas0-serial      # CHOLMOD's dense kernels: halves the 96k liver's load (the reference BLAS is slow)
  libspdlog-dev            # the services' log (viscera-server, viscera-console), never in the libraries
  libgtest-dev googletest  # unit and integration tests
  libbenchmark-dev         # bench/
  cyclonedds-dev cyclonedds-tools   # DDS C API, idlc, ddsperf
  libflatbuffers-dev flatbuffers-compiler  # wire schemas, flatc
  nlohmann-json3-dev       # JSON for scene, material and data-set files
  python3                  # bench summary and test scripts that read JSON
  libpugixml-dev           # XML parsing of VTU meshes
  libcgal-dev              # viscera-mesh: CGAL Mesh_3 on labelled images (a patient's organ from a CT label map)
  libnifti2-dev            # viscera-mesh: the label maps (NIfTI-1 and -2, .nii and .nii.gz)
  libzstd-dev liblz4-dev   # MCAP chunk compression (zstd, lz4) in session recordings
  libssl-dev               # SHA-256 of the files a scene was built from (recordings name them); the console's HTTPS and WSS
  libboost-dev             # Boost.Beast: the console's HTTP and WebSocket server (header-only)
  openssl                  # the console's access token (openssl rand), the test PKI (deploy/dds/make-test-pki.sh)
  pybind11-dev python3-dev # the Python package's extension module (client-sdk/python, docs/PYTHON.md)
  python3-numpy python3-pandas  # its arrays and DataFrames
  python3-matplotlib       # plots in its examples and Analysis.plot
)
# What only the tests need.
test_packages=(
  clang libclang-rt-14-dev # libFuzzer for the message-decoder fuzz target
  clang-format clang-tidy  # lint tests: the layout of every C++ file, clang-tidy on recent changes
  chromium                 # the browser tests of the console page (headless, driven by playwright-core)
  libnss3-tools            # certutil: the browser test trusts the test CA in Chromium's certificate store (no ignored errors)
  python3-pytest python3-mypy   # the Python package's tests (pytest under ctest) and the type check of its stubs, examples and tests
  podman runc mmdebstrap   # the runtime image's test: a Debian 12 base from Debian's archive, run by podman with runc
)
demo="${DEPS:-all}"
case "$demo" in
  demo) ;;
  all) packages+=("${test_packages[@]}") ;;
  *) echo "install-deps: DEPS is '$demo'; it is 'all' (the default) or 'demo'" >&2; exit 2 ;;
esac
# Node.js and npm: the official MCAP reader (@mcap/core) that judges recordings in the tests. Debian's
# packages, unless a node and an npm are on the PATH already (a NodeSource install bundles npm).
node_packages=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  missing+=("${node_packages[@]}")
fi

if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# npm packages, each folder pinned by its lock file and installed again only when the lock file
# changed: tests/node (what the tests run: the MCAP reader, playwright-core, ws, the Foxglove
# client) and the console page's (three.js, uPlot, esbuild), which the build bundles.
root="$(cd "$(dirname "$0")/.." && pwd)"
node_dirs=("$root/tools/viscera-console/web")
[ "$demo" = demo ] || node_dirs+=("$root/tests/node")
for node_dir in "${node_dirs[@]}"; do
  if ! cmp -s "$node_dir/package-lock.json" "$node_dir/node_modules/.installed-lock.json"; then
    echo "install-deps: npm ci in ${node_dir#"$root"/}" >&2
    (cd "$node_dir" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
    cp "$node_dir/package-lock.json" "$node_dir/node_modules/.installed-lock.json"
  fi
done
