#!/usr/bin/python3
"""Stand-in recorded logs for `armfault import` (item 5), and the round trip's check.

No real robot's log can be fetched here, so the logs stand in for one honestly: they are made
from simulations (`armfault export` of tests/campaigns/data/import_standin.json, whose runs draw a
payload, torque-sensor noise and friction the importer is never told) and rewritten in a layout
armfault does not write: other column names (German, as a rig's logger might name them), the
time in milliseconds from an arbitrary origin on a 1 kHz clock with jitter, angles in degrees,
velocities in deg/s, torque in mN m, currents in mA, the bus voltage as raw counts (scale and
offset), a text column, the time not first, one gap per run (short enough to be accepted), and
the same runs once as one file per run and once as one long file split by a "Versuch" column.

  import_standin.py write EXPORT_DIR OUT_DIR     logs, two maps (files, shift) and truth.json
  import_standin.py check EXPORT_DIR OUT_DIR IMPORT_DIR LAYOUT
                                                 the imported signals against the simulated
                                                 ones, within the stated resampling bound;
                                                 the labels in the manifest; exit 1 if not
  import_standin.py bad OUT_DIR                  bad variants of the first log (error tests)

The stated bound (docs/import.md, "Resampling"): the log samples the simulated signal f, which
is taken as piecewise linear between its control ticks; linear interpolation between the two
samples a <= t_k <= b around a tick then errs by at most (b - a) / 4 times the sum of |changes
of f's slope| at f's knots inside (a, b), plus the text's rounding (10 significant digits in
the log: 5e-10 relative; the time's 0.1 us).
"""
import gzip
import json
import os
import sys

import numpy as np
import pandas as pd

PERIOD_MS = 1.0          # the logger's clock: 1 kHz
JITTER_MS = 0.25         # +- uniform on each sample time
GAP_AT_S = 1.2           # one gap per run, here
GAP_MS = 6.0             # with the jitter, 6 to 8.5 ms: under the default limit of 5 periods (10 ms)
BAD_GAP_MS = 15.0        # 7.5 periods: refused
ORIGIN_MS = 86_400_000.0 # the logger's clock starts at an arbitrary origin
VBUS_SCALE, VBUS_OFFSET = 0.02, 10.0  # raw counts = (V - offset) / scale

# JointSignals field -> (foreign column pattern, map entry, factor from SI to the log's unit)
FIELDS = {
    "q_meas_rad": ("Achse{J}_Pos_deg", {"unit": "deg"}, 180 / np.pi),
    "q_ref_rad": ("Achse{J}_Soll_deg", {"unit": "deg"}, 180 / np.pi),
    "qd_est_rad_s": ("Achse{J}_Vel_dps", {"unit": "deg/s"}, 180 / np.pi),
    "tau_sensor_Nm": ("Achse{J}_Moment_mNm", {"unit": "mN m"}, 1000.0),
    "i_cmd_A": ("Achse{J}_Icmd_mA", {"unit": "mA"}, 1000.0),
    "i_supply_meas_A": ("Achse{J}_Iin_mA", {"unit": "mA", "resample": "linear"}, 1000.0),
    "v_bus_meas_V": ("Achse{J}_Ubus_raw", {"scale": VBUS_SCALE, "offset": VBUS_OFFSET}, None),
}
UNMAPPED = ["qd_ref_rad_s", "winding_temp_C"]  # not logged: NaN after the import
JOINTS = 3
UNLABELLED = 2  # this case is left without a label: "unknown"


def manifest(export_dir):
    with open(os.path.join(export_dir, "manifest.jsonl")) as f:
        return [json.loads(line) for line in f]


def sample_times_ms(end_ms, rng, gap_ms):
    """1 kHz with jitter; first and last sample exactly at the run's ends; one gap."""
    n = int(round(end_ms / PERIOD_MS))
    t = np.arange(n + 1) * PERIOD_MS + rng.uniform(-JITTER_MS, JITTER_MS, n + 1)
    t[0], t[-1] = 0.0, end_ms
    gap_start = GAP_AT_S * 1000
    keep = (t <= gap_start) | (t >= gap_start + gap_ms)
    return t[keep]


def foreign_frame(truth, t_ms):
    """The log's columns at the sample times: the simulated signal, linear between its ticks."""
    tt = truth["t_s"].to_numpy() * 1000
    cols = {"Betriebsart": "AUTO", "Zeit_ms": ORIGIN_MS + t_ms}
    for j in range(1, JOINTS + 1):
        for field, (pattern, _, factor) in FIELDS.items():
            x = np.interp(t_ms, tt, truth[f"{field}_j{j}"].to_numpy())
            cols[pattern.format(J=j)] = (x - VBUS_OFFSET) / VBUS_SCALE if factor is None else x * factor
    return pd.DataFrame(cols)


def write_csv(frame, path):
    frame.to_csv(path, index=False, float_format="%.10g")
    # the time with 0.1 us resolution (float_format's 10 digits would cut it at ms offsets)
    text = open(path).read().splitlines()
    header = text[0].split(",")
    k = header.index("Zeit_ms")
    out = [text[0]]
    for line, t in zip(text[1:], frame["Zeit_ms"].to_numpy()):
        cells = line.split(",")
        cells[k] = f"{t:.4f}"
        out.append(",".join(cells))
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def the_map(robot, labels, run_column=None):
    joints = {}
    for j in range(1, JOINTS + 1):
        joints[str(j)] = {field: dict({"column": pattern.format(J=j)}, **entry)
                          for field, (pattern, entry, _) in FIELDS.items()}
    m = {"name": "standin", "robot": robot, "time": {"column": "Zeit_ms", "unit": "ms"}, "joints": joints,
         "labels": labels}
    if run_column:
        m["run_column"] = run_column
    return m


def label_of(run):
    if run["family"] is None:
        return "healthy"
    return {"family": run["family"], "joint": run["joint"], "onset_s": run["onset_s"], "magnitude": run["magnitude"]}


def write(export_dir, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    rng = np.random.default_rng(29)
    runs = manifest(export_dir)
    file_labels, shift_labels, truth = {}, {}, []
    shift = []
    clock_ms = 0.0
    for run in runs:
        sim = pd.read_csv(os.path.join(export_dir, run["signals"]))
        end_ms = sim["t_s"].iloc[-1] * 1000
        t_ms = sample_times_ms(end_ms, rng, GAP_MS)
        frame = foreign_frame(sim, t_ms)
        name = f"rig_{run['case']:02d}"
        write_csv(frame, os.path.join(out_dir, name + ".csv"))
        # the long file: one clock across runs, 0.5 s between them
        part = frame.copy()
        part["Zeit_ms"] = part["Zeit_ms"] + clock_ms
        part.insert(1, "Versuch", f"V{run['case']}")
        shift.append(part)
        clock_ms += end_ms + 500
        if run["case"] != UNLABELLED:
            file_labels[name] = label_of(run)
            shift_labels[f"shift/V{run['case']}"] = label_of(run)
        truth.append({"case": run["case"], "signals": run["signals"], "files_run_id": name,
                      "shift_run_id": f"shift/V{run['case']}",
                      "label": None if run["case"] == UNLABELLED else label_of(run)})
    write_csv(pd.concat(shift, ignore_index=True), os.path.join(out_dir, "shift.csv"))
    robot = json.load(open(os.path.join(export_dir, "campaign.json")))["campaign"]["robot"]["name"]
    json.dump(the_map(robot, file_labels), open(os.path.join(out_dir, "map_files.json"), "w"), indent=1)
    json.dump(the_map(robot, shift_labels, "Versuch"), open(os.path.join(out_dir, "map_shift.json"), "w"), indent=1)
    json.dump(truth, open(os.path.join(out_dir, "truth.json"), "w"), indent=1)


def bound(truth_t, truth_x, a, b):
    """(b - a) / 4 * sum |slope changes| of the piecewise-linear truth strictly inside (a, b)."""
    dt = truth_t[1] - truth_t[0]
    slope = np.diff(truth_x) / dt                     # slope on [t_m, t_m+1]
    change = np.zeros_like(truth_x)
    change[1:-1] = np.abs(np.diff(slope))             # at knot m (interior)
    csum = np.concatenate([[0], np.cumsum(change)])
    lo = np.searchsorted(truth_t, a, side="right")    # first knot > a
    hi = np.searchsorted(truth_t, b, side="left")     # first knot >= b
    return (b - a) / 4 * (csum[hi] - csum[lo])


def check(export_dir, out_dir, import_dir, layout):
    truth_runs = json.load(open(os.path.join(out_dir, "truth.json")))
    imported = {m["run_id"]: m for m in (json.loads(l) for l in open(os.path.join(import_dir, "manifest.jsonl")))}
    failures = []
    worst = {}
    for tr in truth_runs:
        rid = tr[f"{layout}_run_id"]
        if rid not in imported:
            failures.append(f"{rid}: not in the manifest")
            continue
        m = imported[rid]
        label = tr["label"]
        want = "unknown" if label is None else ("healthy" if label == "healthy" else "fault")
        if m["label"] != want:
            failures.append(f"{rid}: label {m['label']}, expected {want}")
        if isinstance(label, dict):
            for key in ("family", "joint", "onset_s", "magnitude"):
                if m[key] != label[key]:
                    failures.append(f"{rid}: {key} {m[key]!r}, expected {label[key]!r}")
        elif m["family"] is not None:
            failures.append(f"{rid}: a family {m['family']} on an unlabelled or healthy run")
        sim = pd.read_csv(os.path.join(export_dir, tr["signals"]))
        got = pd.read_csv(os.path.join(import_dir, m["signals"]))
        if list(got.columns) != list(sim.columns):
            failures.append(f"{rid}: columns differ from the export's")
            continue
        if len(got) != len(sim) or m["ticks"] != len(sim):
            failures.append(f"{rid}: {len(got)} ticks, expected {len(sim)}")
            continue
        if np.max(np.abs(got["t_s"].to_numpy() - sim["t_s"].to_numpy())) > 1e-12:
            failures.append(f"{rid}: t_s differs from the control clock")
        # the log's sample times, relative to the run's first sample, in s
        log = pd.read_csv(os.path.join(out_dir, ("rig_%02d.csv" % tr["case"]) if layout == "files" else "shift.csv"))
        if layout == "shift":
            log = log[log["Versuch"] == f"V{tr['case']}"]
        ts = (log["Zeit_ms"].to_numpy() - log["Zeit_ms"].iloc[0]) / 1000
        tk = sim["t_s"].to_numpy()
        idx = np.searchsorted(ts, tk, side="left")  # first sample >= tick
        b = ts[np.minimum(idx, len(ts) - 1)]
        a = np.where(ts[np.minimum(idx, len(ts) - 1)] == tk, tk, ts[np.maximum(idx - 1, 0)])
        b = np.where(b == tk, tk, b)
        for j in range(1, JOINTS + 1):
            for field in FIELDS:
                col = f"{field}_j{j}"
                x = sim[col].to_numpy()
                y = got[col].to_numpy()
                if np.isnan(x).any():  # no sensor (a torque sensor absent): NaN in, NaN out is not tested here
                    continue
                limit = np.array([bound(tk, x, a[i], b[i]) for i in range(len(tk))])
                # the time's rounding (0.1 us in the log): the steeper side's slope times 1e-7 s
                side = np.abs(np.diff(x)) / np.diff(tk)
                slope = np.maximum(np.concatenate([[0], side]), np.concatenate([side, [0]]))
                limit += 5e-10 * np.abs(x) + 1e-12 + slope * 1e-7 + 1e-9 * np.max(np.abs(x))
                err = np.abs(y - x)
                over = np.nonzero(err > limit)[0]
                if len(over):
                    i = over[0]
                    failures.append(f"{rid}: {col} at t={tk[i]:.3f} s: |{y[i]!r} - {x[i]!r}| = {err[i]:.3g} > bound "
                                    f"{limit[i]:.3g} ({len(over)} ticks over)")
                w = worst.setdefault(field, [0.0, 0.0])
                w[0] = max(w[0], float(np.max(err)))
                w[1] = max(w[1], float(np.max(limit)))
            for field in UNMAPPED:
                if not got[f"{field}_j{j}"].isna().all():
                    failures.append(f"{rid}: {field}_j{j} should be NaN (not in the log)")
    for field, (e, l) in sorted(worst.items()):
        print(f"{layout}: {field}: largest error {e:.3g}, largest bound {l:.3g}")
    if failures:
        print("\n".join(failures[:30]), file=sys.stderr)
        print(f"{len(failures)} failures", file=sys.stderr)
        sys.exit(1)
    print(f"{layout}: {len(truth_runs)} runs match the simulation within the stated bound; labels in the manifest")


def bad(out_dir):
    """Bad variants of rig_00.csv, each with one fault at a known line (1-based, header = 1)."""
    src = open(os.path.join(out_dir, "rig_00.csv")).read().splitlines()
    header = src[0].split(",")
    col = header.index("Achse3_Pos_deg")
    tcol = header.index("Zeit_ms")

    def with_cell(line_no, column, value):
        lines = list(src)
        cells = lines[line_no - 1].split(",")
        cells[column] = value
        lines[line_no - 1] = ",".join(cells)
        return lines

    variants = {
        "bad_nan.csv": with_cell(101, col, "NaN"),
        "bad_empty.csv": with_cell(102, col, ""),
        "bad_number.csv": with_cell(103, col, "SECRET4.2.1"),
    }
    # time going back at line 104
    lines = list(src)
    prev_t = float(lines[102].split(",")[tcol])
    variants["bad_nonmonotonic.csv"] = with_cell(104, tcol, f"{prev_t - 0.5:.4f}")
    # a column renamed
    lines = list(src)
    lines[0] = lines[0].replace("Achse3_Moment_mNm", "Achse3_Moment_Nm")
    variants["bad_column.csv"] = lines
    # a gap too long: drop the lines whose time is within 15 ms after 0.5 s
    t = np.array([float(l.split(",")[tcol]) for l in src[1:]])
    t0 = t[0]
    drop = set(np.nonzero((t - t0 > 500) & (t - t0 < 500 + BAD_GAP_MS))[0] + 2)
    variants["bad_gap.csv"] = [l for i, l in enumerate(src, start=1) if i not in drop]
    # the line (in the bad file) of the first sample after the gap: where the error is
    kept_times = [t[i - 2] for i in range(2, len(src) + 1) if i not in drop]
    first_after = 2 + next(k for k, x in enumerate(kept_times) if x - t0 >= 500 + BAD_GAP_MS)
    for name, lines in variants.items():
        with open(os.path.join(out_dir, name), "w") as f:
            f.write("\n".join(lines) + "\n")
    # the long file with a run that starts again after another
    shift = open(os.path.join(out_dir, "shift.csv")).read().splitlines()
    first_v0 = shift[1]
    with open(os.path.join(out_dir, "bad_shift.csv"), "w") as f:
        f.write("\n".join(shift + [first_v0]) + "\n")
    json.dump({"bad_gap.csv": first_after, "bad_shift.csv": len(shift) + 1}, open(os.path.join(out_dir, "bad_lines.json"), "w"))


if __name__ == "__main__":
    cmd = sys.argv[1]
    if cmd == "write":
        write(sys.argv[2], sys.argv[3])
    elif cmd == "check":
        check(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5])
    elif cmd == "bad":
        bad(sys.argv[2])
    else:
        sys.exit(f"unknown command {cmd}")
