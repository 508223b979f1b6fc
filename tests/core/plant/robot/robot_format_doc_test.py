#!/usr/bin/python3
"""docs/robot-format.md against the robot the loader writes back.

Usage: robot_format_doc_test.py path/to/armfault SOURCE_DIR

Runs a tiny campaign on "mrr-config1" and reads its robot from campaign.json (every key filled
in). Every key there must be documented in docs/robot-format.md and every documented key must
exist; the default columns of the module groups must equal joint 2 (MRR2 defaults) and joint 1
(MRR1 defaults), and the mrr-config1 columns of the top-level and link tables the preset's
values; the allowed ranges of the module groups must be the schema's. Prints one line per
failed check and "N passed, M failed"; exits non-zero on failure.
"""
import json
import os
import re
import subprocess
import sys
import tempfile

if len(sys.argv) != 3:
    print("usage: robot_format_doc_test.py path/to/armfault SOURCE_DIR", file=sys.stderr)
    sys.exit(2)
ARMFAULT = os.path.abspath(sys.argv[1])
SRC = os.path.abspath(sys.argv[2])

passed = 0
failed = 0
# Module groups written back only when the robot gives them (absent: the feature is off).
OPTIONAL_GROUPS = ["ripple"]


def check(name, ok, detail=""):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL: %s%s" % (name, ": " + detail if detail else ""))


with tempfile.TemporaryDirectory(prefix="armfault_robot_doc.") as tmp:
    path = os.path.join(tmp, "tiny.json")
    with open(path, "w") as f:
        json.dump({"robot": "mrr-config1", "duration_s": 0.02, "healthy": 1,
                   "trajectories": [{"name": "still", "joints": {}}]}, f)
    r = subprocess.run([ARMFAULT, "run", path, "-o", os.path.join(tmp, "out"), "-q", "-j", "1"],
                       capture_output=True, text=True, timeout=300)
    if r.returncode not in (0, 1):
        print("FAIL: tiny campaign: status %d: %s" % (r.returncode, r.stderr[:300]))
        sys.exit(1)
    with open(os.path.join(tmp, "out", "campaign.json")) as f:
        robot = json.load(f)["campaign"]["robot"]
    # "engine" is written only when it is not the default (an ODE robot is written as before):
    # from a campaign run in the articulated engine, where it must be there.
    with open(path, "w") as f:
        json.dump({"robot": "mrr-config1", "engine": "articulated", "duration_s": 0.02, "healthy": 1,
                   "trajectories": [{"name": "still", "joints": {}}]}, f)
    r = subprocess.run([ARMFAULT, "run", path, "-o", os.path.join(tmp, "art"), "-q", "-j", "1"],
                       capture_output=True, text=True, timeout=300)
    with open(os.path.join(tmp, "art", "campaign.json")) as f:
        articulated = json.load(f)["campaign"]["robot"]
    check("engine written when not ode", "engine" not in robot and articulated.get("engine") == "articulated",
          "ode robot %s, articulated robot %s" % (robot.get("engine"), articulated.get("engine")))
    robot["engine"] = "ode"
    # The optional groups (written only when given, so absent from mrr-config1): their defaults
    # from an MRR1 and an MRR2 module that give them empty.
    with open(path, "w") as f:
        json.dump({"robot": {"modules": [{"type": "MRR1", **{g: {} for g in OPTIONAL_GROUPS}},
                                         {g: {} for g in OPTIONAL_GROUPS}], "links": [{}, {}]},
                   "duration_s": 0.02, "healthy": 1, "trajectories": [{"name": "still", "joints": {}}]}, f)
    r = subprocess.run([ARMFAULT, "run", path, "-o", os.path.join(tmp, "opt"), "-q", "-j", "1"],
                       capture_output=True, text=True, timeout=300)
    if r.returncode not in (0, 1):
        print("FAIL: campaign with the optional groups: status %d: %s" % (r.returncode, r.stderr[:300]))
        sys.exit(1)
    with open(os.path.join(tmp, "opt", "campaign.json")) as f:
        optional = json.load(f)["campaign"]["robot"]["modules"]
    for g in OPTIONAL_GROUPS:
        check("optional group %s absent from mrr-config1" % g, g not in robot["modules"][1])
        robot["modules"][0][g] = optional[0][g]
        robot["modules"][1][g] = optional[1][g]

with open(os.path.join(SRC, "docs", "robot-format.md")) as f:
    doc = f.read()

# Tables by section: the heading above them ("Top level", "Module", "`motor`: ...", "Link").
tables = {}
section = None
header = None
for line in doc.split("\n"):
    m = re.match(r"^#+ (.*)$", line)
    if m:
        heading = m.group(1)
        g = re.match(r"^`(\w+)`", heading)
        section = g.group(1) if g else heading
        header = None
        continue
    if not line.startswith("|"):
        continue
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if header is None:
        header = cells
        continue
    if set(line) <= set("|-"):
        continue
    keys = re.findall(r"`(\w+)`", cells[0])
    for key in keys:
        tables.setdefault(section, {})[key] = dict(zip(header, cells))


def number(text):
    """A documented number: unicode minus, thin thousands spaces, scientific notation."""
    return float(text.replace("\u2212", "-").replace(" ", "").replace("\u202f", ""))


def same(doc_text, value):
    if isinstance(value, bool):
        return doc_text == "`%s`" % str(value).lower()
    if isinstance(value, str):
        return doc_text.strip("`\"") == value
    if isinstance(value, list):
        nums = re.findall(r"[-\u2212]?[0-9.]+(?:e[-\u2212]?[0-9]+)?", doc_text)
        return len(nums) == len(value) and all(abs(number(n) - v) <= 1e-12 * max(1, abs(v)) for n, v in zip(nums, value))
    try:
        return abs(number(doc_text) - value) <= 1e-12 * max(1, abs(value))
    except ValueError:
        return False


mrr1, mrr2 = robot["modules"][0], robot["modules"][1]
groups = [k for k, v in mrr2.items() if isinstance(v, dict)]

# Coverage: the same keys in the doc as in the written robot.
top_keys = set(robot)
check("top-level keys documented", set(tables.get("Top level", {})) == top_keys,
      "doc %s, code %s" % (sorted(tables.get("Top level", {})), sorted(top_keys)))
module_keys = {k for k in mrr2 if k not in groups}
documented_module = set(tables.get("Module", {})) - set(groups)
check("module keys documented", documented_module == module_keys, "doc %s, code %s" % (sorted(documented_module), sorted(module_keys)))
link_keys = set().union(*(set(l) for l in robot["links"])) | {"inertia_kg_m2"}
check("link keys documented", set(tables.get("Link", {})) == link_keys, "doc %s, code %s" % (sorted(tables.get("Link", {})), sorted(link_keys)))
for g in groups:
    check("%s keys documented" % g, set(tables.get(g, {})) == set(mrr2[g]),
          "doc %s, code %s" % (sorted(tables.get(g, {})), sorted(mrr2[g])))

# Defaults of each group: MRR2 = joint 2 of mrr-config1, MRR1 = joint 1.
for g in groups:
    for key, row in tables.get(g, {}).items():
        if key not in mrr2[g]:
            continue
        if "MRR2" in row:
            check("%s/%s MRR2 default" % (g, key), same(row["MRR2"], mrr2[g][key]), "doc %s, code %s" % (row["MRR2"], mrr2[g][key]))
            check("%s/%s MRR1 default" % (g, key), same(row["MRR1"], mrr1[g][key]), "doc %s, code %s" % (row["MRR1"], mrr1[g][key]))
        else:
            both = row.get("default (both types)", "")
            check("%s/%s default" % (g, key), same(both, mrr2[g][key]) and mrr1[g][key] == mrr2[g][key],
                  "doc %s, code MRR2 %s MRR1 %s" % (both, mrr2[g][key], mrr1[g][key]))

# The allowed ranges of the module groups, as the schema states them (which tests/campaigns/spec/
# schema_test.py holds to the loader).
with open(os.path.join(SRC, "campaigns", "spec", "campaign.schema.json")) as f:
    module_schema = json.load(f)["$defs"]["module"]["properties"]
for g in groups:
    for key, row in tables.get(g, {}).items():
        prop = module_schema.get(g, {}).get("properties", {}).get(key)
        m = re.search(r"([\[(])([^,\]]+), ([^\]]+)\]", row.get("allowed", ""))
        if prop is None or m is None:
            check("%s/%s range documented and in the schema" % (g, key), False, row.get("allowed", ""))
            continue
        exclusive = m.group(1) == "("
        low = prop.get("exclusiveMinimum" if exclusive else "minimum")
        ok = (low is not None and abs(number(m.group(2)) - low) <= 1e-12 * max(1, abs(low)) and
              abs(number(m.group(3)) - prop["maximum"]) <= 1e-12 * max(1, abs(prop["maximum"])) and
              ("whole number" in row["allowed"]) == (prop.get("type") == "integer"))
        check("%s/%s range as in the schema" % (g, key), ok, "doc %s, schema %s" % (row["allowed"], prop))

# The allowed ranges of the top-level and link values, as the schema states them: the first
# "[a, b]" or "(a, b]" of the row (of each number for a 3-number key) against the schema's
# minimum and maximum (of its items for an array). Rows without a range are skipped.
defs = json.load(open(os.path.join(SRC, "campaigns", "spec", "campaign.schema.json")))["$defs"]
for section, schema_props in (("Top level", defs["robotObject"]["properties"]), ("Link", defs["link"]["properties"])):
    for key, row in tables.get(section, {}).items():
        m = re.search(r"([\[(])([^,\]]+), ([^\]]+)\]", row.get("allowed", ""))
        if m is None:
            continue
        prop = schema_props.get(key, {})
        if prop.get("type") == "array":
            prop = prop.get("items", {})
        exclusive = m.group(1) == "("
        low = prop.get("exclusiveMinimum" if exclusive else "minimum")
        high = prop.get("maximum")
        ok = (low is not None and high is not None and abs(number(m.group(2)) - low) <= 1e-12 * max(1, abs(low)) and
              abs(number(m.group(3)) - high) <= 1e-12 * max(1, abs(high)))
        check("%s %s range as in the schema" % (section.lower(), key), ok, "doc %s, schema %s" % (row["allowed"], prop))

# The preset's own values: top level and links.
for key, row in tables.get("Top level", {}).items():
    if key in ("modules", "links"):
        continue
    column = row.get("`mrr-config1`", "")
    check("top level %s in mrr-config1" % key, same(column, robot[key]), "doc %s, code %s" % (column, robot[key]))
for key, row in tables.get("Link", {}).items():
    column = row.get("`mrr-config1` links 1 / 2 / 3", "")
    parts = [p.strip() for p in column.split(" / ")]
    if key not in robot["links"][0]:
        continue
    check("link %s in mrr-config1" % key,
          len(parts) == 3 and all(same(p, l[key]) for p, l in zip(parts, robot["links"])),
          "doc %s, code %s" % (column, [l[key] for l in robot["links"]]))

print("%d passed, %d failed" % (passed, failed))
sys.exit(1 if failed else 0)
