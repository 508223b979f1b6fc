# Shared by the command-line checks (cli_test.sh, cli_runs_test.sh, provenance_cli_test.sh):
# sourced after their usage line. Sets armfault, src (the source tree), tmp (a temp dir, removed
# on exit, with work/ as the current directory) and the check helpers run, expect_*, pass, fail.
set -u

if [[ $# -ne 1 || ! -x "$1" ]]; then
  echo "usage: $0 path/to/armfault" >&2
  exit 2
fi
armfault=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
src=$(cd "$(dirname "$0")/../.." && pwd)  # the source tree (shipped campaigns)

tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_cli_test.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/work" "$tmp/elsewhere"
cd "$tmp/work" || exit 2  # stray default outputs (trace.csv) land in the temp dir

passed=0
failed=0
status=0

pass() { passed=$((passed + 1)); }
fail() {
  failed=$((failed + 1))
  echo "FAIL: $current: $*"
}

# run NAME CMD...: runs CMD, keeping its exit status in $status and its output in files.
run() {
  current=$1
  shift
  "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  status=$?
}

expect_status() {
  if [[ $status -eq $1 ]]; then pass; else fail "exit status $status, expected $1; stderr: $(head -c 400 "$tmp/stderr")"; fi
}

expect_stderr_contains() {
  if grep -qF -- "$1" "$tmp/stderr"; then pass; else fail "stderr lacks '$1'; stderr: $(head -c 400 "$tmp/stderr")"; fi
}

expect_stdout_contains() {
  if grep -qF -- "$1" "$tmp/stdout"; then pass; else fail "stdout lacks '$1'; stdout: $(head -c 400 "$tmp/stdout")"; fi
}

# An invalid-input error: status 2 and exactly one line "armfault: error: <expected...>".
expect_input_error() {
  expect_status 2
  local lines first
  lines=$(wc -l <"$tmp/stderr")
  first=$(head -n 1 "$tmp/stderr")
  if [[ $lines -eq 1 && $first == "armfault: error: "* ]]; then pass; else fail "stderr is not one 'armfault: error: ' line: $(head -c 400 "$tmp/stderr")"; fi
  local needle
  for needle in "$@"; do expect_stderr_contains "$needle"; done
}
