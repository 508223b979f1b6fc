#!/bin/bash
# `armfault import` (items 1 and 5): stand-in logs written by import_standin.py from
# simulations the importer knows nothing of (drawn payload, sensor noise, friction), in a foreign
# layout (other names, ms clock with jitter, degrees, mA, raw counts, a gap, one long file split
# into runs); imported, they give the simulated signals within the stated resampling bound, the
# labels land in the manifest, and `armfault score` scores the import as it scores an export.
# Then every bad input: exit 2, an error naming the file, the line and the column (or the map,
# its JSON pointer and the value), never the bad cell's text, and nothing written.
# Usage: import_test.sh path/to/armfault
set -u
ARMFAULT=$(realpath "$1")
HERE=$(cd "$(dirname "$0")" && pwd)
PY=/usr/bin/python3
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$ARMFAULT" export "$HERE/import_standin.json" -o sim -q >/dev/null || { echo "FAIL: export"; exit 1; }
$PY "$HERE/import_standin.py" write sim logs || { echo "FAIL: writing the stand-in logs"; exit 1; }

# The round trip, both layouts.
"$ARMFAULT" import logs/rig_0*.csv --map logs/map_files.json -o imp_files -q >/dev/null || fail "import of the per-run files"
"$ARMFAULT" import logs/shift.csv --map logs/map_shift.json -o imp_shift -q >/dev/null || fail "import of the long file"
for layout in files shift; do
  [ -f imp_$layout/campaign.json ] && [ -f imp_$layout/channels.json ] && [ -f imp_$layout/manifest.csv ] ||
    fail "$layout: the export's files are not all there"
  cmp -s sim/channels.json imp_$layout/channels.json || fail "$layout: channels.json differs from the export's"
  $PY "$HERE/import_standin.py" check sim logs imp_$layout $layout || fail "$layout: round trip"
done

# `score` takes an import: an alarm naming each labelled fault 0.3 s after its onset.
$PY - imp_files > verdicts.jsonl <<'EOF'
import json, sys
for line in open(sys.argv[1] + "/manifest.jsonl"):
    m = json.loads(line)
    if m["label"] == "fault":
        print(json.dumps({"run_id": m["run_id"], "t_s": m["onset_s"] + 0.3, "joint": m["joint"],
                          "family": m["family"], "alarm": True, "magnitude": m["magnitude"]}))
EOF
[ "$(wc -l < verdicts.jsonl)" -eq 4 ] || fail "expected 4 labelled faulty runs, got $(wc -l < verdicts.jsonl)"
if "$ARMFAULT" score imp_files verdicts.jsonl -o scored >/dev/null; then
  $PY - scored/summary.json <<'EOF' || fail "score of the import: unexpected summary"
import json, sys
s = json.load(open(sys.argv[1]))["overall"]
assert s["faulty_runs"] == 4 and s["healthy_runs"] == 2, s
assert s["detection"]["rate"] == 1.0 and s["isolation"]["rate"] == 1.0, s
assert s["false_alarm"]["successes"] == 0, s
assert abs(s["latency"]["median_s"] - 0.3) < 0.003, s["latency"]
EOF
else
  fail "armfault score of the import"
fi

# Bad inputs. expect_error NAME 'pattern'... -- ARGS: exit 2, stderr matches every pattern, no
# output directory, no temporary directory left.
expect_error() {
  local name=$1
  shift
  local patterns=()
  while [ "$1" != "--" ]; do patterns+=("$1"); shift; done
  shift
  rm -rf out_bad
  "$ARMFAULT" import "$@" -o out_bad -q >/dev/null 2>err.txt
  local status=$?
  [ $status -eq 2 ] || fail "$name: exit $status, expected 2 ($(cat err.txt))"
  for p in "${patterns[@]}"; do grep -qF -- "$p" err.txt || fail "$name: no \"$p\" in: $(cat err.txt)"; done
  [ ! -e out_bad ] || fail "$name: out_bad was written"
  ls -d out_bad.import-tmp.* >/dev/null 2>&1 && fail "$name: a temporary directory was left"
  grep -q SECRET err.txt && fail "$name: the error echoes the file's contents"
  return 0
}
$PY "$HERE/import_standin.py" bad logs || { echo "FAIL: writing the bad logs"; exit 1; }
gap_line=$($PY -c "import json; print(json.load(open('logs/bad_lines.json'))['bad_gap.csv'])")
shift_line=$($PY -c "import json; print(json.load(open('logs/bad_lines.json'))['bad_shift.csv'])")
M=logs/map_files.json
expect_error nan 'logs/bad_nan.csv: line 101, column "Achse3_Pos_deg": NaN' -- logs/bad_nan.csv --map $M
expect_error empty 'logs/bad_empty.csv: line 102, column "Achse3_Pos_deg": empty cell' -- logs/bad_empty.csv --map $M
expect_error number 'logs/bad_number.csv: line 103, column "Achse3_Pos_deg": not a number' -- logs/bad_number.csv --map $M
expect_error nonmonotonic 'logs/bad_nonmonotonic.csv: line 104, column "Zeit_ms": time does not increase' \
  -- logs/bad_nonmonotonic.csv --map $M
expect_error gap "logs/bad_gap.csv: line $gap_line, column \"Zeit_ms\": a gap of" 'longer than the limit of 0.01 s' \
  -- logs/bad_gap.csv --map $M
expect_error column 'logs/bad_column.csv: line 1: no column "Achse3_Moment_mNm"' '/joints/3/tau_sensor_Nm/column' \
  'did you mean "Achse3_Moment_Nm"?' -- logs/bad_column.csv --map $M
# a good log after a bad one: still nothing written
expect_error second_log 'logs/bad_nan.csv: line 101' -- logs/rig_00.csv logs/bad_nan.csv --map $M
expect_error rerun_run "logs/bad_shift.csv: line $shift_line, column \"Versuch\": the run first seen on line 2 starts again" \
  -- logs/bad_shift.csv --map logs/map_shift.json
expect_error missing_log 'logs/none.csv' -- logs/none.csv --map $M
# A compressed log cut short (after whole lines: the deflate stream ends but its trailer is
# missing; or in the middle) or corrupt: exit 2 with zlib's reason, nothing imported.
head -n 300 logs/rig_00.csv | gzip -c | head -c -8 > logs/cut_at_line.csv.gz
gzip -c logs/rig_00.csv > logs/whole.csv.gz
head -c $(( $(stat -c %s logs/whole.csv.gz) / 2 )) logs/whole.csv.gz > logs/cut.csv.gz
$PY -c "
import sys
b = bytearray(open('logs/whole.csv.gz', 'rb').read()); b[len(b) // 2] ^= 0xff
open('logs/corrupt.csv.gz', 'wb').write(b)"
expect_error gzip_cut_at_line 'logs/cut_at_line.csv.gz: (document root): cannot read the file: unexpected end of file (cut short or corrupt)' \
  -- logs/cut_at_line.csv.gz --map $M
expect_error gzip_cut 'logs/cut.csv.gz: (document root): cannot read the file: unexpected end of file' -- logs/cut.csv.gz --map $M
expect_error gzip_corrupt 'logs/corrupt.csv.gz: (document root): cannot read the file: ' '(cut short or corrupt)' -- logs/corrupt.csv.gz --map $M
# Whole gzip logs import as the plain ones do.
mkdir -p logs/gz && for f in logs/rig_0*.csv; do gzip -c "$f" > "logs/gz/$(basename "$f").gz"; done
if "$ARMFAULT" import logs/gz/rig_0*.csv.gz --map $M -o imp_gz -q >/dev/null; then
  for f in imp_files/runs/*.csv.gz; do
    cmp -s <(zcat "$f") <(zcat "imp_gz/runs/$(basename "$f")") || fail "gzip logs: $(basename "$f") differs from the plain logs' import"
  done
else
  fail "import of whole gzip logs"
fi

# The map's errors name the map, the JSON pointer and the value.
edit_map() {  # edit_map OUT PYTHON-STATEMENT-ON-m
  $PY - "$M" "$1" "$2" <<'EOF'
import json, sys
m = json.load(open(sys.argv[1]))
exec(sys.argv[3])
json.dump(m, open(sys.argv[2], "w"))
EOF
}
edit_map logs/m_unit.json 'm["joints"]["3"]["q_meas_rad"]["unit"] = "furlong"'
expect_error unit 'logs/m_unit.json: /joints/3/q_meas_rad/unit: unknown unit "furlong" for q_meas_rad (known: rad, mrad, deg)' \
  -- logs/rig_00.csv --map logs/m_unit.json
edit_map logs/m_unit2.json 'm["joints"]["2"]["i_cmd_A"]["unit"] = "deg"'
expect_error unit_quantity 'logs/m_unit2.json: /joints/2/i_cmd_A/unit: unknown unit "deg" for i_cmd_A (known: A, mA)' \
  -- logs/rig_00.csv --map logs/m_unit2.json
edit_map logs/m_time.json 'm["time"]["unit"] = "min"'
expect_error time_unit 'logs/m_time.json: /time/unit: unknown time unit "min"' -- logs/rig_00.csv --map logs/m_time.json
edit_map logs/m_key.json 'm["joints"]["1"]["q_mes_rad"] = m["joints"]["1"].pop("q_meas_rad")'
expect_error key 'logs/m_key.json: /joints/1/q_mes_rad' 'did you mean "q_meas_rad"?' -- logs/rig_00.csv --map logs/m_key.json
edit_map logs/m_family.json 'm["labels"]["rig_01"] = {"family": "kt_degredation", "joint": 3, "onset_s": 1.5}'
expect_error family 'logs/m_family.json: /labels/rig_01/family: unknown fault family "kt_degredation"' \
  'did you mean "kt_degradation"?' -- logs/rig_00.csv --map logs/m_family.json
edit_map logs/m_joint.json 'm["joints"]["7"] = m["joints"]["1"]'
expect_error joint 'logs/m_joint.json: /joints/7: joint 7 does not exist: the robot has 3 joints' \
  -- logs/rig_00.csv --map logs/m_joint.json
edit_map logs/m_robot.json 'm["robot"] = "mrr-config9"'
expect_error robot 'logs/m_robot.json: /robot: "mrr-config9" is neither a robot preset' -- logs/rig_00.csv --map logs/m_robot.json
edit_map logs/m_run.json 'm["labels"]["rig_9"] = "healthy"'
expect_error label_run 'logs/m_run.json: /labels/rig_9: no run "rig_9" in the logs' -- logs/rig_00.csv --map logs/m_run.json
edit_map logs/m_magnitude.json 'm["labels"]["rig_00"]["magnitude"] = 7'
expect_error magnitude 'logs/m_magnitude.json: /labels/rig_00/magnitude: 7 is outside kt_degradation' \
  -- logs/rig_00.csv --map logs/m_magnitude.json
# "DIR/" is DIR; an existing empty directory is taken.
mkdir -p imp_slash
"$ARMFAULT" import logs/rig_00.csv --map logs/m_run.json -o imp_slash/ -q >/dev/null 2>&1 && fail "m_run.json was accepted"
"$ARMFAULT" import logs/rig_0*.csv --map $M -o imp_slash/ -q >/dev/null 2>err.txt || fail "-o DIR/: $(cat err.txt)"
[ -f imp_slash/manifest.jsonl ] && [ "$(ls -d imp_slash* | wc -l)" -eq 1 ] || fail "-o DIR/ did not write DIR alone"
# An existing non-empty output directory is refused before anything is read.
mkdir -p out_full && touch out_full/x
"$ARMFAULT" import logs/rig_00.csv --map $M -o out_full -q >/dev/null 2>err.txt
[ $? -eq 2 ] && grep -q "not an empty directory" err.txt || fail "a non-empty output directory: $(cat err.txt)"

if [ $failures -ne 0 ]; then
  echo "$failures failures"
  exit 1
fi
echo "import: round trip (files, shift), score, and every bad input: ok"
