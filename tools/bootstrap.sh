#!/usr/bin/env bash
# Installs what a fresh Debian 12 machine lacks (as root, or with sudo), then configures and
# builds armfault in build/. Safe to run again: it installs nothing that is already there.
#
#   tools/bootstrap.sh            the main job: build_packages only; builds the armfault binary.
#   tools/bootstrap.sh --python   also python_packages; builds the binary and the Python package.
#   tools/bootstrap.sh --tests    the test command: every list below; builds everything (tests,
#                                 benchmarks, Python package) for `ctest --test-dir build`.
#
# A fresh build/ made by the main job is configured with BUILD_TESTING, ARMFAULT_BUILD_BENCH and
# ARMFAULT_BUILD_PYTHON off, so that configuring needs none of the test packages; an existing
# build/ keeps the options it was configured with (the main job then builds only the binary).
# --python and --tests switch their parts on.
set -euo pipefail
cd "$(dirname "$0")/.."

python=0
tests=0
for arg in "$@"; do
  case "$arg" in
    --python) python=1 ;;
    --tests) tests=1 python=1 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bootstrap: unknown argument '$arg' (want --python or --tests)" >&2; exit 2 ;;
  esac
done

# Building and running armfault: the compiler and CMake, ODE (physics), Eigen, oneTBB,
# nlohmann-json, CLI11, OpenSSL (SHA-256 of the provenance), zlib (`armfault export` writes gzip
# CSV), ISA-L (igzip: `armfault import` deflates its CSV blocks), urdfdom and TinyXML (URDF robots), Boost.Math (header-only here: the statistics'
# distributions), nodejs and npm (`npm ci` fetches the report's plotting libraries, pinned with
# their integrity hashes in reports/web/package-lock.json; the build inlines them into report.html).
# The Dockerfile's build stage installs exactly these (tests/deploy/deploy_test.sh).
build_packages=(build-essential cmake pkg-config nodejs npm libode-dev libeigen3-dev libtbb-dev nlohmann-json3-dev
                libcli11-dev libssl-dev zlib1g-dev libisal-dev liburdfdom-dev libtinyxml-dev libboost-math-dev)
# The Python package (python/): pybind11 and python3-dev to build it, NumPy and pandas for its
# arrays and DataFrames.
python_packages=(python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pandas)
# Test-only: GoogleTest and GoogleMock (the unit tests), Google Benchmark (bench/),
# chromium (report page), slurm-wlm and munge (tools/slurm_check.sh runs a real Slurm; their
# packages enable slurmctld and munged as services), python3-yaml (tests/deploy/deploy_test.sh
# parses the Kubernetes YAML), python3-jsonschema (tests/campaigns/spec/schema_test.py checks
# campaigns/spec/campaign.schema.json), python3-pytest (the Python package's tests), clang and
# libclang-rt-14-dev (libFuzzer, only a Recommends of clang-14) for the parsers' fuzzing test
# (tests/fuzz/fuzz_test.sh, docs/fuzzing.md), jupyter-nbconvert, python3-ipykernel (the python3
# kernel) and python3-matplotlib to execute examples/notebooks/first-campaign.ipynb
# (python/tests/notebook_test.sh), and libmujoco-dev (MuJoCo 2.2.2, optional: `armfault bench`
# times it beside ODE and the joint-space engine when CMake finds it; no run uses it).
test_packages=(libgtest-dev libgmock-dev libbenchmark-dev chromium slurm-wlm munge python3-yaml
               python3-jsonschema python3-pytest clang libclang-rt-14-dev
               jupyter-nbconvert python3-ipykernel python3-matplotlib libmujoco-dev)

packages=("${build_packages[@]}")
[ "$python" -eq 0 ] || packages+=("${python_packages[@]}")
[ "$tests" -eq 0 ] || packages+=("${test_packages[@]}")
missing=()
for p in "${packages[@]}"; do
  # Node.js from elsewhere (NodeSource's nodejs carries its own npm and conflicts with Debian's
  # npm package): a working `node` and `npm` are what the build needs, not Debian's packages.
  if [ "$p" = nodejs ] && command -v node >/dev/null 2>&1; then continue; fi
  if [ "$p" = npm ] && command -v npm >/dev/null 2>&1; then continue; fi
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "bootstrap: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The report's plotting libraries, as locked (the npm registry, or npm's cache when it holds them:
# --prefer-offline; the lock file pins each version with its hash, so a cached copy is the same;
# skipped when node_modules is as new as the lock file). --ignore-scripts: no package runs code here.
if [ ! -f reports/web/node_modules/.package-lock.json ] ||
   [ reports/web/package-lock.json -nt reports/web/node_modules/.package-lock.json ]; then
  (cd reports/web && npm ci --ignore-scripts --prefer-offline --no-audit --no-fund)
fi

options=(-DCMAKE_BUILD_TYPE=Release)
if [ "$tests" -eq 1 ]; then
  options+=(-DBUILD_TESTING=ON -DARMFAULT_BUILD_BENCH=ON -DARMFAULT_BUILD_PYTHON=ON)
elif [ "$python" -eq 1 ]; then
  options+=(-DARMFAULT_BUILD_PYTHON=ON)
fi
if [ ! -f build/CMakeCache.txt ]; then
  # A fresh build/: only what was asked for is on.
  [ "$tests" -eq 1 ] || options+=(-DBUILD_TESTING=OFF -DARMFAULT_BUILD_BENCH=OFF)
  [ "$python" -eq 1 ] || options+=(-DARMFAULT_BUILD_PYTHON=OFF)
fi
cmake -S . -B build "${options[@]}" >/dev/null
if [ "$tests" -eq 1 ]; then
  cmake --build build -j "$(nproc)"
elif [ "$python" -eq 1 ]; then
  cmake --build build -j "$(nproc)" --target armfault armfault_python
else
  cmake --build build -j "$(nproc)" --target armfault
fi
