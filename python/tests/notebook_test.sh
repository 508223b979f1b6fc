#!/usr/bin/env bash
# Executes examples/notebooks/first-campaign.ipynb headless, as a user would
# (`jupyter nbconvert --to notebook --execute`), so that the notebook cannot rot: any cell that
# raises fails the test. Then checks what it made: every code cell ran, no error output, its three
# figures drawn (PNG in the executed notebook and on disk) and the campaign's files written. And
# that the check can fail: a notebook whose cell raises must make nbconvert exit non-zero.
# Needs Debian's jupyter-nbconvert, python3-ipykernel (the python3 kernel, /usr/bin/python3) and
# python3-matplotlib (tools/bootstrap.sh --tests), and the package on PYTHONPATH (ctest python_notebook
# sets build/python, as for python_package).
# Usage: notebook_test.sh SOURCE_DIR. Prints "N passed, M failed"; non-zero on failure.
set -euo pipefail

if [[ $# -ne 1 || ! -f $1/examples/notebooks/first-campaign.ipynb ]]; then
  echo "usage: $0 SOURCE_DIR" >&2
  exit 2
fi
src=$(cd "$1" && pwd)
if ! /usr/bin/python3 -c 'import nbconvert, ipykernel, matplotlib' 2>/dev/null; then
  echo "FAIL: /usr/bin/python3 lacks nbconvert, ipykernel or matplotlib: apt-get install jupyter-nbconvert python3-ipykernel python3-matplotlib (tools/bootstrap.sh --tests)"
  exit 1
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_notebook_test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
# Jupyter's and matplotlib's state (connection files, font cache) in the temp dir, not in $HOME.
export JUPYTER_RUNTIME_DIR=$tmp/runtime IPYTHONDIR=$tmp/ipython MPLCONFIGDIR=$tmp/mpl
export PYDEVD_DISABLE_FILE_VALIDATION=1  # ipykernel's debugger warning on every kernel start
# The kernel runs in the notebook's directory: PYTHONPATH's entries made absolute.
PYTHONPATH=$(/usr/bin/python3 -c 'import os, sys; print(os.pathsep.join(os.path.abspath(p) for p in sys.argv[1].split(os.pathsep) if p))' "${PYTHONPATH:-}")
export PYTHONPATH

# /usr/bin/python3's nbconvert (Debian's), whatever python3 is first on the PATH.
nbconvert() {
  /usr/bin/python3 -m nbconvert --to notebook --execute --ExecutePreprocessor.kernel_name=python3 \
    --ExecutePreprocessor.timeout=300 "$@"
}

passed=0
failed=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1
  shift
  if "$@" >"$tmp/out" 2>&1; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $name: $(tail -c 1500 "$tmp/out")"; fi
}

executes() {
  ARMFAULT_NOTEBOOK_OUT=$tmp/out_dir nbconvert --output-dir "$tmp/executed" \
    "$src/examples/notebooks/first-campaign.ipynb"
}
check notebook_executes executes

executed_notebook_complete() {
  /usr/bin/python3 - "$tmp/executed/first-campaign.ipynb" "$tmp/out_dir" <<'PY'
import json, pathlib, sys
nb = json.load(open(sys.argv[1]))
out = pathlib.Path(sys.argv[2])
problems = []
code = [c for c in nb["cells"] if c["cell_type"] == "code"]
for k, cell in enumerate(code):
    if cell.get("execution_count") is None:
        problems.append(f"code cell {k} did not run")
    for o in cell["outputs"]:
        if o["output_type"] == "error":
            problems.append(f"code cell {k} raised {o['ename']}: {o['evalue']}")
        if o["output_type"] == "stream" and o["name"] == "stderr" and "Traceback" in "".join(o["text"]):
            problems.append(f"code cell {k} printed a traceback")
pngs = sum("image/png" in o.get("data", {}) for c in code for o in c["outputs"])
if pngs != 3:
    problems.append(f"expected 3 figures in the executed notebook, got {pngs}")
for name in ("detection_vs_magnitude.png", "confusion_matrix.png", "one_run.png"):
    path = out / name
    if not path.is_file() or path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n" or path.stat().st_size < 10000:
        problems.append(f"{path}: no figure")
for name in ("campaign.json", "results.jsonl", "decisions.jsonl", "summary.json"):
    if not (out / "campaign" / name).is_file():
        problems.append(f"the campaign wrote no {name}")
text = "".join("".join(o.get("text", "")) for c in code for o in c["outputs"])
if "first tick over the threshold" not in text:
    problems.append("the one-run cell printed no detection check")
if problems:
    sys.exit("\n".join(problems))
PY
}
check executed_notebook_complete executed_notebook_complete

# The check can fail: a cell that raises ends nbconvert with a non-zero status.
raising_cell_fails() {
  /usr/bin/python3 -c '
import nbformat, sys
nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("import armfault"),
                                     nbformat.v4.new_code_cell("raise RuntimeError(\"cell raised\")")])
nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
nbformat.write(nb, sys.argv[1])' "$tmp/raises.ipynb"
  if nbconvert --output-dir "$tmp/executed_raises" "$tmp/raises.ipynb" >"$tmp/raises.log" 2>&1; then
    echo "nbconvert exited 0 on a notebook whose cell raises"
    return 1
  fi
  grep -q "cell raised" "$tmp/raises.log"
}
check raising_cell_fails raising_cell_fails

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
