#!/usr/bin/env bash
# The campaign report as a browser shows it: runs campaigns/files/ci.json, tunes it (or, while
# `armfault tune` does not exist, uses the tuning.json fixture), writes the report and renders
# it in headless Chromium. Checks that vega-embed drew every plot's Vega-Lite spec (its <div>
# holds an <svg> of marks with non-empty path data), that the required plots are there, that
# nothing is fetched (no script or link with a source), that a click on a run's dot copies
# that run's `armfault trace` command, and that a screenshot is produced.
# Chromium missing is a failure, not a skip: tools/bootstrap.sh --tests installs it.
# Usage: report_chromium_test.sh path/to/armfault
# Prints one line per failed check and a final "N passed, M failed"; exits non-zero on failure.
set -u

if [[ $# -ne 1 || ! -x "$1" ]]; then
  echo "usage: $0 path/to/armfault" >&2
  exit 2
fi
armfault=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
src=$(cd "$(dirname "$0")/../../.." && pwd)
fixture="$src/tests/reports/page/data/tuning.json"

passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() {
  failed=$((failed + 1))
  echo "FAIL: $*"
}
finish() {
  echo "$passed passed, $failed failed"
  [[ $failed -eq 0 ]]
  exit $?
}

chromium=$(command -v chromium || command -v chromium-browser || true)
if [[ -z "$chromium" ]]; then
  fail "chromium is not installed (tools/bootstrap.sh --tests installs the Debian package chromium)"
  finish
fi
pass

tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_report_chromium.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
dir="$tmp/ci"

# A campaign directory: ci.json meets its floors (0); a missed floor (1) still has every file.
"$armfault" run "$src/campaigns/files/ci.json" -o "$dir" -q >"$tmp/run.log" 2>&1
status=$?
if [[ $status -le 1 && -f "$dir/summary.json" ]]; then pass; else fail "armfault run: status $status: $(tail -5 "$tmp/run.log")"; finish; fi

# `armfault tune --help` alone is not enough: without a tune subcommand CLI11 prints the
# top-level help and exits 0. The subcommand's own usage line names it.
if "$armfault" tune --help 2>/dev/null | grep -q "Usage: .* tune "; then
  "$armfault" tune "$dir" >"$tmp/tune.log" 2>&1 || true
  if [[ -f "$dir/tuning.json" ]]; then pass; else fail "armfault tune wrote no tuning.json: $(tail -5 "$tmp/tune.log")"; fi
else
  cp "$fixture" "$dir/tuning.json" && pass
fi

"$armfault" report "$dir" >"$tmp/report.log" 2>&1
status=$?
if [[ $status -eq 0 && -s "$dir/report.html" && -s "$dir/report.md" ]]; then
  pass
else
  fail "armfault report: status $status: $(tail -5 "$tmp/report.log")"
  finish
fi

flags=(--headless --no-sandbox --disable-gpu --disable-dev-shm-usage --no-first-run --no-default-browser-check
       --disable-extensions --hide-scrollbars "--user-data-dir=$tmp/profile")
url="file://$dir/report.html"

# Vega draws after the page's load event, asynchronously: a virtual-time budget lets it finish.
timeout 180 "$chromium" "${flags[@]}" --virtual-time-budget=30000 --dump-dom "$url" >"$tmp/dom.html" 2>"$tmp/chromium-dom.log"
status=$?
if [[ $status -eq 0 && -s "$tmp/dom.html" ]]; then
  pass
else
  fail "chromium --dump-dom: status $status: $(tail -5 "$tmp/chromium-dom.log")"
  finish
fi

# Each plot of the page (the data-plot of its spec), and in the rendered DOM each plot with "ok"
# when vega-embed drew it: its <div> says data-rendered="true" and holds an <svg> with a mark
# group (class "mark-...") whose paths have path data.
grep -o 'class="vega-spec" data-plot="[^"]*"' "$dir/report.html" | sed 's/.*data-plot="//; s/"$//' | sort >"$tmp/ids.txt"
python3 - "$tmp/dom.html" "$tmp/ids.txt" >"$tmp/dom-ids.txt" <<'PY'
import re, sys
dom = open(sys.argv[1], encoding="utf-8").read()
for plot in open(sys.argv[2]).read().split():
    m = re.search(r'<div[^>]*\bid="%s"[^>]*>' % re.escape(plot), dom)
    if not m:
        print(plot, "missing")
        continue
    end = dom.find('data-plot="%s"' % plot, m.end())
    body = dom[m.start():end if end > 0 else len(dom)]
    drawn = ('data-rendered="true"' in m.group(0) and "<svg" in body and
             re.search(r'<g class="mark-[^"]*"[^>]*>.*?<path[^>]* d="M[^"]+', body, re.S) is not None)
    print(plot, "ok" if drawn else "empty")
PY
count=$(wc -l <"$tmp/ids.txt")
if [[ $count -ge 9 ]]; then pass; else fail "only $count plots in report.html"; fi
while read -r id; do
  if grep -qx "$id ok" "$tmp/dom-ids.txt"; then
    pass
  else
    fail "plot $id: not rendered with data ($(grep "^$id " "$tmp/dom-ids.txt" || echo missing))"
  fi
done <"$tmp/ids.txt"
# The plots every report of this campaign must have.
for pattern in '^roc$' '^pod-' '^latency-threshold-' '^confusion$' '^latency-distribution$' '^thesis-table-5-3$' \
               '^run-j[0-9]+-efficiency$' '^run-j[0-9]+-current$' '^run-j[0-9]+-torque$'; do
  if grep -Eq "$pattern" "$tmp/ids.txt"; then pass; else fail "no plot matching $pattern"; fi
done
# Nothing fetched from elsewhere: no remote URL as a source or link, and every script inline.
if grep -Eq '(src|href)="(https?:)?//' "$tmp/dom.html"; then fail "the page refers to a remote URL"; else pass; fi
# In report.html outside its scripts' text (the libraries' code builds tags of its own), no
# element with a source or a link elsewhere, and every <script> inline.
loads=$(python3 - "$dir/report.html" <<'PY'
import re, sys
html = open(sys.argv[1], encoding="utf-8").read()
tags = re.findall(r"<script[^>]*>", html)
page = re.sub(r"(<script[^>]*>).*?</script>", r"\1</script>", html, flags=re.S)
bad = [t for t in re.findall(r"<[a-z]+[^>]*\b(?:src|href)=\"[^#\"][^>]*>", page)]
bad += [t for t in tags if " src=" in t]
print("\n".join(bad[:3]))
PY
)
if [[ -z "$loads" ]]; then pass; else fail "report.html loads a file: $loads"; fi

# A click on a run's mark copies its trace command: a copy of the page whose probe, once the
# plots are drawn, stands in for the clipboard (headless Chromium grants no clipboard to a
# synthetic click) and clicks the first detection-probability dot.
python3 - "$dir/report.html" "$tmp/click.html" <<'PY'
import sys
html = open(sys.argv[1], encoding="utf-8").read()
probe = """<script>setTimeout(function () {
  Object.defineProperty(navigator, 'clipboard', {value: {writeText: function (t) {
    document.body.setAttribute('data-copied', t); return Promise.resolve(); }}});
  var mark = document.querySelector('div.plot[id^="pod-"] g.mark-symbol path');
  if (mark) mark.dispatchEvent(new MouseEvent('click', {bubbles: true, cancelable: true, view: window}));
}, 3000);</script>"""
at = html.rindex("</body>")
open(sys.argv[2], "w", encoding="utf-8").write(html[:at] + probe + html[at:])
PY
timeout 120 "$chromium" "${flags[@]}" --virtual-time-budget=10000 --dump-dom "file://$tmp/click.html" \
  >"$tmp/click-dom.html" 2>"$tmp/chromium-click.log"
copied=$(grep -o '<body[^>]* data-copied="[^"]*"' "$tmp/click-dom.html" | sed 's/.*data-copied="//; s/"$//')
run=$(sed -n "s/^armfault trace [^ ]*campaign.json --run '\{0,1\}\([^' ]*\)'\{0,1\} -o [^ ]*\.csv\$/\1/p" <<<"$copied")
if [[ -n "$run" ]] && grep -qF "\"run_id\":\"$run\"" "$dir/results.jsonl"; then
  pass
else
  fail "a click on a detection-probability dot copied '$copied', not a trace command of a run of results.jsonl"
fi

timeout 180 "$chromium" "${flags[@]}" --virtual-time-budget=30000 "--screenshot=$tmp/shot.png" --window-size=1400,5000 "$url" \
  >"$tmp/chromium-shot.log" 2>&1
status=$?
size=$(stat -c %s "$tmp/shot.png" 2>/dev/null || echo 0)
magic=$(head -c 4 "$tmp/shot.png" 2>/dev/null | od -An -c | tr -d ' \n')
if [[ $status -eq 0 && "$magic" == "211PNG" && $size -gt 100000 ]]; then
  pass
else
  fail "screenshot: status $status, $size bytes, magic '$magic': $(tail -5 "$tmp/chromium-shot.log")"
fi
finish
