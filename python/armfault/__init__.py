"""armfault from Python: fault-injection campaigns for robot-joint health monitors.

Load a campaign, run it with the built-in monitor or with a monitor written in Python, and look
at what a monitor sees::

    import armfault

    campaign = armfault.load_campaign("campaigns/files/ci.json")
    records = armfault.run_campaign(campaign, output_dir="out")   # what `armfault run` writes
    print(armfault.summary(records, campaign)["overall"]["detection"])

    class Mine(armfault.Monitor):
        def step(self, t_s, signals):            # every controller tick
            if signals.i_cmd_A[2] > 5:           # joint 3 (arrays are 0-based)
                return [armfault.Verdict(3, "worn", "kt_degradation")]

    records = armfault.run_campaign(campaign, monitor=Mine)  # scored like the built-in one

    trace = armfault.simulate(campaign, "exp1/healthy/0")   # t_s [N], signals [N, joints]
    verdicts = armfault.replay(Mine, trace)                  # a monitor over a recorded run

Runs go through the same code as the `armfault` command (RunCase), so the records are the CLI's
byte for byte. A campaign may also name its Python monitor by import path,
``"monitor": {"type": "python", "class": "package.module:Class", "settings": {...}}``: then
``armfault.run_campaign("campaign.json")`` builds it, and ``python3 -m armfault COMMAND ...`` runs
any command of the `armfault` binary (run, trace --run, tune, boundary, report ...) with it.
docs/monitor-api.md, "A monitor in Python", documents the package.
"""

import collections
import json
import math
import os
import sys
import warnings

import numpy as _np

from . import _armfault
from ._armfault import (FAULT_FAMILIES, SIGNAL_FIELDS, Campaign, InputError, Verdict, __version__,
                        magnitude_key)

__all__ = [
    "Campaign", "FAULT_FAMILIES", "InputError", "Monitor", "RunsFailed", "RunsFailedWarning", "SIGNAL_FIELDS",
    "Signals", "Statistic", "Trace",
    "Verdict", "load_campaign", "magnitude_key", "read_channels", "read_results_csv", "replay", "run_campaign",
    "simulate", "summary", "with_monitor", "__version__",
]


class Signals:
    """What a monitor reads at one controller tick: the signals of every joint.

    One attribute per field of SIGNAL_FIELDS (q_ref_rad, qd_ref_rad_s, q_meas_rad, qd_est_rad_s,
    tau_sensor_Nm, i_cmd_A, i_supply_meas_A, v_bus_meas_V, winding_temp_C), each a read-only
    float64 NumPy array of one value per joint: joint j is index j - 1. ``array`` holds them all,
    shape [fields, joints], in SIGNAL_FIELDS order.

    A run passes the same object at every tick and overwrites its arrays in place (that is what
    keeps a tick cheap): copy what you keep (``signals.i_cmd_A.copy()``, ``float(x[2])``).
    """

    __slots__ = SIGNAL_FIELDS + ("array",)

    def __init__(self, array):
        array.setflags(write=False)
        self.array = array
        for k, name in enumerate(SIGNAL_FIELDS):
            setattr(self, name, array[k])

    def __repr__(self):
        return "Signals(" + ", ".join(f"{n}={getattr(self, n).tolist()}" for n in SIGNAL_FIELDS) + ")"


Statistic = collections.namedtuple("Statistic", "name family threshold setting", defaults=("",))
Statistic.__doc__ = """A statistic behind a monitor's alarms, declared so that `armfault tune` can re-score other
thresholds (docs/monitor-api.md, "Statistics for tune"): its name, the fault family its alarm
names (or "unknown"), its threshold (> 0; the joint alarms while the value is above it) and,
optionally, the JSON pointer of that threshold in the monitor's settings."""


class Monitor:
    """Base class of a health monitor written in Python.

    Subclass it and override step() (and finish() if you need the end of the run); pass the class
    to run_campaign(campaign, monitor=MyMonitor), which makes one instance per run, as
    MyMonitor(robot). It is scored exactly as the built-in monitor is (docs/monitor-api.md).

    robot: the nominal robot as designed (the campaign's robot JSON, docs/robot-format.md):
    datasheet values only, never the unit's draw, the fault or its onset. A fresh dict per run.
    The base __init__ keeps it as self.robot and sets self.joints (the joint count) and
    self.dt_s (the controller period, s); call it from yours (super().__init__(robot)).

    Statistics for tune (optional): declare ``statistics = [armfault.Statistic(name, family,
    threshold)]`` on the class and write each joint's values into ``self.values[joint - 1, k]``
    (a float64 array the base __init__ makes, NaN: no value) in step(). The contract: at every
    tick a joint alarms exactly while some statistic is above its threshold, naming the family of
    the first such one (a latched alarm publishes the running maximum). `armfault tune` then
    sweeps the thresholds from the stored runs, and checks the contract on every run.

    Settings: a class named in a campaign by import path ({"type": "python", "class":
    "package.module:Class", "settings": {...}}) finds the campaign's settings as self.settings (a
    fresh dict per run), set before its __init__ runs so that __init__ may read them; made as
    MyMonitor(robot) it has {}. `armfault tune` writes a tuned threshold into them at its
    statistic's `setting` pointer.

    Commissioning (optional): where the campaign commissions its units, a monitor that defines
    ``commission_tick(t_s, signals)`` learns each unit before its runs. armfault makes a fresh
    instance for the unit, calls ``commission_begin()`` (if defined), ``commission_tick`` at every
    tick of the unit's healthy commissioning run (one tick at a time: keep only what you need),
    then ``commission_end(t_end_s)``, which returns what was learned: bytes, or a JSON value (a
    dict, a list, numbers...), or None for nothing. armfault keeps it once per unit and sets it as
    ``self.commissioning`` on every instance made for a run of that unit, before its first step
    (bytes as returned; a JSON value as a fresh object per run, so runs stay independent).
    ``self.commissioning`` is None where the unit was not commissioned.
    """

    statistics = ()

    def __init__(self, robot):
        # A class named in a campaign ("class": "package.module:Class") has its settings set
        # before __init__ runs (armfault._Configured); one made as Class(robot) has none.
        if "settings" not in self.__dict__:
            self.settings = {}
        self.robot = robot
        self.joints = len(robot["modules"])
        self.dt_s = 1.0 / robot["modules"][0]["controller"]["rate_Hz"]
        self.commissioning = None
        if self.statistics:
            self.values = _np.full((self.joints, len(self.statistics)), math.nan)

    def step(self, t_s, signals):
        """Called at every controller tick in time order, with the tick's time [s] and the
        Signals of every joint. Returns None, an armfault.Verdict, or a list of them (emit a
        verdict when your view of a joint changes); a verdict without t_s gets the tick's. An
        exception fails the run with its message; the campaign goes on."""
        return None

    def finish(self, t_end_s):
        """Called once after the last tick (t_end_s: its time). May return verdicts, like step."""
        return None


class _Configured:
    """factory(robot) of a Monitor subclass named in a campaign ({"type": "python", "class":
    "package.module:Class", "settings": {...}}): each call makes an instance with a fresh dict of
    the settings as self.settings before the class's __init__(robot) runs, so __init__ may read
    them. Attributes other than its own are the class's (commission_tick, statistics, ...)."""

    def __init__(self, cls, settings_json):
        self._cls, self._settings_json = cls, settings_json

    def __call__(self, robot):
        instance = self._cls.__new__(self._cls)
        instance.settings = json.loads(self._settings_json)
        instance.__init__(robot)
        return instance

    def __getattr__(self, name):
        return getattr(self._cls, name)


class Trace:
    """One run as its monitor saw it (armfault.simulate makes one).

    t_s: the tick times, float64 [N]. signals: a dict, field of SIGNAL_FIELDS -> float64 array
    [N, joints] (column j - 1 is joint j), units in the field names (rad, rad/s, N m, A, V, °C).
    record: the run's record, the dict results.jsonl holds for it (its fault, onset and
    magnitude are the truth; detected, latency_s ... the monitor's score). robot: the nominal
    robot dict a monitor gets. run_id and case: which run.
    """

    def __init__(self, t_s, signals, record, robot):
        self.t_s = t_s
        self.signals = signals
        self.record = record
        self.robot = robot

    @property
    def run_id(self):
        return self.record["run_id"]

    @property
    def case(self):
        return self.record["case"]

    @property
    def joints(self):
        return len(self.robot["modules"])

    def frame(self, joint):
        """The signals of one joint (1-based) as a pandas DataFrame: t_s and one column per field."""
        import pandas
        if not 1 <= joint <= self.joints:
            raise ValueError(f"joint {joint} out of range, expected 1..{self.joints}")
        columns = {"t_s": self.t_s}
        columns.update({name: self.signals[name][:, joint - 1] for name in SIGNAL_FIELDS})
        return pandas.DataFrame(columns)

    def __repr__(self):
        return (f"<armfault.Trace {self.run_id!r}: {len(self.t_s)} ticks x {self.joints} joints, "
                f"status {self.record['status']}, detected {self.record['detected']}>")


# ------------------------------------------------------------------------------ campaigns

def _plain(value, pointer):
    """value as plain JSON data (NumPy scalars and arrays, tuples and int keys converted);
    anything JSON cannot hold is an InputError naming its pointer."""
    if value is None or isinstance(value, (bool, str, int)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise _input_error("<dict>", pointer or "", f"expected a finite number, got {value}")
        return value
    if isinstance(value, dict):
        out = {}
        for key, item in value.items():
            if not isinstance(key, (str, int)) or isinstance(key, bool):
                raise _input_error("<dict>", pointer or "", f"keys must be str, got {key!r}")
            token = str(key)
            out[token] = _plain(item, pointer + "/" + token.replace("~", "~0").replace("/", "~1"))
        return out
    if isinstance(value, (list, tuple)):
        return [_plain(item, f"{pointer}/{k}") for k, item in enumerate(value)]
    if isinstance(value, (_np.generic, _np.ndarray)):
        return _plain(value.tolist(), pointer)
    raise _input_error("<dict>", pointer or "",
                       f"expected JSON data (dict, list, str, number, bool, None), got {type(value).__name__}")


def _input_error(file, pointer, message):
    error = InputError(f"{file}: {pointer}: {message}" if pointer else f"{file}: {message}")
    error.file, error.pointer, error.message, error.hint = file, pointer, message, ""
    error.errors = [{"file": file, "pointer": pointer, "message": message, "hint": ""}]
    return error


def load_campaign(source, base_dir=None):
    """A campaign from a file (str or path: a campaign file, or the campaign.json of an output
    directory) or from a dict shaped like a campaign file (docs/campaign-format.md), checked as
    `armfault validate` checks it. A Campaign is returned as it is.

    base_dir: where a dict's relative file names (a csv trajectory, a monitor file) resolve;
    default the current directory. Errors raise armfault.InputError, whose message names the
    file ("<dict>" for a dict), the JSON pointer and the value, one line per error.
    """
    if isinstance(source, Campaign):
        return source
    if isinstance(source, dict):
        text = json.dumps(_plain(source, ""))
        return _armfault.load_campaign_text(text, "<dict>", os.fspath(base_dir) if base_dir else os.getcwd())
    if isinstance(source, (str, os.PathLike)):
        return _armfault.load_campaign_file(os.fspath(source))
    raise TypeError(f"load_campaign takes a file name or a dict, got {type(source).__name__}")


def _factory_name(factory):
    module = getattr(factory, "__module__", None) or type(factory).__module__
    name = getattr(factory, "__qualname__", None) or type(factory).__qualname__
    return f"{module}.{name}"


def _class_path(monitor):
    """"package.module:Class" when `monitor` is a Monitor subclass that importing that path gives
    back (so any later command can rebuild it), else "" (a class defined in __main__, a notebook
    or a function, or any other factory)."""
    if not (isinstance(monitor, type) and issubclass(monitor, Monitor)):
        return ""
    module, qualname = getattr(monitor, "__module__", ""), getattr(monitor, "__qualname__", "")
    if not module or module == "__main__" or "<locals>" in qualname:
        return ""
    found = sys.modules.get(module)
    for part in qualname.split("."):
        found = getattr(found, part, None)
    return f"{module}:{qualname}" if found is monitor else ""


def with_monitor(campaign, monitor):
    """A copy of `campaign` whose runs use a Python monitor: `monitor` is a class (a Monitor
    subclass) or a factory, called as monitor(robot) once per run. The copy's resolved campaign
    (campaign.json, summary.json, the campaign hash) names it: a Monitor subclass that can be
    imported by name as {"type": "python", "class": "module:Class", "settings": {}}, which
    `python3 -m armfault trace --run`, `boundary` ... rebuild; any other (a class of __main__ or
    a notebook, a function) as {"type": "python", "factory": "module.Class"}, which they cannot."""
    campaign = load_campaign(campaign)
    if not isinstance(monitor, type) and callable(getattr(monitor, "step", None)):
        raise TypeError("pass the monitor's class (or a factory), not an instance: every run makes its own")
    return _armfault.with_monitor(campaign, monitor, _factory_name(monitor), _class_path(monitor))


class RunsFailed(RuntimeError):
    """Raised by run_campaign when runs failed (a simulation that diverged, a monitor that raised
    or emitted a bad verdict): str(e) names how many, and the first failed run (lowest case
    number) with its reason. Attributes: failed, runs (counts), run_id and reason (the first
    failure's), records (what run_campaign would have returned), output_dir (written first, or
    None)."""

    def __init__(self, message, failed, runs, run_id, reason, records, output_dir):
        super().__init__(message)
        self.failed, self.runs, self.run_id, self.reason = failed, runs, run_id, reason
        self.records, self.output_dir = records, output_dir


class RunsFailedWarning(UserWarning):
    """What run_campaign(..., on_failure="warn") warns with instead of raising RunsFailed."""


def _failure_message(records):
    """(message, first failed record) of records in case order, or (None, None) if none failed."""
    failed = [r for r in records if r.get("status") != "ok"]
    if not failed:
        return None, None
    first = failed[0]
    return (f"{len(failed)} of {len(records)} runs failed; first failed run {first.get('run_id')}: "
            f"{first.get('reason')}"), first


def _as_frame(records, as_frame):
    if as_frame is False:
        return records
    try:
        import pandas
    except ImportError:
        if as_frame:
            raise
        return records
    frame = pandas.DataFrame.from_records(records)
    if len(frame.columns):
        first = ["case", "run_id"]
        frame = frame[first + [c for c in frame.columns if c not in first]]
    return frame


def _progress_printer(done, total):
    print(f"\rarmfault: {done}/{total} runs", end="\n" if done == total else "", file=sys.stderr, flush=True)


def run_campaign(campaign, output_dir=None, threads=0, monitor=None, *, as_frame=None, progress=None,
                 on_failure="raise"):
    """Runs every case of `campaign` (a Campaign, a file name or a dict) and returns the run
    records, one per run in case order: a pandas DataFrame (one column per results.jsonl key)
    when pandas can be imported, else a list of dicts (as_frame=False: always the list; True:
    always a DataFrame).

    output_dir: also writes what `armfault run -o DIR` writes there: campaign.json,
    results.jsonl, results.csv, summary.json, junit.xml (byte-identical for the same campaign).
    threads: runs at a time (0: all cores); the records do not depend on it.
    monitor: None for the campaign's own monitor (the records are `armfault run`'s), or a
    Python monitor (a Monitor subclass or factory, see with_monitor), scored the same way.
    progress: a callable(done, total), called every 0.2 s and at the end, or True for a line on
    stderr. Ctrl-C stops after the runs in flight and raises KeyboardInterrupt.
    on_failure: what happens when runs failed (their records say "status": "failed" and why),
    after output_dir is written: "raise" (default) raises RunsFailed naming the first failed run
    and its reason (e.records holds the records); "warn" warns (RunsFailedWarning) with the same
    message and returns the records.
    """
    if on_failure not in ("raise", "warn"):
        raise ValueError(f'on_failure: expected "raise" or "warn", got {on_failure!r}')
    campaign = load_campaign(campaign)
    if monitor is not None:
        campaign = with_monitor(campaign, monitor)
    if progress is True:
        progress = _progress_printer
    try:
        lines, decision_lines = _armfault.run_cases(campaign, int(threads), progress)
    except KeyboardInterrupt:
        if progress is _progress_printer:
            print(file=sys.stderr)
        raise
    if output_dir is not None:
        _armfault.write_outputs(os.fspath(output_dir), campaign, lines, decision_lines)
    records = [json.loads(line) for line in lines]
    message, first = _failure_message(records)
    result = _as_frame(records, as_frame)
    if message is not None:
        if output_dir is not None:
            message += f" (every failed run: failed_runs in {os.path.join(os.fspath(output_dir), 'summary.json')})"
        if on_failure == "warn":
            warnings.warn(message, RunsFailedWarning, stacklevel=2)
        else:
            raise RunsFailed(message + '; the records: e.records, or run_campaign(..., on_failure="warn")',
                             sum(r.get("status") != "ok" for r in records), len(records), first.get("run_id"),
                             first.get("reason"), result, output_dir)
    return result


def _record_line(record):
    def plain(x):
        if isinstance(x, float) and math.isnan(x):
            return None  # pandas' missing value: JSON null
        if isinstance(x, dict):
            return {k: plain(v) for k, v in x.items()}
        if isinstance(x, list):
            return [plain(v) for v in x]
        if isinstance(x, (_np.generic, _np.ndarray)):
            return plain(x.tolist())
        return x
    return json.dumps(plain(dict(record)))


def summary(records, campaign=None):
    """summary.json's content (a dict) for run records as run_campaign returns them (DataFrame or
    list of dicts, any subset, in any order): rates with Wilson intervals, the confusion matrix,
    latency, magnitude errors (docs/campaign-format.md, "summary.json"). With the campaign (its
    Campaign, file or dict) also its floors ("floors", "floors_met"), its hash and the false
    alarms per hour of healthy operation ("healthy_operation")."""
    if hasattr(records, "to_dict") and hasattr(records, "columns"):
        records = records.to_dict("records")
    lines = [_record_line(r) for r in records]
    return json.loads(_armfault.summary(lines, None if campaign is None else load_campaign(campaign)))


# ------------------------------------------------------------------------------ CSV files

# Columns of results.csv and an export's manifest.csv that hold integers or booleans, with empty
# cells where results.jsonl has null (docs/campaign-format.md, "results.csv").
_CSV_INTEGERS = ("case", "joint", "seed", "repetition", "unit", "isolated_joint", "ticks")
_CSV_BOOLEANS = ("took_effect", "detected", "alarm_before_onset", "isolated", "excited")


def read_results_csv(path):
    """results.csv (or an export's manifest.csv) as a pandas DataFrame whose integer columns
    (joint, case, seed, ...) are pandas' nullable Int64 and boolean ones (detected, isolated,
    took_effect, ...) nullable boolean, where plain pandas.read_csv makes a column with an empty
    cell (a healthy run's joint) float or object. seed is UInt64 (a seed may exceed 2^63)."""
    import pandas
    header = pandas.read_csv(path, nrows=0).columns
    dtype = {c: "Int64" for c in _CSV_INTEGERS if c in header}
    if "seed" in dtype:
        dtype["seed"] = "UInt64"
    dtype.update({c: "boolean" for c in _CSV_BOOLEANS if c in header})
    return pandas.read_csv(path, dtype=dtype, keep_default_na=False,
                           na_values={c: [""] for c in header})


def _sidecar(csv_path):
    """The channels.json of a CSV of signals: beside a trace, "<stem>.channels.json"; for an
    export's runs/<case>.csv.gz, the export directory's channels.json."""
    path = os.fspath(csv_path)
    folder, name = os.path.split(path)
    own = os.path.join(folder, (name[:-4] if name.endswith(".csv") else name) + ".channels.json")
    if os.path.exists(own):
        return own
    return os.path.join(os.path.dirname(folder), "channels.json")


def read_channels(csv_path):
    """A CSV of signals armfault wrote (`armfault trace -o X.csv`, an export's runs/<case>.csv.gz)
    with its channels.json: returns (frame, channels), frame a pandas DataFrame of the CSV,
    channels the list of {"name", "quantity", "unit", "source", "joint", "description"} in column
    order (source "sensor", "truth" or "monitor"; docs/trace-format.md, "Column names and
    channels.json"). Raises ValueError when the sidecar does not describe the CSV's columns."""
    import pandas
    with open(_sidecar(csv_path)) as f:
        channels = json.load(f)["channels"]
    frame = pandas.read_csv(csv_path)
    names = [c["name"] for c in channels]
    if list(frame.columns) != names:
        raise ValueError(f"{csv_path}: its channels.json describes other columns "
                         f"({names[:3]}... against {list(frame.columns)[:3]}...)")
    return frame, channels


# ------------------------------------------------------------------------------ one run

def simulate(campaign, run, monitor=None):
    """Runs one case of `campaign` exactly as run_campaign runs it and returns a Trace: the tick
    times, the signals its monitor saw ([N, joints] per field) and its record (truth and score).

    run: its run_id (str) or case number (int). monitor: as in run_campaign (None: the
    campaign's own)."""
    campaign = load_campaign(campaign)
    if monitor is not None:
        campaign = with_monitor(campaign, monitor)
    t_s, rows, line, robot = _armfault.simulate(campaign, run)
    signals = {name: rows[k] for k, name in enumerate(SIGNAL_FIELDS)}
    return Trace(t_s, signals, json.loads(line), json.loads(robot))


def replay(monitor, trace):
    """Feeds a recorded Trace to a monitor, tick by tick, as a run does (same Signals object,
    same call path), then finish(); returns its verdicts, every t_s filled in. Nothing is
    simulated or scored: a quick loop to develop a monitor on, and how its per-tick cost is
    measured. monitor: a class or factory (called with trace.robot) or an instance (kept, so its
    state can be looked at afterwards). Its exceptions propagate as raised."""
    if isinstance(monitor, type) or not callable(getattr(monitor, "step", None)):
        monitor = monitor(json.loads(json.dumps(trace.robot)))
    rows = _np.ascontiguousarray(
        _np.stack([_np.asarray(trace.signals[name], dtype=_np.float64) for name in SIGNAL_FIELDS], axis=1))
    t_s = _np.ascontiguousarray(trace.t_s, dtype=_np.float64)
    return _armfault.replay(monitor, _factory_name(type(monitor)), json.dumps(trace.robot), trace.joints, t_s, rows)
