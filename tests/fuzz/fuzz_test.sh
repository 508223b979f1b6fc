#!/usr/bin/env bash
# The parsers' fuzzing test (docs/fuzzing.md). Configures and builds the libFuzzer targets of
# tests/fuzz with clang (ASan + UBSan, ccache when present) in a build directory of their own,
# runs every target over every input in tests/fuzz/regressions/<target>/ (each crash ever found),
# then fuzzes each target from tests/fuzz/corpus/<target>/ for its share of --seconds.
# Exit status 1 when any target crashes (a regression input, or a new crash: its input is
# left under BUILD/artifacts/<target>/ and named), 2 on a usage or build problem.
#
#   tests/fuzz/fuzz_test.sh                    # CI: regressions, then 60 s in all
#   tests/fuzz/fuzz_test.sh --seconds 600      # longer: 120 s a target
#   tests/fuzz/fuzz_test.sh --only robot --seconds 300
#   tests/fuzz/fuzz_test.sh --regressions-only
#
# Options: --seconds N (total fuzzing time, split evenly between the targets run; default 60),
# --build-dir DIR (default build/fuzz), --only TARGET (campaign, robot, monitor, verdicts, run, urdf),
# --regressions-only. New inputs the fuzzer finds go to BUILD/corpus/<target>/ (kept between
# runs, never into the repository); the shipped seeds are only read.
set -euo pipefail

src=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seconds=60
build="$src/build/fuzz"
targets=(campaign robot monitor verdicts run urdf)
fuzz=1
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --build-dir) build="$2"; shift 2 ;;
    --only) targets=("$2"); shift 2 ;;
    --regressions-only) fuzz=0; shift ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "fuzz_test.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
case "$seconds" in ''|*[!0-9]*) echo "fuzz_test.sh: --seconds takes a whole number, got '$seconds'" >&2; exit 2 ;; esac
for t in "${targets[@]}"; do
  [ -f "$src/tests/fuzz/fuzz_$t.cc" ] || { echo "fuzz_test.sh: no target '$t' (tests/fuzz/fuzz_$t.cc)" >&2; exit 2; }
done

# clang and libFuzzer (Debian: clang and libclang-rt-14-dev; tools/bootstrap.sh --tests installs them).
cxx=""
for c in clang++ clang++-14; do
  if command -v "$c" >/dev/null; then cxx=$(command -v "$c"); break; fi
done
[ -n "$cxx" ] || { echo "fuzz_test.sh: clang++ not found (Debian: apt-get install clang; tools/bootstrap.sh --tests does)" >&2; exit 2; }
cc=${cxx%++}
[ -x "$cc" ] || cc=${cxx/clang++/clang}
libfuzzer="$("$cxx" -print-resource-dir)/lib/linux/libclang_rt.fuzzer-x86_64.a"
[ -f "$libfuzzer" ] || { echo "fuzz_test.sh: libFuzzer not found ($libfuzzer; Debian: apt-get install libclang-rt-14-dev)" >&2; exit 2; }

launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
echo "fuzz_test.sh: building the targets in $build ($cxx)"
cmake -S "$src" -B "$build" -DARMFAULT_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_C_COMPILER="$cc" "${launcher[@]}" \
  -DBUILD_TESTING=OFF -DARMFAULT_BUILD_BENCH=OFF -DARMFAULT_BUILD_PYTHON=OFF >"$build.configure.log" 2>&1 \
  || { cat "$build.configure.log" >&2; echo "fuzz_test.sh: configure failed" >&2; exit 2; }
names=()
for t in "${targets[@]}"; do names+=("fuzz_$t"); done
cmake --build "$build" -j "${ARMFAULT_FUZZ_BUILD_JOBS:-2}" --target "${names[@]}" >"$build.build.log" 2>&1 \
  || { tail -40 "$build.build.log" >&2; echo "fuzz_test.sh: build failed (log: $build.build.log)" >&2; exit 2; }
bin="$build/tests/fuzz"

# Leaks inside third-party parsers on their own error paths (tests/fuzz/lsan.supp).
export LSAN_OPTIONS="suppressions=$src/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

failed=()
# Every crash ever found, run as a plain input (no fuzzing).
for t in "${targets[@]}"; do
  inputs=()
  if [ -d "$src/tests/fuzz/regressions/$t" ]; then
    while IFS= read -r -d '' f; do inputs+=("$f"); done \
      < <(find "$src/tests/fuzz/regressions/$t" -type f ! -name '.*' ! -name '*.md' -print0 | sort -z)
  fi
  [ ${#inputs[@]} -gt 0 ] || { echo "fuzz_$t: no regression inputs"; continue; }
  log="$build/regressions-$t.log"
  if "$bin/fuzz_$t" -rss_limit_mb=2560 -timeout=60 "${inputs[@]}" >"$log" 2>&1; then
    echo "fuzz_$t: ${#inputs[@]} regression inputs pass"
  else
    tail -40 "$log"
    echo "fuzz_$t: FAILED on a regression input (log: $log)"
    failed+=("fuzz_$t (regressions)")
  fi
done

if [ "$fuzz" = 1 ] && [ "$seconds" -gt 0 ]; then
  share=$(( seconds / ${#targets[@]} ))
  [ "$share" -ge 1 ] || share=1
  for t in "${targets[@]}"; do
    corpus="$build/corpus/$t"
    artifacts="$build/artifacts/$t"
    mkdir -p "$corpus" "$artifacts"
    log="$build/fuzz-$t.log"
    status=0
    "$bin/fuzz_$t" "$corpus" "$src/tests/fuzz/corpus/$t" -dict="$src/tests/fuzz/json.dict" \
      -max_total_time="$share" -timeout=30 -rss_limit_mb=2560 -max_len=16384 -print_final_stats=1 \
      -artifact_prefix="$artifacts/" >"$log" 2>&1 || status=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    if [ "$status" = 0 ]; then
      echo "fuzz_$t: ${share} s, ${runs:-?} inputs, ${rate:-?}/s, no crash"
    else
      grep -E '^(ODE |==[0-9]+==ERROR|SUMMARY|.*runtime error|.*Test unit written to|.*uncaught exception|terminate called|what\(\))' "$log" | head -8 || true
      echo "fuzz_$t: CRASH after ${runs:-?} inputs (log: $log); keep its input in tests/fuzz/regressions/$t/ once fixed"
      failed+=("fuzz_$t")
    fi
  done
fi

if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz_test.sh: FAILED: ${failed[*]}"
  exit 1
fi
echo "fuzz_test.sh: all targets passed"
