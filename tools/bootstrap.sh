#!/usr/bin/env bash
# Installs what a fresh Debian 12 machine lacks (as root, or with sudo), then configures and
# builds armfault in build/. Safe to run again: it installs nothing that is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

# Test-only: chromium (report page), slurm-wlm and munge (tools/slurm_check.sh runs a real Slurm),
# python3-yaml (tests/deploy/deploy_test.sh parses the Kubernetes YAML), python3-jsonschema
# (tests/campaigns/schema_test.py checks campaigns/campaign.schema.json).
# The Python package (python/): pybind11 and python3-dev to build it, NumPy and pandas for its
# arrays and DataFrames, pytest for its tests. zlib1g-dev: `armfault export` writes gzip CSV.
# Test-only: clang and libclang-rt-14-dev (libFuzzer, only a Recommends of clang-14) for the
# parsers' fuzzing test (tests/fuzz/fuzz_test.sh, docs/fuzzing.md).
# Test-only: jupyter-nbconvert, python3-ipykernel (the python3 kernel) and python3-matplotlib
# execute examples/notebooks/first-campaign.ipynb (python/tests/notebook_test.sh).
# nodejs and npm: `npm ci` installs the report's plotting libraries (Vega, Vega-Lite, vega-embed,
# pinned with their integrity hashes in reports/web/package-lock.json), which the build inlines
# into report.html (reports/CMakeLists.txt).
packages=(build-essential cmake pkg-config nodejs npm libode-dev libeigen3-dev libtbb-dev nlohmann-json3-dev
          libcli11-dev libssl-dev zlib1g-dev liburdfdom-dev libtinyxml-dev libgtest-dev libgmock-dev libbenchmark-dev chromium slurm-wlm
          munge python3-yaml python3-jsonschema python3-dev pybind11-dev python3-pybind11 python3-numpy
          python3-pandas python3-pytest clang libclang-rt-14-dev
          jupyter-nbconvert python3-ipykernel python3-matplotlib)
missing=()
for p in "${packages[@]}"; do
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

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$(nproc)"
