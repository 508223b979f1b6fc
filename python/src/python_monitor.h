// A health monitor written in Python (a subclass of armfault.Monitor, or any factory of objects
// with step()) as a MonitorModel and HealthMonitor, so that RunCase runs and scores it exactly as
// it does the built-in monitor: ScoreVerdicts on what it emitted, CheckOutput on the contract, a
// Python exception fails the run (MonitorFailure) and the campaign goes on.
//
// Threads and the GIL: runs go on in parallel (oneTBB) with the GIL released. A Python monitor
// keeps the signals of the ticks it is given (no GIL) and, every kBatchTicks ticks and at the
// end, takes the GIL once and calls step() for each of them in order, as if tick by tick: step
// sees the same values in the same order, and verdicts and failures carry their own tick's time.
// So the C++ simulation of one run goes on while another run's monitor runs Python, and the GIL
// changes hands once per batch, not once per tick. Each run makes its own thread state
// (PyGILState_Ensure) when its monitor is made and keeps it until the monitor is destroyed.
// docs/monitor-api.md, "A monitor in Python".
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "core/monitors/monitor.h"
#include "core/monitors/registry.h"
#include "core/monitors/threshold_statistics.h"

namespace armfault::python {

// The signals a Python monitor gets, in this order: the rows of Signals.array.
extern const std::vector<const char*> kSignalFields;

// Ticks whose step() calls go under one hold of the GIL (half a second at 500 Hz).
constexpr size_t kBatchTicks = 256;

// What a Python monitor's commission_end returned for one unit, owned by the framework (kept
// once per unit, shared read-only by its runs): bytes as they were, or anything else as its
// JSON text (json.dumps), which each run gets as a fresh json.loads.
struct PythonCommissioningBlob {
  bool is_bytes = false;
  std::string data;
};

// armfault.Verdict: a Verdict whose time may be left to the tick that emitted it.
struct PyVerdict {
  Verdict verdict;
  bool has_time = false;
};

// The Python side of a factory: a strong reference to `factory` (called as factory(robot) once
// per run), the nominal robot as JSON text (each run gets a fresh dict of it) and armfault's
// Signals class. Immutable, shared by every run and thread; each use takes the GIL.
class PythonMonitorModel : public MonitorModel, public std::enable_shared_from_this<PythonMonitorModel> {
 public:
  // Needs the GIL. `name` ("module.Class") is what messages and the resolved campaign call it.
  PythonMonitorModel(pybind11::handle factory, std::string name, std::string robot_json, int joints);
  ~PythonMonitorModel() override;
  PythonMonitorModel(const PythonMonitorModel&) = delete;
  PythonMonitorModel& operator=(const PythonMonitorModel&) = delete;

  std::string type() const override { return "python"; }
  std::string source() const override { return name_; }
  // Takes the GIL itself: callable from any thread, with or without it. A factory that raises
  // throws MonitorFailure (the run could not be set up, with the exception's message).
  std::unique_ptr<HealthMonitor> NewMonitor() const override;
  // A monitor whose instances have commission_tick (and commission_end) learns each unit: a
  // fresh instance (factory(robot)) gets commission_begin(), commission_tick(t_s, signals) at
  // every tick (batched under the GIL as step is), commission_end(t_end_s); what that returns
  // (bytes, or a JSON value; None: nothing learned) becomes the unit's model, whose runs' instances
  // get it as self.commissioning before their first step. nullptr without commission_tick.
  // Needs the model to be owned by a shared_ptr (the unit's model keeps it).
  std::unique_ptr<CommissioningSink> BeginCommissioning(double control_dt_s) const override;
  // The factory (a class) has commission_tick. Takes the GIL itself.
  bool LearnsFromCommissioning() const override;

  const std::string& name() const { return name_; }
  PyObject* factory() const { return factory_; }
  PyObject* signals_type() const { return signals_type_; }
  PyObject* json_loads() const { return json_loads_; }
  const std::string& robot_json() const { return robot_json_; }
  int joints() const { return joints_; }

 private:
  PyObject* factory_ = nullptr;
  PyObject* signals_type_ = nullptr;  // armfault.Signals
  PyObject* json_loads_ = nullptr;    // json.loads
  std::string name_;
  std::string robot_json_;
  int joints_ = 0;
};

// One run's Python monitor. Made, used and destroyed on one thread (RunCase's).
class PythonMonitor : public HealthMonitor {
 public:
  // Calls the model's factory with the robot, or, given `instance` (a monitor made already, as
  // replay() takes one), uses that. Takes the GIL itself; a factory that raises, or an object
  // without step(), throws MonitorFailure.
  // `commissioning`: the unit's blob, set as the instance's `commissioning` attribute (null: left
  // as the instance has it). `commissions`: the instance is made to be commissioned (its
  // commission_tick and commission_end in place of step and finish; commission_begin called).
  explicit PythonMonitor(const PythonMonitorModel& model, PyObject* instance = nullptr,
                         const PythonCommissioningBlob* commissioning = nullptr, bool commissions = false);
  ~PythonMonitor() override;
  PythonMonitor(const PythonMonitor&) = delete;
  PythonMonitor& operator=(const PythonMonitor&) = delete;

  // Keeps the tick; every kBatchTicks ticks calls step() for each kept one (a failure in one
  // throws MonitorFailure naming its tick's time, and the later ticks are not called).
  void Observe(double t_s, const std::vector<JointSignals>& joints) override;
  // The same with the signals already laid out as Signals.array ([field][joint], the fields in
  // kSignalFields order): what replay() feeds from a recorded trace.
  void ObserveRows(double t_s, const double* rows);
  // step() for the ticks still kept, then finish().
  void Finish(double t_end_s) override;
  const MonitorOutput& output() const override { return output_; }
  // A monitor that declares `statistics` gets a tap recording self.values after every step().
  std::unique_ptr<DecisionTap> NewDecisionTap(double onset_s) const override;

  // The Python exception that failed the monitor (a new reference, or nullptr); needs the GIL.
  PyObject* TakeError();

  // Made with `commissions`: whether the instance has commission_tick (else it learns nothing).
  bool commissions() const { return step_ != nullptr; }
  // Made with `commissions`: commission_tick for the ticks still kept, then commission_end; its
  // result as a blob (nullptr for None). A failure throws MonitorFailure.
  std::shared_ptr<const PythonCommissioningBlob> EndCommissioning(double t_end_s);

 private:
  double* Keep(double t_s);  // room for one tick's rows
  void Flush();              // step() for every kept tick
  void Call(PyObject* method, const char* what, double t_s, bool with_signals);
  [[noreturn]] void Fail(const char* what, double t_s);
  void Collect(PyObject* result, const char* what, double t_s);
  void Release();
  // Reads `statistics` and `values` of a new instance: "" or why they break the contract.
  std::string ReadStatistics(const pybind11::object& instance);
  void RecordValues(double t_s);  // after a step(), with the GIL

  const PythonMonitorModel& model_;
  bool commissioning_mode_ = false;  // step_/finish_ are commission_tick/commission_end
  PyGILState_STATE gil_state_;
  PyThreadState* saved_ = nullptr;  // this run's thread state while the GIL is released
  PyObject* instance_ = nullptr;
  PyObject* step_ = nullptr;
  PyObject* finish_ = nullptr;      // nullptr: the monitor has no finish()
  PyObject* signals_ = nullptr;     // the Signals object passed at every tick
  PyObject* array_ = nullptr;       // its array, [field][joint], overwritten at every tick
  double* rows_ = nullptr;          // the array's data
  size_t row_size_ = 0;             // doubles in one tick's rows: fields x joints
  std::vector<double> kept_t_s_;    // ticks kept for the next batch ...
  std::vector<double> kept_rows_;   // ... and their rows, one row_size_ each
  PyObject* error_ = nullptr;       // the exception that failed the run
  MonitorOutput output_;
  std::vector<StatisticInfo> statistics_;  // what the instance declares (`statistics`)
  PyObject* values_ = nullptr;             // its `values` array, [joint][statistic]
  const double* values_data_ = nullptr;
  mutable ThresholdRecorder* recorder_ = nullptr;  // the tap's, while the run lasts
};

// "ValueError: bad gain (my_monitor.py:42 in step)": an exception's type, its message and where
// it was raised (the innermost frame of its traceback). Needs the GIL; never throws.
std::string DescribeException(PyObject* value);

// The builder of "python" monitors named by class ({"type": "python", "class":
// "package.module:Class", "settings": {...}}), installed by the package when imported
// (SetMonitorHost): imports the module, finds the class, checks that it is a subclass of
// armfault.Monitor, and makes the model, whose instances get the settings as self.settings
// before their __init__ runs. A module that does not import, a missing class or one that is not
// a Monitor is an InputError at <pointer>/class naming the value. Takes the GIL itself.
std::shared_ptr<const MonitorModel> BuildPythonMonitor(const nlohmann::json& settings, const MonitorContext& context,
                                                       const std::string& pointer);

// Builds a Verdict the way armfault.Verdict(...) does (for the bindings and their tests).
PyVerdict MakePyVerdict(int joint, pybind11::object state, pybind11::object family,
                        pybind11::object magnitude_name, double magnitude, double confidence,
                        pybind11::object t_s, pybind11::object alarm);

}  // namespace armfault::python
