#!/usr/bin/env bash
# Checks of what runs armfault elsewhere, without Docker or a cluster: the Kubernetes Jobs in
# deploy/k8s/ (they parse, and shards.yaml and merge.yaml agree on the image, the index variable,
# --shard-count = completions, the output path and the volume), the Dockerfile's package lists
# (build stage = tools/bootstrap.sh's build_packages, the main job's; runtime stage = the libraries the
# binary links), and `cmake --install` into a temp prefix giving a working bin/armfault and the
# monitor plugin header a plugin builds against.
# Usage: deploy_test.sh SOURCE_DIR BUILD_DIR. Prints "N passed, M failed"; non-zero on failure.
set -euo pipefail

if [[ $# -ne 2 || ! -d $1 || ! -x $2/armfault ]]; then
  echo "usage: $0 SOURCE_DIR BUILD_DIR (BUILD_DIR holding a built armfault)" >&2
  exit 2
fi
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/armfault_deploy_test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

passed=0
failed=0
check() {  # check NAME CONDITION-COMMAND...
  local name=$1
  shift
  if "$@" >"$tmp/out" 2>&1; then passed=$((passed + 1)); else failed=$((failed + 1)); echo "FAIL: $name: $(head -c 600 "$tmp/out")"; fi
}

# ------------------------------------------------------------------ Kubernetes YAML
# Debian's python3-yaml (tools/bootstrap.sh --tests) is for /usr/bin/python3; another python3 may have its own.
py=""
for p in /usr/bin/python3 python3; do
  if command -v "$p" >/dev/null && "$p" -c 'import yaml' 2>/dev/null; then py=$p; break; fi
done
k8s_yaml() {
  [[ -n $py ]] || { echo "no python3 with the yaml module (Debian: python3-yaml, see tools/bootstrap.sh --tests)"; return 1; }
  "$py" - "$src/deploy/k8s/shards.yaml" "$src/deploy/k8s/merge.yaml" "$src/README.md" <<'PY'
import re, sys, yaml

problems = []
def need(cond, what):
    if not cond:
        problems.append(what)

def load(path):
    with open(path) as f:
        docs = [d for d in yaml.safe_load_all(f) if d is not None]
    if len(docs) != 1:
        sys.exit(f"{path}: expected one YAML document, got {len(docs)}")
    return docs[0]

shards, merge = load(sys.argv[1]), load(sys.argv[2])
readme = open(sys.argv[3]).read()

def container(job, path):
    cs = job["spec"]["template"]["spec"]["containers"]
    need(len(cs) == 1, f"{path}: one container expected")
    return cs[0]

for job, name, path in ((shards, "armfault-shards", "shards.yaml"), (merge, "armfault-merge", "merge.yaml")):
    need(job.get("apiVersion") == "batch/v1" and job.get("kind") == "Job", f"{path}: not a batch/v1 Job")
    need(job["metadata"]["name"] == name, f"{path}: metadata.name is not {name}")
    need(job["spec"]["template"]["spec"].get("restartPolicy") == "Never", f"{path}: restartPolicy must be Never")

spec = shards["spec"]
need(spec.get("completionMode") == "Indexed", "shards.yaml: completionMode must be Indexed")
n = spec.get("completions")
need(isinstance(n, int) and n >= 1, "shards.yaml: completions must be a whole number")
need(isinstance(spec.get("backoffLimitPerIndex"), int), "shards.yaml: backoffLimitPerIndex missing")
rules = spec.get("podFailurePolicy", {}).get("rules", [])
need(any(r.get("action") == "FailJob" and r.get("onExitCodes", {}).get("operator") == "In"
         and r["onExitCodes"].get("values") == [2] and r["onExitCodes"].get("containerName") == "armfault"
         for r in rules), "shards.yaml: no FailJob rule on exit code 2 of container armfault")
need(any(r.get("action") == "Ignore" and {"type": "DisruptionTarget"} in r.get("onPodConditions", [])
         for r in rules), "shards.yaml: no Ignore rule on the DisruptionTarget condition")

sc, mc = container(shards, "shards.yaml"), container(merge, "merge.yaml")
need(sc["name"] == "armfault", "shards.yaml: the container must be named armfault (the FailJob rule names it)")
image = sc.get("image", "")
need(image != "" and mc.get("image") == image, f"the two Jobs name different images: {image!r}, {mc.get('image')!r}")
need(f"docker build -t {image} ." in readme, f"README.md does not build the image {image!r} (docker build -t {image} .)")

run = " ".join(sc.get("command", []) + sc.get("args", []))
m = re.search(r"armfault run (\S+) --shard-count (\d+) -o (\S+)\$JOB_COMPLETION_INDEX(?:\s|$)", run)
need(m is not None, f"shards.yaml: no 'armfault run CAMPAIGN --shard-count N -o DIR$JOB_COMPLETION_INDEX' in {run!r}")
need("--resume" in run, "shards.yaml: the shards must run with --resume (a retried pod continues)")
mrun = " ".join(mc.get("command", []) + mc.get("args", []))
mm = re.search(r"armfault merge (\S+)\* -o (\S+)", mrun)
need(mm is not None, f"merge.yaml: no 'armfault merge PREFIX* -o DIR' in {mrun!r}")
if m and mm:
    need(int(m.group(2)) == n, f"shards.yaml: --shard-count {m.group(2)} differs from completions {n}")
    need(m.group(3) == mm.group(1), f"the shards write {m.group(3)}K but the merge reads {mm.group(1)}*")
    # The output path must lie on the same claim in both Jobs.
    def claim_of(job, c, path):
        mount = max((v for v in c.get("volumeMounts", []) if path.startswith(v["mountPath"].rstrip("/") + "/")),
                    key=lambda v: len(v["mountPath"]), default=None)
        if mount is None:
            return None
        vol = next(v for v in job["spec"]["template"]["spec"]["volumes"] if v["name"] == mount["name"])
        return vol.get("persistentVolumeClaim", {}).get("claimName")
    a, b = claim_of(shards, sc, m.group(3)), claim_of(merge, mc, mm.group(1))
    need(a is not None and a == b, f"the output path is on claim {a!r} for the shards and {b!r} for the merge")
    need(mm.group(2).startswith(m.group(3).rsplit("/", 1)[0]), "merge.yaml: the merged output is not beside the shards")
for f in ("deploy/k8s/shards.yaml", "deploy/k8s/merge.yaml"):
    need(f in readme, f"README.md does not point to {f}")
if problems:
    sys.exit("\n".join(problems))
print(f"ok: {n} shards, image {image}")
PY
}
check k8s_yaml k8s_yaml

# A broken file must fail the check (the check can fail).
k8s_yaml_catches_mismatch() {
  mkdir -p "$tmp/bad/deploy/k8s"
  cp "$src/README.md" "$tmp/bad/"
  sed 's/--shard-count 16/--shard-count 15/' "$src/deploy/k8s/shards.yaml" >"$tmp/bad/deploy/k8s/shards.yaml"
  cp "$src/deploy/k8s/merge.yaml" "$tmp/bad/deploy/k8s/"
  local saved=$src
  src=$tmp/bad
  if k8s_yaml; then src=$saved; echo "a --shard-count unequal to completions passed"; return 1; fi
  src=$saved
}
check k8s_yaml_catches_mismatch k8s_yaml_catches_mismatch

# ------------------------------------------------------------------ Dockerfile
# The packages of the first `apt-get install` in the stage starting at FROM number $1.
stage_packages() {
  awk -v stage="$1" '
    /^FROM / { n++ }
    n == stage && /apt-get install/ { on = 1 }
    on { line = line " " $0; if ($0 !~ /\\$/) { on = 0; done = 1 } }
    END { print line }' "$src/Dockerfile" |
    tr ' \\' '\n\n' | sed -n '/^install$/,$p' | grep -E '^[a-z0-9][a-z0-9.+-]+$' | grep -vx -e install -e '&&' |
    sed '/^rm$/,$d' | sort -u
}
# The packages of the list `$1=(...)` in tools/bootstrap.sh.
bootstrap_packages() {
  sed -n "/^$1=(/,/)/p" "$src/tools/bootstrap.sh" | tr -d '()' | sed "s/$1=//" | tr ' ' '\n' |
    grep -E '^[a-z0-9]' | sort -u
}
docker_build_stage() {
  # The image's build stage installs what the main job's bootstrap does: its build_packages.
  local want
  want=$(bootstrap_packages build_packages)
  [[ -n $want ]] || { echo "no build_packages=(...) list in tools/bootstrap.sh"; return 1; }
  diff <(echo "$want") <(stage_packages 1) || { echo "(< bootstrap's build_packages, > Dockerfile build stage)"; return 1; }
  grep -q -- '-DBUILD_TESTING=OFF -DARMFAULT_BUILD_BENCH=OFF' "$src/Dockerfile"
}
check docker_build_stage docker_build_stage
docker_runtime_stage() {
  # Every shared library the binary loads must come from a runtime-stage package or the base image.
  local base="libc6 libstdc++6 libgcc-s1" libs pkgs missing="" have queue p
  libs=$(ldd "$build/armfault" | awk '/=> \//{print $3}')
  pkgs=$(for l in $libs; do dpkg -S "$(readlink -f "$l")" 2>/dev/null || dpkg -S "$l"; done | cut -d: -f1 | sort -u)
  # What apt installs with the runtime stage's packages: their dependencies, recursively (as
  # installed here; libode8 brings libccd2).
  have=" $base "
  queue=$(stage_packages 2)
  while [[ -n $queue ]]; do
    set -- $queue
    p=$1
    shift
    queue="$*"
    [[ $have == *" $p "* ]] && continue
    have="$have$p "
    queue="$queue $(dpkg-query -W -f='${Depends}, ${Pre-Depends}' "$p" 2>/dev/null |
      tr ',|' '\n\n' | sed 's/(.*)//; s/:any//; s/ //g' | grep -v '^$' | tr '\n' ' ')"
  done
  for p in $pkgs; do
    [[ $have == *" $p "* ]] || missing="$missing $p"
  done
  [[ -z $missing ]] || { echo "the runtime stage lacks:$missing (the binary links $(echo $libs))"; return 1; }
}
check docker_runtime_stage docker_runtime_stage

# ------------------------------------------------------------------ cmake --install
install_prefix() {
  cmake --install "$build" --prefix "$tmp/prefix" >/dev/null &&
    "$tmp/prefix/bin/armfault" --version | grep -qx "armfault 0.1.0" &&
    "$tmp/prefix/bin/armfault" validate "$tmp/prefix/share/armfault/campaigns/ci.json" >"$tmp/validate_ci" &&
    grep -q ': 52 runs' "$tmp/validate_ci" &&
    [[ -f $tmp/prefix/share/armfault/campaigns/thesis-sweep.json && -f $tmp/prefix/share/armfault/campaigns/five-families.json ]]
}
check install_prefix install_prefix
# The monitor plugin header (docs/monitor-api.md, "C plugin") installed beside the binary, usable
# from C99 and C++; the example plugin built from it with the documented gcc line loads.
installed_plugin_header() {
  local header=$tmp/prefix/include/armfault/monitor_plugin.h
  [[ -f $header ]] || { echo "$header not installed"; return 1; }
  printf '#include <armfault/monitor_plugin.h>\n#include <armfault/monitor_settings.h>\n' |
    gcc -std=c99 -pedantic -Wall -Wextra -Werror -fsyntax-only -I "$tmp/prefix/include" -x c - &&
    printf '#include <armfault/monitor_plugin.h>\n#include <armfault/monitor_settings.h>\n' |
      g++ -std=c++17 -pedantic -Wall -Wextra -Werror -fsyntax-only -I "$tmp/prefix/include" -x c++ - &&
    mkdir -p "$tmp/plugin" &&
    gcc -std=c99 -O2 -Wall -Wextra -Werror -fPIC -shared -I "$tmp/prefix/include" \
      "$src/examples/plugins/current_residual.c" -o "$tmp/plugin/libcurrent_residual.so" -lm &&
    cp "$src/tests/core/monitors/data/plugin_campaign.json" "$tmp/plugin/" &&
    "$tmp/prefix/bin/armfault" validate --load-plugins "$tmp/plugin/plugin_campaign.json" >"$tmp/plugin/out" &&
    grep -q ': 28 runs' "$tmp/plugin/out"
}
check installed_plugin_header installed_plugin_header

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
