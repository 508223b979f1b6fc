#!/usr/bin/env bash
# The realistic fleet's 90/95 targets, as a check: runs campaigns/files/realistic-pod.json (K_T and
# friction swept near the detection boundary on 20 units with datasheet tolerances, 15-40 °C,
# commissioning), scores it at the monitor's own limits with `armfault tune` (the as-run
# setting only), and requires the 90 % detection at 95 % confidence (a90/95) within
#   K_T factor >= 0.90 (a loss of at most 10 %), friction factor <= 1.5.
# Usage: realistic_pod_test.sh path/to/armfault
set -euo pipefail
armfault=$1
src=$(cd "$(dirname "$0")/../../.." && pwd)
out=$(mktemp -d "${TMPDIR:-/tmp}/armfault_pod.XXXXXX")
trap 'rm -rf "$out"' EXIT
"$armfault" run "$src/campaigns/files/realistic-pod.json" -o "$out" -q -j 2 >/dev/null
# Only the as-run limits: the figures are the monitor's as shipped, not a tuned one's.
limits=$(python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))["campaign"]["monitor"]
print("kt_factor.worn=%g,friction_factor.worn=%g,resistance_factor.worn=%g,sensor_drift_Nm.worn=%g,significance=%g" % (
    m["kt_factor"]["worn"], m["friction_factor"]["worn"], m["resistance_factor"]["worn"], m["sensor_drift_Nm"]["worn"],
    m["significance"]))' "$out/campaign.json")
"$armfault" tune "$out" --sweep "$limits" >/dev/null
python3 "$src/tools/realistic_targets.py" "$out" --check-a90-95 kt_degradation:0.90:min friction_increase:1.5:max
