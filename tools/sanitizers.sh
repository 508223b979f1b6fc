#!/usr/bin/env bash
# Sanitizer builds, by hand (too slow for .ci/run; README "Sanitizers", docs/architecture.md
# "Thread safety").
#
#   tools/sanitizers.sh tsan   ThreadSanitizer: builds oneTBB and ODE with -fsanitize=thread
#                              from Debian's own source packages (the versions of the installed
#                              libtbb-dev and libode-dev, their Debian patches and ODE's Debian
#                              configure flags) into $ARMFAULT_SANITIZER_DEPS if they are not
#                              there yet, builds armfault with -fsanitize=thread against both in
#                              build-tsan/, runs campaigns/files/ci.json and
#                              tools/sanitizers/fleet-40.json (a 40-run fleet: datasheet
#                              tolerances, 8 units, commissioning) with -j 2, and fails on any
#                              report. About 15 min on 2 cores the first time.
#   tools/sanitizers.sh asan   AddressSanitizer + UndefinedBehaviorSanitizer: the whole suite
#                              (without the Python package: its tests run in /usr/bin/python3,
#                              which would need libasan preloaded) in build-asan/, then ctest
#                              but `deploy` (it checks that the Docker runtime stage has every
#                              library the binary links, and this one links libasan and
#                              libubsan); a report fails its test. About 30 min on 2 cores (an
#                              hour when shared).
#
# Why the dependencies are rebuilt: Debian's libtbb and libode are not instrumented. TSan does
# not see the synchronisation inside libtbb, so it reports every hand-over of a run between the
# pipeline's stages (campaigns/running/runner.cc) as a race (8 reports on ci.json, 69 on the fleet with
# this build), and it does not see ODE's memory at
# all, so a race inside ODE would go unnoticed. With both instrumented there are none left
# (no suppressions). Only Debian's package registry is used: `apt-get source` through a private
# deb-src list and package lists (nothing under /etc/apt is changed).
#
# Environment: ARMFAULT_SANITIZER_DEPS (default ~/.cache/armfault-sanitizers): where the
# instrumented libraries are built and installed; JOBS (default 2): build and run threads.
# Output: build-tsan/ or build-asan/ (git-ignored), logs and run directories under them.
# Exit status: 0 clean, 1 a sanitizer report (or a failed test), 2 usage or a failed step.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
jobs=${JOBS:-2}
deps=${ARMFAULT_SANITIZER_DEPS:-${HOME}/.cache/armfault-sanitizers}
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi

die() { echo "sanitizers: $*" >&2; exit 2; }

# Installs the Debian packages among "$@" that are missing (as root, or with sudo), as
# tools/bootstrap.sh does; the TSan build needs dpkg-dev (dpkg-source) and libccd-dev (ODE's).
need_packages() {
  local missing=() p
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ "${#missing[@]}" -eq 0 ] && return
  echo "sanitizers: installing ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

# Fetches Debian's source package SRC at VERSION and unpacks it (Debian's patches applied) into
# $deps/src/SRC, through a private deb-src list: nothing under /etc/apt changes.
fetch_debian_source() {
  local pkg=$1 version=$2 work=$deps/src
  mkdir -p "$work/apt/lists/partial" "$work/apt/cache/archives/partial"
  local codename
  codename=$(. /etc/os-release && echo "${VERSION_CODENAME:-bookworm}")
  echo "deb-src [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] http://deb.debian.org/debian $codename main" \
    >"$work/apt/sources.list"
  local apt=(apt-get -q -o Dir::Etc::SourceList="$work/apt/sources.list" -o Dir::Etc::SourceParts=/dev/null
             -o Dir::State::Lists="$work/apt/lists" -o Dir::Cache="$work/apt/cache"
             -o APT::Sandbox::User=root)
  "${apt[@]}" update >"$work/apt-$pkg.log" 2>&1 || { cat "$work/apt-$pkg.log" >&2; die "apt-get update failed"; }
  (cd "$work" && "${apt[@]}" source --download-only "$pkg=$version" >>"$work/apt-$pkg.log" 2>&1) ||
    { cat "$work/apt-$pkg.log" >&2; die "apt-get source $pkg=$version failed"; }
  rm -rf "${work:?}/$pkg"
  (cd "$work" && dpkg-source -x "${pkg}_${version#*:}.dsc" "$pkg" >>"$work/apt-$pkg.log" 2>&1) ||
    die "dpkg-source -x failed (see $work/apt-$pkg.log)"
}

# The version of the source package that built the installed binary package PKG.
installed_source_version() {
  dpkg-query -W -f='${source:Version}' "$1" 2>/dev/null ||
    die "$1 is not installed (tools/bootstrap.sh installs it)"
}

# oneTBB with TBB_SANITIZE=thread into $deps/onetbb-tsan (nothing when it is there already).
build_onetbb_tsan() {
  local prefix=$deps/onetbb-tsan
  if [ -f "$prefix/lib/cmake/TBB/TBBConfig.cmake" ]; then return; fi
  local version
  version=$(installed_source_version libtbb-dev)
  echo "sanitizers: building oneTBB $version with -fsanitize=thread into $prefix"
  fetch_debian_source onetbb "$version"
  # Only libtbb (armfault links TBB::tbb); no tests, no IPO (GCC drops TSan's instrumentation
  # under LTO, oneTBB's CMakeLists.txt says).
  rm -rf "$deps/build-onetbb-tsan"
  cmake -S "$deps/src/onetbb" -B "$deps/build-onetbb-tsan" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DTBB_SANITIZE=thread -DTBB_TEST=OFF -DTBB_STRICT=OFF -DTBBMALLOC_BUILD=OFF -DTBB_ENABLE_IPO=OFF \
    -DCMAKE_INSTALL_PREFIX="$prefix" "${launcher[@]}" >"$deps/onetbb-configure.log" 2>&1 ||
    die "oneTBB configure failed (see $deps/onetbb-configure.log)"
  cmake --build "$deps/build-onetbb-tsan" -j "$jobs" >"$deps/onetbb-build.log" 2>&1 ||
    die "oneTBB build failed (see $deps/onetbb-build.log)"
  cmake --install "$deps/build-onetbb-tsan" >/dev/null
  [[ $(nm -D "$prefix/lib/libtbb.so.12") == *__tsan_* ]] ||
    die "$prefix/lib/libtbb.so.12 has no TSan instrumentation"
}

# ODE with -fsanitize=thread into $deps/ode-tsan (nothing when it is there already): Debian's
# configure flags (debian/rules: double precision, system libccd, shared), no demos.
build_ode_tsan() {
  local prefix=$deps/ode-tsan
  if [ -f "$prefix/lib/pkgconfig/ode.pc" ]; then return; fi
  local version
  version=$(installed_source_version libode-dev)
  echo "sanitizers: building ODE $version with -fsanitize=thread into $prefix"
  fetch_debian_source ode "$version"
  # In the source tree, as Debian builds it: the tarball ships an include/ode/precision.h for
  # single precision that an out-of-tree build would pick up before the configured one.
  local cc="gcc" cxx="g++"
  if command -v ccache >/dev/null; then cc="ccache gcc"; cxx="ccache g++"; fi
  (cd "$deps/src/ode" &&
    ./configure --prefix="$prefix" --enable-double-precision --with-libccd=system --enable-libccd \
      --enable-shared --disable-static --disable-demos CC="$cc" CXX="$cxx" \
      CFLAGS="-g -O2 -fsanitize=thread" CXXFLAGS="-g -O2 -fsanitize=thread" LDFLAGS=-fsanitize=thread \
      >"$deps/ode-configure.log" 2>&1) || die "ODE configure failed (see $deps/ode-configure.log)"
  make -C "$deps/src/ode" -j "$jobs" >"$deps/ode-build.log" 2>&1 || die "ODE build failed (see $deps/ode-build.log)"
  make -C "$deps/src/ode" install >/dev/null 2>&1 || die "ODE install failed"
  [[ $(nm -D "$prefix/lib/libode.so.8") == *__tsan_* ]] || die "$prefix/lib/libode.so.8 has no TSan instrumentation"
}

# Runs one campaign under TSan; prints and returns its report count.
tsan_run() {
  local name=$1 campaign=$2 out=build-tsan/sanitizer-runs/$1 log=build-tsan/sanitizer-runs/$1.log
  rm -rf "$out"
  mkdir -p build-tsan/sanitizer-runs
  local start=$SECONDS status=0
  TSAN_OPTIONS="halt_on_error=0 exitcode=66 second_deadlock_stack=1 ${TSAN_OPTIONS:-}" \
    build-tsan/armfault run "$campaign" -o "$out" -j "$jobs" -q >"$log" 2>&1 || status=$?
  local reports
  reports=$(grep -c '^WARNING: ThreadSanitizer' "$log" || true)
  echo "sanitizers: tsan $name: $reports reports, exit $status, $((SECONDS - start)) s (log: $log)"
  # 0 and 1 (a floor missed) are armfault's own verdicts; 66 is TSan's; anything else failed.
  if [ "$status" -ne 0 ] && [ "$status" -ne 1 ] && [ "$status" -ne 66 ]; then
    tail -20 "$log" >&2
    return 2
  fi
  [ "$reports" -eq 0 ]
}

case $mode in
  tsan)
    need_packages dpkg-dev xz-utils libccd-dev
    build_onetbb_tsan
    build_ode_tsan
    tbb_prefix=$deps/onetbb-tsan ode_prefix=$deps/ode-tsan
    flags="-fsanitize=thread -fno-omit-frame-pointer"
    # A cache from other libraries (pkg_check_modules keeps what it found) starts afresh.
    if [ -f build-tsan/CMakeCache.txt ] &&
       { ! grep -qx "ODE_PREFIX:INTERNAL=$ode_prefix" build-tsan/CMakeCache.txt ||
         ! grep -qE "^TBB_DIR:[A-Z]+=$tbb_prefix/lib/cmake/TBB\$" build-tsan/CMakeCache.txt; }; then
      rm build-tsan/CMakeCache.txt
    fi
    PKG_CONFIG_PATH="$ode_prefix/lib/pkgconfig" \
    cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
      -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
      -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread \
      -DCMAKE_PREFIX_PATH="$tbb_prefix" -DTBB_DIR="$tbb_prefix/lib/cmake/TBB" \
      -DBUILD_TESTING=OFF -DARMFAULT_BUILD_BENCH=OFF -DARMFAULT_BUILD_PYTHON=OFF >/dev/null
    cmake --build build-tsan -j "$jobs" --target armfault >build-tsan/build.log 2>&1 ||
      { tail -30 build-tsan/build.log >&2; die "build-tsan failed"; }
    # The binary must load the instrumented libraries, not Debian's (its RUNPATH says where).
    for lib in "$tbb_prefix/lib/libtbb.so.12" "$ode_prefix/lib/libode.so.8"; do
      [[ $(ldd build-tsan/armfault) == *" => $lib "* ]] ||
        die "build-tsan/armfault does not load $lib: $(ldd build-tsan/armfault | grep -E 'tbb|ode')"
    done
    failed=0
    tsan_run ci campaigns/files/ci.json || failed=1
    tsan_run fleet-40 tools/sanitizers/fleet-40.json || failed=1
    if [ "$failed" -ne 0 ]; then
      echo "sanitizers: tsan: FAILED (reports above; the first of each log names the two stacks)"
      exit 1
    fi
    echo "sanitizers: tsan: no reports"
    ;;
  asan)
    # -fno-sanitize-recover: a UBSan finding aborts its process, so the test that hit it fails.
    flags="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
    cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
      -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
      -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined \
      -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined \
      -DARMFAULT_BUILD_BENCH=OFF -DARMFAULT_BUILD_PYTHON=OFF >/dev/null
    start=$SECONDS
    cmake --build build-asan -j "$jobs" >build-asan/build.log 2>&1 ||
      { tail -30 build-asan/build.log >&2; die "build-asan failed"; }
    echo "sanitizers: asan: built in $((SECONDS - start)) s"
    start=$SECONDS
    status=0
    ASAN_OPTIONS="detect_leaks=1 abort_on_error=0 ${ASAN_OPTIONS:-}" \
    UBSAN_OPTIONS="print_stacktrace=1 ${UBSAN_OPTIONS:-}" \
      ctest --test-dir build-asan --output-on-failure -j "$jobs" -E '^deploy$' >build-asan/ctest.log 2>&1 || status=$?
    grep -E '^(ERROR: AddressSanitizer|ERROR: LeakSanitizer|SUMMARY: |.*runtime error: )' build-asan/ctest.log | sort | uniq -c || true
    tail -40 build-asan/ctest.log | sed -n '/tests passed/,$p'
    echo "sanitizers: asan: ctest exit $status, $((SECONDS - start)) s (log: build-asan/ctest.log)"
    [ "$status" -eq 0 ] || exit 1
    ;;
  *)
    echo "usage: tools/sanitizers.sh tsan|asan" >&2
    exit 2
    ;;
esac
