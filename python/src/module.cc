// armfault._armfault: the compiled half of the Python package (python/armfault/__init__.py is
// the other, and the API users read). Campaigns are loaded by the same code as `armfault run`,
// every run goes through RunCase and the output files through the same writers, so results are
// the CLI's byte for byte. docs/monitor-api.md, "Python".
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <thread>

#include "app/cli.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "core/base/suggest.h"
#include "faults/fault.h"
#include "python/src/python_monitor.h"

namespace armfault::python {

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace pybind11::literals;

namespace {

// armfault.InputError (a ValueError): created once at import, never freed (it lives as long as
// the interpreter, like the module).
PyObject* g_input_error = nullptr;

void SetInputError(const InputError& e) {
  std::string text;
  for (const std::string& line : ErrorReportLines(e)) text += (text.empty() ? "" : "\n") + line;
  py::object error = py::reinterpret_borrow<py::object>(g_input_error)(text);
  error.attr("file") = e.source();
  error.attr("pointer") = e.pointer();
  error.attr("message") = e.message();
  error.attr("hint") = e.hint();
  py::list all;
  for (const InputError& one : e.errors()) {
    all.append(py::dict("file"_a = one.source(), "pointer"_a = one.pointer(), "message"_a = one.message(),
                        "hint"_a = one.hint()));
  }
  error.attr("errors") = all;
  PyErr_SetObject(g_input_error, error.ptr());
}

py::object FromJson(const nlohmann::json& value) {
  return py::module_::import("json").attr("loads")(value.dump());
}

// A campaign as Python holds it: immutable (with_monitor() makes a changed copy).
struct PyCampaign {
  std::shared_ptr<const Campaign> campaign;
};

// A campaign file, or the campaign.json of an output directory (the resolved campaign wrapped
// with the version and shard), as `armfault trace --run` takes either.
PyCampaign LoadFile(const std::string& path) {
  const nlohmann::json input = ReadJsonFile(path);
  const bool output_dir_file = input.is_object() && input.contains("armfault_version") && input.contains("campaign");
  const std::string base = fs::path(path).parent_path().string();
  return {std::make_shared<const Campaign>(
      CampaignFromJson(output_dir_file ? input["campaign"] : input, path, base.empty() ? "." : base))};
}

PyCampaign LoadText(const std::string& text, const std::string& source, const std::string& base_dir) {
  return {std::make_shared<const Campaign>(CampaignFromJson(ParseJsonText(text, source), source, base_dir))};
}

// The campaign with a Python monitor in place of its own: every run makes one with
// factory(robot); the resolved campaign (campaign.json, summary.json and the campaign hash)
// names it: {"type": "python", "class": "module:Class", "settings": {}} given `class_path` (a
// Monitor subclass importable by that path, which any command can then rebuild), else
// {"type": "python", "factory": "module.Class"} (a record of what ran).
PyCampaign WithMonitor(const PyCampaign& pc, py::object factory, const std::string& name, const std::string& class_path) {
  if (!PyCallable_Check(factory.ptr())) {
    throw py::type_error("monitor must be a class or a factory callable as monitor(robot), got a " +
                         py::str(py::type::handle_of(factory).attr("__name__")).cast<std::string>());
  }
  auto copy = std::make_shared<Campaign>(*pc.campaign);
  copy->monitor_model = std::make_shared<PythonMonitorModel>(factory, name, RobotToJson(copy->robot).dump(),
                                                             static_cast<int>(copy->robot.modules.size()));
  copy->monitor.type = "python";
  copy->monitor.settings = class_path.empty() ? nlohmann::json{{"factory", name}}
                                              : nlohmann::json{{"class", class_path}, {"settings", nlohmann::json::object()}};
  copy->resolved["monitor"] = copy->monitor.ToJson();
  return {copy};
}

// The case `run` names: a case number (int, or a string of digits as `trace --run` takes) or a
// run_id; an unknown id names the nearest one.
const CaseSpec& FindCase(const Campaign& campaign, const std::vector<CaseSpec>& cases, py::handle run) {
  std::string id;
  if (py::isinstance<py::int_>(run) && !py::isinstance<py::bool_>(run)) {
    const long long k = run.cast<long long>();
    if (k < 0 || k >= static_cast<long long>(cases.size())) {
      throw InputError(campaign.source, "", "case " + std::to_string(k) + " does not exist: the campaign's cases are 0.." +
                                                std::to_string(static_cast<long long>(cases.size()) - 1));
    }
    return cases[static_cast<size_t>(k)];
  }
  if (!py::isinstance<py::str>(run)) throw py::type_error("run must be a run_id (str) or a case number (int)");
  id = run.cast<std::string>();
  if (!id.empty() && std::all_of(id.begin(), id.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return FindCase(campaign, cases, py::int_(std::stoll(id.substr(0, 18))));
  }
  for (const CaseSpec& c : cases) {
    if (c.run_id == id) return c;
  }
  // The nearest: among the ids sharing the longest prefix with it, the one with fewest edits.
  size_t best_prefix = 0, best_distance = 0;
  const std::string* best = nullptr;
  for (const CaseSpec& c : cases) {
    const size_t prefix =
        static_cast<size_t>(std::mismatch(id.begin(), id.end(), c.run_id.begin(), c.run_id.end()).first - id.begin());
    if (prefix < best_prefix) continue;
    const size_t d = EditDistance(id, c.run_id);
    if (!best || prefix > best_prefix || d < best_distance) best = &c.run_id, best_prefix = prefix, best_distance = d;
  }
  throw InputError(campaign.source, "", "no run \"" + id + "\" in campaign " + campaign.name +
                                            (best ? "; did you mean \"" + *best + "\"?" : std::string()) +
                                            " (or give a case number 0.." + std::to_string(cases.size() - 1) + ")");
}

// Every case of the campaign through RunCase, `threads` at a time (0: all cores), each record as
// its results.jsonl line, in case order whatever the threads. The GIL is released throughout;
// this thread only waits, and every 0.2 s takes the GIL to call `progress(done, total)` and to
// let Ctrl-C through (then the runs in flight finish, no other starts, KeyboardInterrupt).
// Returns (results lines, decisions lines), both in case order.
std::pair<std::vector<std::string>, std::vector<std::string>> RunCases(const PyCampaign& pc, int threads,
                                                                       py::object progress) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores), got " + std::to_string(threads));
  const Campaign& campaign = *pc.campaign;
  const std::vector<CaseSpec> cases = ExpandCases(campaign);
  const size_t n = cases.size();
  std::vector<std::string> lines(n), decision_lines(n);
  std::atomic<long> done{0};
  std::atomic<bool> stop{false};
  std::exception_ptr worker_error;
  std::optional<py::error_already_set> python_error;
  {
    py::gil_scoped_release release;
    std::mutex mutex;
    std::condition_variable finished_cv;
    bool finished = false;
    std::thread worker([&] {
      try {
        UnitMonitors units(campaign);
        tbb::task_arena arena(threads > 0 ? threads : tbb::this_task_arena::max_concurrency());
        arena.execute([&] {
          tbb::parallel_for(size_t{0}, n, [&](size_t k) {
            if (stop.load()) return;
            const RunRecord r = RunCase(campaign, cases[k], nullptr, &units);
            lines[k] = ToJson(r).dump();
            decision_lines[k] = DecisionLineJson(r).dump();
            done.fetch_add(1);
          });
        });
      } catch (...) {
        worker_error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex);
      finished = true;
      finished_cv.notify_all();
    });
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex);
        if (finished_cv.wait_for(lock, std::chrono::milliseconds(200), [&] { return finished; })) break;
      }
      py::gil_scoped_acquire gil;
      if (python_error) continue;
      try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (!progress.is_none()) progress(done.load(), n);
      } catch (py::error_already_set& e) {
        python_error.emplace(std::move(e));
        stop.store(true);
      }
    }
    worker.join();
  }
  if (python_error) throw *python_error;
  if (worker_error) std::rethrow_exception(worker_error);
  if (!progress.is_none()) progress(n, n);
  return {std::move(lines), std::move(decision_lines)};
}

// What `armfault run` writes: campaign.json, results.jsonl and decisions.jsonl from the runs'
// lines, then the outputs of results.jsonl from the run directory's table
// (campaigns/running/run_dir.h, WriteRecordOutputs), as every command writes them.
void WriteOutputs(const std::string& dir_name, const PyCampaign& pc, const std::vector<std::string>& lines,
                  const std::vector<std::string>& decision_lines) {
  const Campaign& campaign = *pc.campaign;
  py::gil_scoped_release release;
  const fs::path dir(dir_name);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir_name, "", "cannot create the output directory: " + ec.message());
  fs::remove(dir / run_dir::kEarlyStop, ec);  // of an earlier `run --early-stop` here: not this run's
  WriteAtomically(dir / run_dir::kCampaign, CampaignFileJson(campaign, ShardSpec{}).dump(2) + "\n");
  std::string jsonl;
  for (const std::string& line : lines) jsonl += line + "\n";
  WriteAtomically(dir / run_dir::kResults, jsonl);
  std::string decisions;  // what `armfault tune` reads
  for (const std::string& line : decision_lines) decisions += line + "\n";
  WriteAtomically(dir / run_dir::kDecisions, decisions);
  WriteRecordOutputs(dir, campaign, false);
}

// summary.json's content from records (results.jsonl lines); without a campaign no floors and
// a null campaign and hash.
std::string SummaryOf(const std::vector<std::string>& lines, std::optional<PyCampaign> pc) {
  SummaryBuilder builder(pc ? pc->campaign->include_not_excited : false);
  long n = 0;
  for (const std::string& line : lines) {
    ++n;
    try {
      builder.Add(RunRecordFromJson(nlohmann::json::parse(line)));
    } catch (const std::exception& e) {
      throw InputError("records", "/" + std::to_string(n - 1), std::string("not a run record: ") + e.what());
    }
  }
  nlohmann::json summary = pc ? builder.Build(pc->campaign->floors, pc->campaign->resolved, ARMFAULT_VERSION)
                              : builder.Build(Floors{}, nullptr, ARMFAULT_VERSION);
  // as `run` writes it (campaigns/running/run_dir.cc): the hours need the campaign's duration
  if (pc) {
    summary["healthy_operation"] =
        HealthyOperationOf(builder, pc->campaign->duration_s, StatedFalseAlarmsPerHour(*pc->campaign)).ToJson();
  }
  return summary.dump();
}

// One case as the campaign runs it, with what its monitor saw at every tick: (t_s [N],
// signals [field, N, joint], the record's line, the nominal robot's JSON).
py::tuple SimulateCase(const PyCampaign& pc, py::object run) {
  const Campaign& campaign = *pc.campaign;
  const std::vector<CaseSpec> cases = ExpandCases(campaign);
  const CaseSpec& spec = FindCase(campaign, cases, run);
  const size_t joints = campaign.robot.modules.size();
  const size_t fields = kSignalFields.size();
  std::vector<double> t_s;
  std::vector<double> rows;  // [tick][field][joint]
  std::string line;
  {
    py::gil_scoped_release release;
    const RunRecord record = RunCase(campaign, spec, [&](const Tick& tick) {
      t_s.push_back(tick.t_s);
      const size_t at = rows.size();
      rows.resize(at + fields * joints);
      for (size_t j = 0; j < joints && j < tick.joints->size(); ++j) {
        const JointSignals& s = (*tick.joints)[j].signals;
        const double values[] = {s.q_ref_rad,    s.qd_ref_rad_s, s.q_meas_rad,      s.qd_est_rad_s, s.tau_sensor_Nm,
                                 s.i_cmd_A,      s.i_supply_meas_A, s.v_bus_meas_V, s.winding_temp_C};
        for (size_t f = 0; f < fields; ++f) rows[at + f * joints + j] = values[f];
      }
    });
    line = ToJson(record).dump();
  }
  const size_t n = t_s.size();
  py::array_t<double> times(static_cast<py::ssize_t>(n));
  std::copy(t_s.begin(), t_s.end(), times.mutable_data());
  py::array_t<double> signals({static_cast<py::ssize_t>(fields), static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(joints)});
  double* out = signals.mutable_data();
  for (size_t k = 0; k < n; ++k) {
    for (size_t f = 0; f < fields; ++f) {
      for (size_t j = 0; j < joints; ++j) out[(f * n + k) * joints + j] = rows[(k * fields + f) * joints + j];
    }
  }
  return py::make_tuple(times, signals, line, RobotToJson(campaign.robot).dump());
}

// A monitor (made already) over recorded signals: rows [tick][field][joint], then finish() at
// the last tick. Returns its verdicts, times filled in; a Python exception is raised as is.
std::vector<PyVerdict> ReplayTrace(py::object instance, const std::string& name, const std::string& robot_json, int joints,
                              py::array_t<double, py::array::c_style | py::array::forcecast> t_s,
                              py::array_t<double, py::array::c_style | py::array::forcecast> rows) {
  const size_t fields = kSignalFields.size();
  if (t_s.ndim() != 1 || rows.ndim() != 3 || rows.shape(0) != t_s.shape(0) ||
      rows.shape(1) != static_cast<py::ssize_t>(fields) || rows.shape(2) != joints) {
    throw py::value_error("replay: expected t_s [N] and signals [N, " + std::to_string(fields) + ", " +
                          std::to_string(joints) + "]");
  }
  PythonMonitorModel model(py::none(), name, robot_json, joints);
  const size_t n = static_cast<size_t>(t_s.shape(0));
  const double* times = t_s.data();
  const double* data = rows.data();
  std::vector<PyVerdict> out;
  PyObject* error = nullptr;
  std::string failure;
  {
    py::gil_scoped_release release;
    try {
      PythonMonitor monitor(model, instance.ptr());
      try {
        for (size_t k = 0; k < n; ++k) monitor.ObserveRows(times[k], data + k * fields * static_cast<size_t>(joints));
        monitor.Finish(n ? times[n - 1] : 0.0);
      } catch (const MonitorFailure& e) {
        failure = e.what();
        error = monitor.TakeError();
      }
      for (const Verdict& v : monitor.output().verdicts) out.push_back({v, true});
    } catch (const MonitorFailure& e) {
      failure = e.what();
    }
  }
  if (error) {
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error)), error);
    Py_DECREF(error);
    throw py::error_already_set();
  }
  if (!failure.empty()) throw py::type_error(failure);
  return out;
}

// `python3 -m armfault ARGS`: the armfault command line (app/cli.h) in this process, where the
// package has installed its builder of Python monitors, so a campaign naming one by class runs
// as with any other monitor. The GIL is released throughout: each Python monitor takes it for
// its calls (python_monitor.h), from whichever thread runs it.
int CliMainFromPython(const std::vector<std::string>& args) {
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  py::gil_scoped_release release;
  std::fflush(stdout);
  const int status = CliMain(static_cast<int>(copy.size()), argv.data());
  std::fflush(stdout);
  std::fflush(stderr);
  return status;
}

py::dict VerdictDict(const PyVerdict& pv) {
  const Verdict& v = pv.verdict;
  return py::dict("t_s"_a = pv.has_time ? py::object(py::float_(v.t_s)) : py::object(py::none()), "joint"_a = v.joint,
                  "state"_a = HealthStateName(v.state), "alarm"_a = v.alarm, "family"_a = v.family,
                  "magnitude_name"_a = v.magnitude_name, "magnitude"_a = v.magnitude, "confidence"_a = v.confidence);
}

}  // namespace

}  // namespace armfault::python

PYBIND11_MODULE(_armfault, m) {
  using namespace armfault;
  using namespace armfault::python;
  namespace py = pybind11;
  using namespace pybind11::literals;
  m.doc() = "The compiled half of the armfault package; use `import armfault`.";
  m.attr("__version__") = ARMFAULT_VERSION;

  g_input_error = PyErr_NewExceptionWithDoc(
      "armfault.InputError",
      "Invalid input (a campaign file or dict, a run id): str(e) names the file, the JSON pointer and the\n"
      "value, one line per error. Attributes of the first error: file, pointer, message, hint; every\n"
      "error: errors (a list of dicts with those keys).",
      PyExc_ValueError, nullptr);
  m.attr("InputError") = py::handle(g_input_error);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      SetInputError(e);
    } catch (const MonitorFailure& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });

  py::list fields;
  for (const char* f : kSignalFields) fields.append(f);
  m.attr("SIGNAL_FIELDS") = py::tuple(fields);
  m.attr("FAULT_FAMILIES") = py::tuple(py::cast(FaultFamilyNames()));
  m.def("magnitude_key", &FaultMagnitudeKey, "family"_a,
        "The parameter that sizes a fault of `family` (\"kt_factor\", ...); \"\" if none.");

  py::class_<PyCampaign>(m, "Campaign",
                         "A campaign, parsed and checked as `armfault run` does (armfault.load_campaign makes one).\n"
                         "len(campaign) is its number of runs.")
      .def_property_readonly("name", [](const PyCampaign& c) { return c.campaign->name; })
      .def_property_readonly("source", [](const PyCampaign& c) { return c.campaign->source; },
                             "The file it came from (\"<dict>\" for a dict).")
      .def_property_readonly("seed", [](const PyCampaign& c) { return c.campaign->seed; })
      .def_property_readonly("duration_s", [](const PyCampaign& c) { return c.campaign->duration_s; })
      .def_property_readonly("joints", [](const PyCampaign& c) { return c.campaign->robot.modules.size(); })
      .def_property_readonly("robot", [](const PyCampaign& c) { return FromJson(RobotToJson(c.campaign->robot)); },
                             "The nominal robot (datasheet values) as JSON: what a monitor may know.")
      .def_property_readonly("resolved", [](const PyCampaign& c) { return FromJson(c.campaign->resolved); },
                             "The campaign with defaults filled in, as campaign.json holds it.")
      .def_property_readonly("monitor", [](const PyCampaign& c) {
        nlohmann::json spec = c.campaign->monitor.ToJson();
        if (!spec.contains("type")) spec["type"] = c.campaign->monitor.type;
        return FromJson(spec);
      }, "The monitor's type and settings.")
      .def_property_readonly("run_ids", [](const PyCampaign& c) {
        std::vector<std::string> ids;
        for (const CaseSpec& s : ExpandCases(*c.campaign)) ids.push_back(s.run_id);
        return ids;
      }, "Every run's id, in case order.")
      .def("cases", [](const PyCampaign& c) {
        py::list out;
        for (const CaseSpec& s : ExpandCases(*c.campaign)) {
          out.append(py::dict("case"_a = s.index, "run_id"_a = s.run_id,
                              "trajectory"_a = c.campaign->trajectories[s.trajectory].name, "group"_a = s.group,
                              "fault"_a = FromJson(s.fault), "seed"_a = s.seed, "repetition"_a = s.repetition,
                              "variation"_a = FromJson(s.VariationJson())));
        }
        return out;
      }, "Every run as a dict (case, run_id, trajectory, group, fault, seed, repetition, variation), in case order.")
      .def_property_readonly("warnings", [](const PyCampaign& c) { return CampaignWarnings(*c.campaign); },
                             "What `armfault validate` warns about, one line each.")
      .def("__len__", [](const PyCampaign& c) { return CaseCount(*c.campaign); })
      .def("__repr__", [](const PyCampaign& c) {
        return "<armfault.Campaign '" + c.campaign->name + "': " + std::to_string(CaseCount(*c.campaign)) + " runs of " +
               FormatNumber(c.campaign->duration_s) + " s, monitor " + c.campaign->monitor.type + ", from " +
               c.campaign->source + ">";
      });

  py::class_<PyVerdict>(m, "Verdict",
                        "One verdict about one joint (docs/monitor-api.md, \"The contract\").\n\n"
                        "Verdict(joint, state, family=None, magnitude_name=None, magnitude=0.0, confidence=1.0, *,\n"
                        "        t_s=None, alarm=None)\n\n"
                        "joint: 1-based. state: \"healthy\", \"worn\" or \"defective\", or a bool (True: \"worn\");\n"
                        "alarm is state != \"healthy\" unless given. family: a fault family (armfault.FAULT_FAMILIES)\n"
                        "or \"unknown\"; None: \"unknown\" for an alarm, \"\" when healthy. magnitude is the estimate of\n"
                        "the family's parameter magnitude_name (\"kt_factor\", ...). t_s: None takes the time of the\n"
                        "tick whose step() returned it (finish(): the end of the run). Nothing is checked here beyond\n"
                        "types: a verdict that breaks the contract fails its run with the reason.")
      .def(py::init(&MakePyVerdict), "joint"_a, "state"_a = py::none(), "family"_a = py::none(),
           "magnitude_name"_a = py::none(), "magnitude"_a = 0.0, "confidence"_a = 1.0, py::kw_only(),
           "t_s"_a = py::none(), "alarm"_a = py::none())
      .def_property_readonly("t_s", [](const PyVerdict& v) -> py::object {
        return v.has_time ? py::object(py::float_(v.verdict.t_s)) : py::object(py::none());
      })
      .def_property_readonly("joint", [](const PyVerdict& v) { return v.verdict.joint; })
      .def_property_readonly("state", [](const PyVerdict& v) { return std::string(HealthStateName(v.verdict.state)); })
      .def_property_readonly("alarm", [](const PyVerdict& v) { return v.verdict.alarm; })
      .def_property_readonly("family", [](const PyVerdict& v) { return v.verdict.family; })
      .def_property_readonly("magnitude_name", [](const PyVerdict& v) { return v.verdict.magnitude_name; })
      .def_property_readonly("magnitude", [](const PyVerdict& v) { return v.verdict.magnitude; })
      .def_property_readonly("confidence", [](const PyVerdict& v) { return v.verdict.confidence; })
      .def("to_dict", &VerdictDict)
      .def("__eq__", [](const PyVerdict& a, const PyVerdict& b) {
        return VerdictDict(a).equal(VerdictDict(b));
      })
      .def("__repr__", [](const PyVerdict& pv) {
        const Verdict& v = pv.verdict;
        std::string out = "Verdict(joint=" + std::to_string(v.joint) + ", state='" + HealthStateName(v.state) + "'";
        if (v.alarm != (v.state != HealthState::kHealthy)) out += std::string(", alarm=") + (v.alarm ? "True" : "False");
        if (!v.family.empty()) out += ", family='" + v.family + "'";
        if (!v.magnitude_name.empty()) out += ", magnitude_name='" + v.magnitude_name + "', magnitude=" + FormatNumber(v.magnitude);
        out += ", confidence=" + FormatNumber(v.confidence);
        if (pv.has_time) out += ", t_s=" + FormatNumber(v.t_s);
        return out + ")";
      });

  // Campaigns read from here on build a monitor named by Python class (SetMonitorHost).
  SetMonitorHost("python", &BuildPythonMonitor);
  m.def("cli_main", &CliMainFromPython, "argv"_a,
        "The armfault command line with argv (argv[0]: the program's name); returns its exit status.");
  m.def("load_campaign_file", &LoadFile, "path"_a);
  m.def("load_campaign_text", &LoadText, "text"_a, "source"_a, "base_dir"_a);
  m.def("with_monitor", &WithMonitor, "campaign"_a, "factory"_a, "name"_a, "class_path"_a);
  m.def("run_cases", &RunCases, "campaign"_a, "threads"_a, "progress"_a);
  m.def("write_outputs", &WriteOutputs, "output_dir"_a, "campaign"_a, "lines"_a, "decision_lines"_a);
  m.def("summary", &SummaryOf, "lines"_a, "campaign"_a);
  m.def("simulate", &SimulateCase, "campaign"_a, "run"_a);
  m.def("replay", &ReplayTrace, "instance"_a, "name"_a, "robot_json"_a, "joints"_a, "t_s"_a, "rows"_a);
}
