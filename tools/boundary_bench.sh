#!/usr/bin/env bash
# The boundary benchmark (a benchmark script, not a timed test): K_T degradation of
# joint 3 on two trajectories (campaigns/files/boundary-bench.json).
#  1. the 400-run grid (kt_factor 0.900 ... 0.995 in 20 steps x 10 repetitions x 2 trajectories)
#     with `armfault run`, and its a90/95 per trajectory by the same fit (`boundary --from`);
#  2. the boundary search of the same file (`armfault boundary`);
# then prints both estimates, their difference and the runs each used, and checks the target:
# |search - grid| <= 0.02 in kt_factor for every cell, with at most a quarter of the grid's runs.
# Usage: tools/boundary_bench.sh [path/to/armfault] [OUT_DIR] [JOBS]
set -euo pipefail
armfault=${1:-build/armfault}
out=${2:-out/boundary-bench}
jobs=${3:-2}
src=$(cd "$(dirname "$0")/.." && pwd)
campaign="$src/campaigns/files/boundary-bench.json"
mkdir -p "$out"
start=$(date +%s)
"$armfault" run "$campaign" -o "$out/grid" -j "$jobs" -q > "$out/grid.log"
"$armfault" boundary --from "$out/grid" > "$out/grid-boundary.log"
mid=$(date +%s)
"$armfault" boundary "$campaign" -o "$out/search" -j "$jobs" -q > "$out/search.log"
end=$(date +%s)
python3 - "$out/grid/boundary.json" "$out/search/boundary.json" "$((mid - start))" "$((end - mid))" <<'PY'
import json, sys
grid, search = (json.load(open(p)) for p in sys.argv[1:3])
ok = True
print("%-8s %-22s %12s %12s %10s %10s %11s  %s" % ("trajectory", "cell", "grid a90/95", "search a90/95",
      "difference", "grid runs", "search runs", "search status"))
for g, s in zip(grid["cells"], search["cells"]):
    cell = "%s j%d" % (g["family"], g["joint"])
    ga, sa = g["a90_95"], s["a90_95"]
    diff = None if ga is None or sa is None else sa - ga
    ok = ok and diff is not None and abs(diff) <= 0.02
    f = lambda x: "-" if x is None else "%.4f" % x
    print("%-10s %-22s %12s %12s %10s %10d %11d  %s" % (g["trajectory"], cell, f(ga), f(sa),
          "-" if diff is None else "%+.4f" % diff, g["runs"], s["runs"], s["status"]))
runs_ok = search["runs"] * 4 <= grid["runs"]
ok = ok and runs_ok
print("runs: grid %d, search %d (%.1f %% of the grid; target <= 25 %%)" % (grid["runs"], search["runs"],
      100.0 * search["runs"] / grid["runs"]))
print("wall time: grid %s s, search %s s" % (sys.argv[3], sys.argv[4]))
print("target (|difference| <= 0.02 in every cell, runs <= a quarter): %s" % ("MET" if ok else "MISSED"))
sys.exit(0 if ok else 1)
PY
