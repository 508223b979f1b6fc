#!/usr/bin/python3
"""campaigns/spec/campaign.schema.json against the loader (`armfault validate`).

Usage: schema_test.py path/to/armfault SOURCE_DIR

1. The schema is valid JSON Schema 2020-12, and every shipped campaign (campaigns/files/*.json)
   validates against it.
2. A resolved campaign (`campaign.json` of a run: every robot and monitor key written out)
   validates, so the schema knows every key the loader knows.
3. Each bad file below is rejected by the loader (status 2) and, where a JSON Schema can say
   it, by the schema too. The rules a schema cannot express (orders, uniqueness, the robot's
   own joints and ranges, files) must be accepted by the schema and rejected by the loader,
   so the schema's $comment about them stays true.

Needs Debian's python3-jsonschema (tools/bootstrap.sh --tests). Prints one line per failed check and
"N passed, M failed"; exits non-zero on failure.
"""
import copy
import glob
import json
import os
import subprocess
import sys
import tempfile

try:
    import jsonschema
except ImportError:
    print("no jsonschema module for " + sys.executable + " (Debian: python3-jsonschema, see tools/bootstrap.sh --tests)")
    sys.exit(2)

if len(sys.argv) != 3:
    print("usage: schema_test.py path/to/armfault SOURCE_DIR", file=sys.stderr)
    sys.exit(2)
ARMFAULT = os.path.abspath(sys.argv[1])
SRC = os.path.abspath(sys.argv[2])

with open(os.path.join(SRC, "campaigns", "spec", "campaign.schema.json")) as f:
    SCHEMA = json.load(f)
jsonschema.Draft202012Validator.check_schema(SCHEMA)
VALIDATOR = jsonschema.Draft202012Validator(SCHEMA)

passed = 0
failed = 0


def check(name, ok, detail=""):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print("FAIL: %s%s" % (name, ": " + detail if detail else ""))


def schema_errors(document):
    return sorted(VALIDATOR.iter_errors(document), key=lambda e: list(e.absolute_path))


def loader(path):
    """(status, stderr) of `armfault validate path`."""
    r = subprocess.run([ARMFAULT, "validate", path], capture_output=True, text=True, timeout=120)
    return r.returncode, r.stderr


# ---------------------------------------------------------------- shipped campaigns
shipped = sorted(glob.glob(os.path.join(SRC, "campaigns", "files", "*.json")))
check("shipped campaigns found", len(shipped) >= 5, str(shipped))
for path in shipped:
    with open(path) as f:
        document = json.load(f)
    errors = schema_errors(document)
    check("schema accepts " + os.path.basename(path), not errors,
          "; ".join("/%s: %s" % ("/".join(map(str, e.absolute_path)), e.message[:200]) for e in errors[:3]))
    status, stderr = loader(path)
    check("loader accepts " + os.path.basename(path), status == 0, stderr[:300])

# A campaign for the bad cases below; valid as it is.
BASE = {
    "name": "schema-check",
    "seed": 3,
    "duration_s": 1,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [
        {"family": "kt_degradation", "joint": [2, 3], "kt_factor": [0.9, 0.6], "onset_s": 0.5},
        {"family": "friction_increase", "joint": 3, "friction_factor": {"from": 1.5, "to": 2.5, "steps": 3},
         "onset_s": {"uniform": [0.2, 0.8]}},
    ],
    "healthy": 1,
    "repetitions": 1,
    "variation": {"payload_kg": {"uniform": [0, 0.5]}, "friction_spread": 0.1},
    "floors": {"detection_rate": 0.5},
}

with tempfile.TemporaryDirectory(prefix="armfault_schema_test.") as tmp:
    # ---------------------------------------------------------------- a resolved campaign
    # Every key of the robot and the monitor, as the loader writes them back (campaign.json).
    tiny = copy.deepcopy(BASE)
    tiny.update({"duration_s": 0.05, "faults": [], "healthy": 1,
                 "robot": {"modules": [{"type": "MRR1", "winding_temperature_sensor": True}, {"ripple": {}}, {}],
                           "links": [{}, {}, {"inertia_kg_m2": [0.01, 0.02, 0.02]}]},
                 "variation": {"tolerances": "datasheet", "ambient_C": {"uniform": [15, 40]}, "units": 2}})
    tiny_path = os.path.join(tmp, "tiny.json")
    with open(tiny_path, "w") as f:
        json.dump(tiny, f)
    out = os.path.join(tmp, "tiny_out")
    r = subprocess.run([ARMFAULT, "run", tiny_path, "-o", out, "-q", "-j", "1"], capture_output=True, text=True, timeout=300)
    check("tiny campaign runs", r.returncode in (0, 1), r.stderr[:300])
    if os.path.exists(os.path.join(out, "campaign.json")):
        with open(os.path.join(out, "campaign.json")) as f:
            resolved = json.load(f)["campaign"]
        errors = schema_errors(resolved)
        check("schema accepts a resolved campaign (every robot and monitor key)", not errors,
              "; ".join("/%s: %s" % ("/".join(map(str, e.absolute_path)), e.message[:200]) for e in errors[:5]))
    else:
        check("tiny campaign wrote campaign.json", False)

    # ---------------------------------------------------------------- bad files
    def at(document, path):
        """The parent object or array of a JSON pointer given as a list, and the last token."""
        for token in path[:-1]:
            document = document[token]
        return document, path[-1]

    def put(path, value):
        def edit(d):
            parent, key = at(d, path)
            parent[key] = value
        return edit

    def drop(path):
        def edit(d):
            parent, key = at(d, path)
            del parent[key]
        return edit

    def fault(entry):
        """The campaign with one fault entry, `entry`."""
        return put(["faults"], [entry])

    def robot(value):
        return put(["robot"], value)

    def module(**keys):
        m = {}
        m.update(keys)
        return robot({"modules": [m, {}, {}], "links": [{}, {}, {}]})

    def link(**keys):
        return robot({"modules": [{}, {}, {}], "links": [keys, {}, {}]})

    def sine(**keys):
        t = {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}
        t.update(keys)
        return put(["trajectories", 0, "joints", "3"], t)

    kt = {"family": "kt_degradation", "joint": 3, "kt_factor": 0.5}

    def kt_with(**keys):
        e = dict(kt)
        e.update(keys)
        return fault(e)

    # Rejected by the loader and by the schema.
    COMPOUND = {"compound": [{"family": "friction_increase", "joint": 2, "friction_factor": 2, "onset_s": 0.5},
                             {"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 1}], "name": "f+d"}

    def compound(**changes):
        def edit(d):
            entry = copy.deepcopy(COMPOUND)
            for key, value in changes.items():
                if key == "element":
                    entry["compound"][1].update(value)
                elif value is None:
                    entry.pop(key)
                else:
                    entry[key] = value
            d["faults"].append(entry)
        return edit

    def accepted(what, edit, file_name):
        """Both the schema and the loader accept BASE after `edit`."""
        good = copy.deepcopy(BASE)
        edit(good)
        good_path = os.path.join(tmp, file_name)
        with open(good_path, "w") as f:
            json.dump(good, f)
        check("schema accepts " + what, not schema_errors(good), str(schema_errors(good)[:1]))
        status, stderr = loader(good_path)
        check("loader accepts " + what, status == 0, stderr[:300])

    accepted("a compound entry", compound(), "good-compound.json")
    accepted("commissioning on a trajectory", put(["commissioning"], {"trajectory": "exp1", "duration_s": 1}),
             "good-commissioning.json")

    both = [
        ("compound of one fault", compound(compound=[COMPOUND["compound"][0]])),
        ("compound with an unknown key", compound(joint=2)),
        ("compound name with a slash", compound(name="a/b")),
        ("compound element of an unknown family", compound(element={"family": "rust"})),
        ("unknown top-level key", put(["duraton_s"], 5)),
        ("negative seed", put(["seed"], -1)),
        ("fractional seed", put(["seed"], 1.5)),
        ("duration 0", put(["duration_s"], 0)),
        ("duration above an hour", put(["duration_s"], 4000)),
        ("no trajectories", drop(["trajectories"])),
        ("empty trajectories", put(["trajectories"], [])),
        ("empty trajectory name", put(["trajectories", 0, "name"], "")),
        ("slash in a trajectory name", put(["trajectories", 0, "name"], "a/b")),
        ("unknown trajectory key", put(["trajectories", 0, "speed"], 1)),
        ("trajectory without joints", drop(["trajectories", 0, "joints"])),
        ("joint 0", put(["trajectories", 0, "joints", "0"], {"type": "hold"})),
        ("joint written 03", put(["trajectories", 0, "joints", "03"], {"type": "hold"})),
        ("unknown trajectory type", put(["trajectories", 0, "joints", "3"], {"type": "spiral"})),
        ("sine_pair omega 0", sine(omega_rad_s=0)),
        ("sine_pair without omega", drop(["trajectories", 0, "joints", "3", "omega_rad_s"])),
        ("sine_pair unknown key", sine(omega=1)),
        ("cosine_ramp period 0", put(["trajectories", 0, "joints", "3"], {"type": "cosine_ramp", "amplitude_deg": 5, "period_s": 0})),
        ("min_jerk negative time", put(["trajectories", 0, "joints", "3"], {"type": "min_jerk", "waypoints": [[-1, 0], [1, 5]]})),
        ("min_jerk no waypoints", put(["trajectories", 0, "joints", "3"], {"type": "min_jerk", "waypoints": []})),
        ("min_jerk triple", put(["trajectories", 0, "joints", "3"], {"type": "min_jerk", "waypoints": [[0, 0, 0]]})),
        ("hold angle as text", put(["trajectories", 0, "joints", "3"], {"type": "hold", "angle_deg": "up"})),
        ("csv empty path", put(["trajectories", 0, "joints", "3"], {"type": "csv", "path": ""})),
        ("faults not an array", put(["faults"], {})),
        ("unknown fault family", kt_with(family="gremlins")),
        ("fault without family", fault({"joint": 3, "kt_factor": 0.5})),
        ("fault without joint", fault({"family": "kt_degradation", "kt_factor": 0.5})),
        ("fault joint 0", kt_with(joint=0)),
        ("fault joint list empty", kt_with(joint=[])),
        ("fault joint as a uniform", kt_with(joint={"uniform": [1, 3]})),
        ("fault joint as a grid", kt_with(joint={"from": 1, "to": 3, "steps": 3})),
        ("fault joint fractional", kt_with(joint=2.5)),
        ("kt_factor above 1", kt_with(kt_factor=1.5)),
        ("kt_factor 0", kt_with(kt_factor=0)),
        ("kt_factor in a list above 1", kt_with(kt_factor=[0.9, 1.5])),
        ("empty sweep", kt_with(kt_factor=[])),
        ("grid steps 0", kt_with(kt_factor={"from": 0.5, "to": 0.9, "steps": 0})),
        ("grid without steps", kt_with(kt_factor={"from": 0.5, "to": 0.9})),
        ("grid and uniform in one", kt_with(kt_factor={"from": 0.5, "to": 0.9, "steps": 2, "uniform": [0.5, 0.9]})),
        ("uniform of three", kt_with(kt_factor={"uniform": [0.5, 0.7, 0.9]})),
        ("uniform of text", kt_with(kt_factor={"uniform": [0.5, "high"]})),
        ("missing kt_factor", fault({"family": "kt_degradation", "joint": 3})),
        ("misspelt kt_factor", fault({"family": "kt_degradation", "joint": 3, "kt_factr": 0.5})),
        ("a key of another family", kt_with(friction_factor=2)),
        ("negative onset", kt_with(onset_s=-1)),
        ("negative onset in a uniform", kt_with(onset_s={"uniform": [-1, 1]})),
        ("unknown profile", kt_with(profile="sudden")),
        ("ramp_s without the incipient profile", kt_with(ramp_s=1)),
        ("ramp_s with the abrupt profile", kt_with(profile="abrupt", ramp_s=1)),
        ("duty with the incipient profile", kt_with(profile="incipient", duty=0.5)),
        ("ramp_s 0", kt_with(profile="incipient", ramp_s=0)),
        ("duty 0", kt_with(profile="intermittent", duty=0)),
        ("duty above 1", kt_with(profile="intermittent", duty=1.5)),
        ("period_s 0", kt_with(profile="intermittent", period_s=0)),
        ("friction_factor below 1", fault({"family": "friction_increase", "joint": 3, "friction_factor": 0.5})),
        ("friction_factor above 100", fault({"family": "friction_increase", "joint": 3, "friction_factor": 150})),
        ("unknown friction_terms", fault({"family": "friction_increase", "joint": 3, "friction_factor": 1.5,
                                          "friction_terms": "gear"})),
        ("friction_terms as a number", fault({"family": "friction_increase", "joint": 3, "friction_factor": 1.5,
                                              "friction_terms": 1})),
        ("drag_fraction 0", fault({"family": "brake_lock", "joint": 3, "drag_fraction": 0})),
        ("unknown lead", fault({"family": "torque_sensor_stuck", "joint": 3, "lead": "vcc"})),
        ("lead as a number", fault({"family": "torque_sensor_stuck", "joint": 3, "lead": 1})),
        ("unknown short kind", fault({"family": "inverter_short", "joint": 3, "kind": "arc"})),
        ("short resistance 0", fault({"family": "inverter_short", "joint": 3, "kind": "switch", "resistance_ohm": 0})),
        ("resistance_factor 25", fault({"family": "winding_resistance", "joint": 3, "resistance_factor": 25})),
        ("drift 0", fault({"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 0})),
        ("drift 200", fault({"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 200})),
        ("negative healthy", put(["healthy"], -1)),
        ("fractional healthy", put(["healthy"], 1.5)),
        ("repetitions 0", put(["repetitions"], 0)),
        ("unknown variation key", put(["variation", "friction_sprd"], 0.1)),
        ("payload above 100", put(["variation", "payload_kg"], 101)),
        ("payload uniform above 100", put(["variation", "payload_kg"], {"uniform": [0, 200]})),
        ("payload as a list", put(["variation", "payload_kg"], [0, 1])),
        ("payload as a grid", put(["variation", "payload_kg"], {"from": 0, "to": 1, "steps": 2})),
        ("negative torque noise", put(["variation", "torque_noise_Nm"], -1)),
        ("friction spread 0.95", put(["variation", "friction_spread"], 0.95)),
        ("unknown tolerance preset", put(["variation", "tolerances"], "catalog")),
        ("kt tolerance 0.6", put(["variation", "tolerances"], {"kt": 0.6})),
        ("negative tolerance", put(["variation", "tolerances"], {"bus_voltage": -0.1})),
        ("unknown tolerance key", put(["variation", "tolerances"], {"kt_spread": 0.1})),
        ("unknown preset in a tolerance object", put(["variation", "tolerances"], {"preset": "catalog"})),
        ("ambient 300", put(["variation", "ambient_C"], 300)),
        ("ambient uniform below -40", put(["variation", "ambient_C"], {"uniform": [-50, 20]})),
        ("units 0", put(["variation", "units"], 0)),
        ("fractional units", put(["variation", "units"], 1.5)),
        ("commissioning as text", put(["commissioning"], "yes")),
        ("commissioning with an unknown key", put(["commissioning"], {"trajectory": "exp1", "duraton_s": 1})),
        ("commissioning for 0 s", put(["commissioning"], {"duration_s": 0})),
        ("commissioning trajectory as a number", put(["commissioning"], {"trajectory": 1})),
        ("monitor as a number", put(["monitor"], 5)),
        ("plugin without a library", put(["monitor"], {"type": "plugin"})),
        ("plugin with an unknown key", put(["monitor"], {"type": "plugin", "library": "lib.so", "setting": {}})),
        ("plugin settings as a list", put(["monitor"], {"type": "plugin", "library": "lib.so", "settings": []})),
        ("verdicts with a short sha256", put(["monitor"], {"type": "verdicts", "file": "v.jsonl", "sha256": "abc"})),
        ("verdicts without a file", put(["monitor"], {"type": "verdicts", "sha256": "0" * 64})),
        ("unknown monitor key", put(["monitor"], {"debounce": 1})),
        ("negative debounce", put(["monitor"], {"debounce_s": -1})),
        ("mechanical_windows 0", put(["monitor"], {"mechanical_windows": 0})),
        ("kt_factor worn 2", put(["monitor"], {"kt_factor": {"worn": 2}})),
        ("friction_factor worn below 1", put(["monitor"], {"friction_factor": {"worn": 0.5}})),
        ("unknown limit key", put(["monitor"], {"kt_factor": {"wron": 0.9}})),
        ("detection floor 1.5", put(["floors", "detection_rate"], 1.5)),
        ("unknown floor", put(["floors", "detection_rte"], 0.5)),
        ("per-family floor of an unknown family", put(["floors", "per_family"], {"gremlins": {}})),
        ("per-family floor unknown key", put(["floors", "per_family"], {"kt_degradation": {"latency_s": 1}})),
        ("per-family within per-family", put(["floors", "per_family"], {"kt_degradation": {"per_family": {}}})),
        ("unknown robot preset", robot("mrr-config9")),
        ("robot as a number", robot(3)),
        ("robot without modules", robot({"links": [{}]})),
        ("robot with no modules", robot({"modules": [], "links": []})),
        ("unknown robot key", robot({"modules": [{}], "links": [{}], "gravity": 9.81})),
        ("unknown module type", module(type="MRR3")),
        ("unknown module key", module(motr={})),
        ("negative kt", module(motor={"kt_Nm_per_A": -1})),
        ("kt 0 (exclusive minimum)", module(motor={"kt_Nm_per_A": 0})),
        ("fractional pole pairs", module(motor={"pole_pairs": 2.5})),
        ("negative thermal resistance", module(motor={"thermal_resistance_K_per_W": -1})),
        ("thermal time constant 0", module(motor={"thermal_time_constant_s": 0})),
        ("supply-current gain error 0.6", module(inverter={"supply_current_gain_error": 0.6})),
        ("supply-current offset 20 A", module(inverter={"supply_current_offset_error_A": 20})),
        ("negative supply-current noise", module(inverter={"supply_current_noise_A": -0.1})),
        ("torque-sensor gain error -0.6", module(torque_sensor={"gain_error": -0.6})),
        ("torque-sensor offset error 2000", module(torque_sensor={"offset_error_Nm": 2000})),
        ("adc bits 30", module(torque_sensor={"adc_bits": 30})),
        ("gear ratio 0.5", module(drive={"ratio": 0.5})),
        ("mesh loss 0.95", module(drive={"mesh_loss_fraction": 0.95})),
        ("negative friction", module(friction={"coulomb_Nm": -1})),
        ("negative brake torque", module(brake={"holding_torque_Nm": -1})),
        ("encoder 2 counts", module(encoder={"counts_per_rev": 2})),
        ("controller rate 0", module(controller={"rate_Hz": 0})),
        ("velocity window 100", module(controller={"velocity_window": 100})),
        ("min angle above 360", module(min_angle_deg=400)),
        ("max angle above 360", module(max_angle_deg=400)),
        ("winding sensor as text", module(winding_temperature_sensor="yes")),
        ("ripple phase 400", module(ripple={"phase_2x_deg": 400})),
        ("ripple negative cogging", module(ripple={"cogging_Nm": -0.01})),
        ("ripple fractional period count", module(ripple={"cogging_periods_per_rev": 18.5})),
        ("ripple unknown key", module(ripple={"cogging": 0.01})),
        ("ripple not an object", module(ripple=True)),
        ("unknown group key", module(motor={"kt": 0.2})),
        ("link mass 0", link(mass_kg=0)),
        ("negative link length", link(length_m=-1)),
        ("com fraction 2", link(com_fraction=2)),
        ("direction of two numbers", link(direction=[1, 0])),
        ("inertia 0", link(inertia_kg_m2=[0, 1, 1])),
        # Physical limits (docs/assumptions.md): values that aborted the process inside ODE.
        ("link mass 5e-324", link(mass_kg=5e-324)),
        ("link mass 2000", link(mass_kg=2000)),
        ("link length 100", link(length_m=100)),
        ("link radius 1e-300", link(radius_m=1e-300)),
        ("joint axis 1.7e308", link(joint_axis=[1.7e308, 0, 0])),
        ("direction 1e200", link(direction=[0, 1e200, 0])),
        ("inertia 1e-300", link(inertia_kg_m2=[1e-300, 1e-300, 1e-300])),
        ("rotor inertia 1e-300", module(motor={"rotor_inertia_kg_m2": 1e-300})),
        ("gear ratio 1", module(drive={"ratio": 1})),
        ("base position 1e300", robot({"modules": [{}], "links": [{}], "base_position_m": [1e300, 0, 0]})),
        ("unknown link key", link(mass=2)),
        ("payload 500", robot({"modules": [{}], "links": [{}], "payload_kg": 500})),
        ("physics rate 50", robot({"modules": [{}], "links": [{}], "physics_rate_Hz": 50})),
        ("electrical substeps 0", robot({"modules": [{}], "links": [{}], "electrical_substeps": 0})),
        ("fractional substeps", robot({"modules": [{}], "links": [{}], "electrical_substeps": 2.5})),
        ("base position of two numbers", robot({"modules": [{}], "links": [{}], "base_position_m": [0, 0]})),
    ]
    # Rejected by the loader only: a JSON Schema cannot say these (see the schema's $comment).
    loader_only = [
        ("compound element with a list", compound(element={"drift_Nm_per_s": [1, 2]})),
        ("compound element with a list of onset conditions",
         compound(element={"onset": [{"when": "after_reversals", "joint": 3, "count": 1}]})),
        ("uniform low above high", kt_with(onset_s={"uniform": [2, 1]})),
        ("grid from above to", kt_with(kt_factor={"from": 0.9, "to": 0.5, "steps": 3})),
        ("grid of one step between two ends", kt_with(kt_factor={"from": 0.5, "to": 0.9, "steps": 1})),
        ("grid through a forbidden value", fault({"family": "torque_sensor_drift", "joint": 3,
                                                  "drift_Nm_per_s": {"from": -1, "to": 1, "steps": 3}})),
        ("ambient uniform low above high", put(["variation", "ambient_C"], {"uniform": [40, 15]})),
        ("duplicate trajectory names", put(["trajectories"], [BASE["trajectories"][0], BASE["trajectories"][0]])),
        ("commissioning on an unknown trajectory", put(["commissioning"], {"trajectory": "pick"})),
        ("commissioning longer than the campaign", put(["commissioning"], {"trajectory": "exp1", "duration_s": 2})),
        ("trajectory beyond the joint's range", sine(amplitude_deg=200)),
        ("trajectory on joint 7 of a 3-joint robot", put(["trajectories", 0, "joints", "7"], {"type": "hold"})),
        ("fault on joint 7 of a 3-joint robot", kt_with(joint=7)),
        ("waypoint times not increasing", put(["trajectories", 0, "joints", "3"],
                                              {"type": "min_jerk", "waypoints": [[0, 0], [2, 5], [1, 0]]})),
        ("missing csv file", put(["trajectories", 0, "joints", "3"], {"type": "csv", "path": "no-such.csv"})),
        ("missing monitor file", put(["monitor"], "no-such-monitor.json")),
        ("missing plugin library", put(["monitor"], {"type": "plugin", "library": "no-such-plugin.so"})),
        ("verdicts as the monitor of a campaign to run (only `armfault score` writes it)",
         put(["monitor"], {"type": "verdicts", "file": "v.jsonl", "sha256": "0" * 64})),
        ("defective above worn", put(["monitor"], {"kt_factor": {"worn": 0.9, "defective": 0.95}})),
        ("links do not match modules", robot({"modules": [{}, {}], "links": [{}]})),
        ("empty joint range", module(min_angle_deg=0, max_angle_deg=0)),
        ("controller rate not dividing the physics rate", module(controller={"rate_Hz": 300})),
        ("zero link direction", link(direction=[0, 0, 0])),
        ("principal moments breaking the triangle inequality", link(inertia_kg_m2=[1, 0.001, 0.001])),
        ("a ton with a micromotor's moments", link(mass_kg=1000, inertia_kg_m2=[1e-9, 1e-9, 1e-9])),
        ("a 1 g, 1 mm cylinder (moments below 1e-9 kg m^2)", link(mass_kg=0.001, radius_m=0.001, length_m=0)),
        ("no runs", lambda d: (d.pop("faults"), d.update({"healthy": 0}))),
    ]

    for group, cases, schema_rejects in (("both", both, True), ("loader only", loader_only, False)):
        for i, (name, edit) in enumerate(cases):
            document = copy.deepcopy(BASE)
            edit(document)
            path = os.path.join(tmp, "bad-%s-%03d.json" % (group.replace(" ", "-"), i))
            with open(path, "w") as f:
                json.dump(document, f)
            status, stderr = loader(path)
            check("loader rejects: " + name, status == 2 and stderr.startswith("armfault: error: "),
                  "status %d, stderr %s" % (status, stderr[:300]))
            errors = schema_errors(document)
            if schema_rejects:
                check("schema rejects: " + name, bool(errors))
            else:
                check("schema accepts (a loader-only rule): " + name, not errors,
                      "; ".join(e.message[:200] for e in errors[:3]))

print("%d passed, %d failed" % (passed, failed))
sys.exit(1 if failed else 0)
