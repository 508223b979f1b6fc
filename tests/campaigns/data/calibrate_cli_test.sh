#!/usr/bin/env bash
# armfault calibrate on an export (docs/calibration.md): a healthy run gives a twin that a campaign
# runs, with every value's interval; bad input exits 2 naming what is wrong.
# Usage: calibrate_cli_test.sh ARMFAULT SOURCE_DIR
set -u
armfault=$1
src=$2
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_calibrate.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$armfault" export "$src/tests/campaigns/data/calibrate_cli.json" -o "$tmp/x" -q -j 2 > "$tmp/export.out" 2>&1 || fail "export: $(cat "$tmp/export.out")"
healthy=$(python3 -c "import json,sys; print([l['run_id'] for l in map(json.loads, open(sys.argv[1])) if l['family'] is None][0])" "$tmp/x/manifest.jsonl")
faulty=$(python3 -c "import json,sys; print([l['run_id'] for l in map(json.loads, open(sys.argv[1])) if l['family']][0])" "$tmp/x/manifest.jsonl")

"$armfault" calibrate "$tmp/x" --run "$healthy" -o "$tmp/unit.json" > "$tmp/cal.out" 2>&1
status=$?
[ "$status" -eq 0 ] || fail "calibrate exited $status: $(cat "$tmp/cal.out")"
grep -q "motor/kt_Nm_per_A" "$tmp/cal.out" || fail "calibrate printed no K_T: $(cat "$tmp/cal.out")"
grep -q "^payload_kg" "$tmp/cal.out" || fail "calibrate printed no payload"
[ -f "$tmp/unit.json" ] && [ -f "$tmp/unit.calibration.json" ] || fail "twin or its calibration not written"
# The drawn payload (the export's variation) lies in the printed interval; the twin runs in a campaign.
python3 - "$tmp" "$healthy" "$src" <<'PY' || fail "twin check"
import json, sys
tmp, run, src = sys.argv[1:4]
line = [l for l in map(json.loads, open(tmp + "/x/manifest.jsonl")) if l["run_id"] == run][0]
drawn = line["variation"]["extra_payload_kg"]
cal = json.load(open(tmp + "/unit.calibration.json"))
p = cal["payload"]
assert p["identifiable"], p
drawn += p["nominal"]  # the campaign draws a payload on top of the robot's own
assert p["low_95"] <= drawn <= p["high_95"], (drawn, p)
assert len(cal["joints"]) == 3
twin = json.load(open(tmp + "/unit.json"))
camp = json.load(open(src + "/tests/campaigns/data/calibrate_cli.json"))
camp["robot"] = twin
camp["faults"] = []; camp["duration_s"] = 4
camp["variation"] = {}
json.dump(camp, open(tmp + "/twin-campaign.json", "w"))
PY
"$armfault" run "$tmp/twin-campaign.json" -o "$tmp/twin-run" -q -j 2 > "$tmp/twin.out" 2>&1 || fail "the twin's campaign did not run: $(tail -3 "$tmp/twin.out")"

expect_error() {  # expect_error SUBSTRING ARGS...: exit 2 and the message
  local want=$1; shift
  "$armfault" calibrate "$@" > "$tmp/err.out" 2>&1
  local s=$?
  [ "$s" -eq 2 ] || fail "calibrate $* exited $s, expected 2: $(cat "$tmp/err.out")"
  grep -qF -- "$want" "$tmp/err.out" || fail "calibrate $*: no \"$want\" in: $(cat "$tmp/err.out")"
}
expect_error "did you mean" "$tmp/x" --run "${healthy}x" -o "$tmp/u2.json"
expect_error "labelled faulty" "$tmp/x" --run "$faulty" -o "$tmp/u2.json"
expect_error "no such directory" "$tmp/nothere" --run "$healthy" -o "$tmp/u2.json"
expect_error "--block-s" "$tmp/x" --run "$healthy" -o "$tmp/u2.json" --block-s 0
expect_error "at least two bootstrap blocks" "$tmp/x" --run "$healthy" -o "$tmp/u2.json" --block-s 20
[ -e "$tmp/u2.json" ] && fail "a failed calibration wrote its twin"

if [ "$failures" -eq 0 ]; then echo "calibrate_cli: all checks passed"; fi
exit $((failures > 0))
