#!/usr/bin/env bash
# `cmake --install` gives a complete armfault (README, "Install"): installs BUILD_DIR into a temp
# prefix and checks that every part is where the README says, byte-identical to the source:
#   bin/armfault, include/armfault/{monitor_plugin,monitor_settings}.h, share/armfault/campaigns/*.json,
#   share/armfault/schema/campaign.schema.json, share/doc/armfault/{README.md,docs/*.md,examples/},
#   and (when the build has the Python package) PREFIX/ARMFAULT_INSTALL_PYTHONDIR/armfault/.
# Then uses them as a user would, away from the source and build trees: the installed package
# imports with PYTHONPATH set to the install location only, loads an installed campaign and runs
# a small one; the installed binary validates a campaign whose "$schema" names the installed
# schema, and that campaign validates against the installed schema (python3-jsonschema); a bad
# key is refused by both, so the checks can fail.
# Usage: install_test.sh SOURCE_DIR BUILD_DIR. Prints "N passed, M failed"; non-zero on failure.
set -euo pipefail

if [[ $# -ne 2 || ! -d $1 || ! -x $2/armfault || ! -f $2/CMakeCache.txt ]]; then
  echo "usage: $0 SOURCE_DIR BUILD_DIR (BUILD_DIR holding a built armfault)" >&2
  exit 2
fi
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_install_test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
cd "$tmp"  # nothing below may find the source or build tree by accident

passed=0
failed=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1
  shift
  if "$@" >"$tmp/out" 2>&1; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $name: $(tail -c 1500 "$tmp/out")"; fi
}
same() {  # same SOURCE_FILE INSTALLED_FILE: installed, and byte-identical
  [[ -f $2 ]] || { echo "not installed: ${2#$prefix/}"; return 1; }
  cmp "$1" "$2"
}

cache() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
python_built=$(cache ARMFAULT_BUILD_PYTHON)
pythondir=$(cache ARMFAULT_INSTALL_PYTHONDIR)

installs() { cmake --install "$build" --prefix "$prefix"; }
check cmake_install installs

binary_and_header() {
  "$prefix/bin/armfault" --version | grep -qx "armfault $("$build/armfault" --version | awk '{print $2}')" &&
    same "$src/include/armfault/monitor_plugin.h" "$prefix/include/armfault/monitor_plugin.h" &&
    same "$src/include/armfault/monitor_settings.h" "$prefix/include/armfault/monitor_settings.h"
}
check binary_and_header binary_and_header

campaigns_and_schema() {
  local f n=0
  for f in "$src"/campaigns/files/*.json; do
    same "$f" "$prefix/share/armfault/campaigns/$(basename "$f")" || return 1
    n=$((n + 1))
  done
  [[ $n -ge 6 ]] || { echo "only $n shipped campaigns"; return 1; }
  same "$src/campaigns/spec/campaign.schema.json" "$prefix/share/armfault/schema/campaign.schema.json"
}
check campaigns_and_schema campaigns_and_schema

docs_and_examples() {
  local f doc=$prefix/share/doc/armfault n=0
  same "$src/README.md" "$doc/README.md" || return 1
  for f in "$src"/docs/*.md; do
    same "$f" "$doc/docs/$(basename "$f")" || return 1
    n=$((n + 1))
  done
  [[ $n -ge 10 ]] || { echo "only $n docs"; return 1; }
  same "$src/examples/plugins/current_residual.c" "$doc/examples/plugins/current_residual.c" &&
    same "$src/examples/notebooks/first-campaign.ipynb" "$doc/examples/notebooks/first-campaign.ipynb" &&
    same "$src/python/examples/torque_ratio_monitor.py" "$doc/examples/python/torque_ratio_monitor.py"
}
check docs_and_examples docs_and_examples

# The installed binary on a campaign that names the installed schema, as an editor reads it.
schema_referenced_campaign() {
  /usr/bin/python3 - "$prefix" <<'PY'
import json, subprocess, sys
prefix = sys.argv[1]
schema_path = f"{prefix}/share/armfault/schema/campaign.schema.json"
campaign = json.load(open(f"{prefix}/share/armfault/campaigns/ci.json"))
campaign = {"$schema": schema_path, **campaign}
json.dump(campaign, open("schema-ci.json", "w"), indent=1)
bad = dict(campaign, duration=8)  # a misspelt key: refused by the loader and by the schema
json.dump(bad, open("schema-bad.json", "w"), indent=1)
armfault = f"{prefix}/bin/armfault"
done = subprocess.run([armfault, "validate", "schema-ci.json"], capture_output=True, text=True)
if done.returncode != 0 or ": 52 runs" not in done.stdout:
    sys.exit(f"installed armfault validate: status {done.returncode}: {done.stdout}{done.stderr}")
done = subprocess.run([armfault, "validate", "schema-bad.json"], capture_output=True, text=True)
if done.returncode != 2 or '"duration"' not in done.stderr:
    sys.exit(f"installed armfault validate took a misspelt key: status {done.returncode}: {done.stderr}")
try:
    import jsonschema
except ImportError:
    sys.exit("no jsonschema module for /usr/bin/python3 (Debian: python3-jsonschema, see tools/bootstrap.sh --tests)")
validator = jsonschema.Draft202012Validator(json.load(open(campaign["$schema"])))
errors = list(validator.iter_errors(campaign))
if errors:
    sys.exit(f"the installed schema rejects an installed campaign: {errors[0].message}")
if validator.is_valid(bad):
    sys.exit("the installed schema took a misspelt key")
PY
}
check schema_referenced_campaign schema_referenced_campaign

# The Python package, with PYTHONPATH set to its install location only (a clean environment).
python_package() {
  if [[ $python_built != ON ]]; then
    echo "skipped: the build has no Python package (ARMFAULT_BUILD_PYTHON=$python_built)"
    return 0
  fi
  [[ -n $pythondir && -f $prefix/$pythondir/armfault/__init__.py ]] ||
    { echo "no $prefix/$pythondir/armfault/__init__.py"; return 1; }
  ls "$prefix/$pythondir"/armfault/_armfault*.so >/dev/null || return 1
  env -i PATH=/usr/bin:/bin HOME="$tmp" PYTHONPATH="$prefix/$pythondir" PYTHONDONTWRITEBYTECODE=1 \
    /usr/bin/python3 - "$prefix" "$pythondir" <<'PY'
import os, sys
prefix, pythondir = sys.argv[1], sys.argv[2]
import armfault
where = os.path.dirname(armfault.__file__)
assert where == os.path.join(prefix, pythondir, "armfault"), f"imported from {where}"
assert os.path.dirname(armfault._armfault.__file__) == where, armfault._armfault.__file__
campaign = armfault.load_campaign(os.path.join(prefix, "share/armfault/campaigns/ci.json"))
assert len(campaign) == 52, len(campaign)
small = {"name": "installed", "seed": 1, "duration_s": 1, "healthy": 2,
         "trajectories": [{"name": "t", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1.0}}}]}
records = armfault.run_campaign(small, threads=1, as_frame=False)
assert [r["run_id"] for r in records] == ["t/healthy/0", "t/healthy/1"], records
assert all(r["status"] == "ok" for r in records), records
print(f"armfault {armfault.__version__} from {where}: ok")
PY
}
check python_package python_package

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
