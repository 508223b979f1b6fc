#include "python/src/python_monitor.h"

#include <pybind11/numpy.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/base/json_input.h"
#include "core/base/suggest.h"

namespace armfault::python {

namespace py = pybind11;

const std::vector<const char*> kSignalFields = {"q_ref_rad",      "qd_ref_rad_s", "q_meas_rad",
                                                "qd_est_rad_s",   "tau_sensor_Nm", "i_cmd_A",
                                                "i_supply_meas_A", "v_bus_meas_V", "winding_temp_C"};

namespace {

// The GIL on this run's thread state, for one call into Python.
class GilHold {
 public:
  explicit GilHold(PyThreadState** saved) : saved_(saved) { PyEval_RestoreThread(*saved_); }
  ~GilHold() { *saved_ = PyEval_SaveThread(); }
  GilHold(const GilHold&) = delete;
  GilHold& operator=(const GilHold&) = delete;

 private:
  PyThreadState** saved_;
};

}  // namespace

std::string DescribeException(PyObject* value) {
  try {
    py::handle v(value);
    std::string text = py::str(py::type::handle_of(v).attr("__name__")).cast<std::string>();
    const std::string message = py::str(v).cast<std::string>();
    if (!message.empty()) text += ": " + message;
    py::object tb = py::reinterpret_steal<py::object>(PyException_GetTraceback(value));
    if (tb && !tb.is_none()) {
      py::list frames = py::module_::import("traceback").attr("extract_tb")(tb);
      // Python's own import machinery ("<frozen importlib._bootstrap>") is not where to look.
      const std::string file =
          frames.empty() ? "" : py::str(frames[frames.size() - 1].attr("filename")).cast<std::string>();
      if (!frames.empty() && file.rfind("<frozen ", 0) != 0) {
        py::object last = frames[frames.size() - 1];
        text += " (" + std::filesystem::path(file).filename().string() + ":" +
                py::str(last.attr("lineno")).cast<std::string>() + " in " +
                py::str(last.attr("name")).cast<std::string>() + ")";
      }
    }
    return text;
  } catch (const std::exception&) {
    PyErr_Clear();
    return "an exception that cannot be shown";
  }
}

namespace {

// "Class" of "module.Class", for messages.
std::string ShortName(const std::string& name) {
  const size_t dot = name.rfind('.');
  return dot == std::string::npos ? name : name.substr(dot + 1);
}

HealthState StateOf(const std::string& state) {
  if (state == "healthy") return HealthState::kHealthy;
  if (state == "worn") return HealthState::kWorn;
  if (state == "defective") return HealthState::kDefective;
  throw py::value_error("Verdict: state must be \"healthy\", \"worn\" or \"defective\" (or a bool: alarm), got \"" +
                        state + "\"");
}

}  // namespace

PyVerdict MakePyVerdict(int joint, py::object state, py::object family, py::object magnitude_name, double magnitude,
                        double confidence, py::object t_s, py::object alarm) {
  PyVerdict out;
  Verdict& v = out.verdict;
  v.joint = joint;
  if (state.is_none() && alarm.is_none()) throw py::value_error("Verdict: give its state (or alarm)");
  if (!state.is_none()) {
    if (py::isinstance<py::bool_>(state)) {
      v.state = state.cast<bool>() ? HealthState::kWorn : HealthState::kHealthy;
    } else if (py::isinstance<py::str>(state)) {
      v.state = StateOf(state.cast<std::string>());
    } else {
      throw py::type_error("Verdict: state must be a str (\"healthy\", \"worn\", \"defective\") or a bool, got " +
                           py::str(py::type::handle_of(state).attr("__name__")).cast<std::string>());
    }
    // alarm = state is not healthy, unless given too (then the contract check judges the pair).
    v.alarm = alarm.is_none() ? v.state != HealthState::kHealthy : alarm.cast<bool>();
  } else {
    v.alarm = alarm.cast<bool>();
    v.state = v.alarm ? HealthState::kWorn : HealthState::kHealthy;
  }
  v.family = family.is_none() ? (v.alarm ? "unknown" : "") : family.cast<std::string>();
  v.magnitude_name = magnitude_name.is_none() ? "" : magnitude_name.cast<std::string>();
  v.magnitude = magnitude;
  v.confidence = confidence;
  if (!t_s.is_none()) {
    v.t_s = t_s.cast<double>();
    out.has_time = true;
  }
  return out;
}

// ---------------------------------------------------------------------------- the model

PythonMonitorModel::PythonMonitorModel(py::handle factory, std::string name, std::string robot_json, int joints)
    : name_(std::move(name)), robot_json_(std::move(robot_json)), joints_(joints) {
  py::object signals = py::module_::import("armfault").attr("Signals");
  py::object loads = py::module_::import("json").attr("loads");
  factory_ = factory.inc_ref().ptr();
  signals_type_ = signals.release().ptr();
  json_loads_ = loads.release().ptr();
}

PythonMonitorModel::~PythonMonitorModel() {
  if (!Py_IsInitialized()) return;
  const PyGILState_STATE state = PyGILState_Ensure();
  Py_XDECREF(factory_);
  Py_XDECREF(signals_type_);
  Py_XDECREF(json_loads_);
  PyGILState_Release(state);
}

std::unique_ptr<HealthMonitor> PythonMonitorModel::NewMonitor() const {
  return std::make_unique<PythonMonitor>(*this);
}

namespace {

// A unit's model: the campaign's Python monitor and what it learned on the unit, which every
// run's instance gets as self.commissioning.
class PythonUnitModel : public MonitorModel {
 public:
  PythonUnitModel(std::shared_ptr<const PythonMonitorModel> base, std::shared_ptr<const PythonCommissioningBlob> blob)
      : base_(std::move(base)), blob_(std::move(blob)) {}
  std::string type() const override { return "python"; }
  std::string source() const override { return base_->name(); }
  std::unique_ptr<HealthMonitor> NewMonitor() const override {
    return std::make_unique<PythonMonitor>(*base_, nullptr, blob_.get());
  }

 private:
  std::shared_ptr<const PythonMonitorModel> base_;
  std::shared_ptr<const PythonCommissioningBlob> blob_;
};

// One unit's commissioning run streamed to a fresh instance (PythonMonitor in its commissioning
// mode: ticks kept and handed over in batches under the GIL, as a run's are).
class PythonCommissioningSink : public CommissioningSink {
 public:
  PythonCommissioningSink(std::shared_ptr<const PythonMonitorModel> base, std::unique_ptr<PythonMonitor> monitor)
      : base_(std::move(base)), monitor_(std::move(monitor)) {}
  void Tick(double t_s, const std::vector<JointSignals>& joints) override { monitor_->Observe(t_s, joints); }
  std::shared_ptr<const MonitorModel> End(double t_end_s) override {
    std::shared_ptr<const PythonCommissioningBlob> blob = monitor_->EndCommissioning(t_end_s);
    if (!blob) return nullptr;  // commission_end returned None: nothing learned
    return std::make_shared<PythonUnitModel>(base_, std::move(blob));
  }

 private:
  std::shared_ptr<const PythonMonitorModel> base_;
  std::unique_ptr<PythonMonitor> monitor_;
};

}  // namespace

bool PythonMonitorModel::LearnsFromCommissioning() const {
  if (!factory_ || factory_ == Py_None) return false;
  const PyGILState_STATE state = PyGILState_Ensure();
  const bool learns = PyObject_HasAttrString(factory_, "commission_tick") == 1;
  PyGILState_Release(state);
  return learns;
}

std::unique_ptr<CommissioningSink> PythonMonitorModel::BeginCommissioning(double control_dt_s) const {
  (void)control_dt_s;  // the instance has self.dt_s
  auto monitor = std::make_unique<PythonMonitor>(*this, nullptr, nullptr, true);
  if (!monitor->commissions()) return nullptr;
  std::shared_ptr<const PythonMonitorModel> self = weak_from_this().lock();
  if (!self) throw MonitorFailure(ShortName(name_) + ": a monitor model not owned by a shared_ptr cannot be commissioned");
  return std::make_unique<PythonCommissioningSink>(std::move(self), std::move(monitor));
}

// ---------------------------------------------------------------------------- one run

PythonMonitor::PythonMonitor(const PythonMonitorModel& model, PyObject* given, const PythonCommissioningBlob* commissioning,
                             bool commissions)
    : model_(model), commissioning_mode_(commissions) {
  gil_state_ = PyGILState_Ensure();
  std::string failure;
  const char* raised_in = "(robot)";  // where an exception came from, for the message
  try {
    py::object instance;
    if (given) {
      instance = py::reinterpret_borrow<py::object>(given);
    } else {
      // A fresh dict per run: nothing one run's monitor does to it reaches another's.
      py::object robot = py::reinterpret_borrow<py::object>(model.json_loads())(model.robot_json());
      instance = py::reinterpret_borrow<py::object>(model.factory())(robot);
    }
    if (commissioning) {
      // The unit's blob: bytes as they were, a JSON value as a fresh object per run.
      py::object value = commissioning->is_bytes
                             ? py::object(py::bytes(commissioning->data))
                             : py::reinterpret_borrow<py::object>(model.json_loads())(commissioning->data);
      py::setattr(instance, "commissioning", value);
    }
    py::object step = py::getattr(instance, commissions ? "commission_tick" : "step", py::none());
    py::object finish = py::getattr(instance, commissions ? "commission_end" : "finish", py::none());
    if (commissions && !PyCallable_Check(step.ptr())) {
      // No commission_tick: this monitor learns nothing from commissioning (commissions() false).
    } else if (commissions && !PyCallable_Check(finish.ptr())) {
      failure = ShortName(model.name()) + " has commission_tick but no commission_end(t_end_s) to return what it learned";
    } else if (!PyCallable_Check(step.ptr())) {
      failure = ShortName(model.name()) + "(robot) made a " +
                py::str(py::type::handle_of(instance).attr("__name__")).cast<std::string>() +
                ", which has no step(t_s, signals) method";
    } else {
      py::array_t<double> array({static_cast<py::ssize_t>(kSignalFields.size()), static_cast<py::ssize_t>(model.joints())});
      std::fill(array.mutable_data(), array.mutable_data() + array.size(), 0.0);
      rows_ = array.mutable_data();
      row_size_ = static_cast<size_t>(array.size());
      kept_t_s_.reserve(kBatchTicks);
      kept_rows_.reserve(kBatchTicks * row_size_);
      py::object signals = py::reinterpret_borrow<py::object>(model.signals_type())(array);
      instance_ = instance.release().ptr();
      step_ = step.release().ptr();
      finish_ = PyCallable_Check(finish.ptr()) ? finish.release().ptr() : nullptr;
      array_ = array.release().ptr();
      signals_ = signals.release().ptr();
      if (commissions) {
        py::object begin = py::getattr(py::handle(instance_), "commission_begin", py::none());
        raised_in = ".commission_begin()";
        if (PyCallable_Check(begin.ptr())) begin();
      } else {
        failure = ReadStatistics(py::reinterpret_borrow<py::object>(instance_));
      }
    }
  } catch (py::error_already_set& e) {
    e.restore();
    PyObject *type, *value, *tb;
    PyErr_Fetch(&type, &value, &tb);
    PyErr_NormalizeException(&type, &value, &tb);
    if (tb) PyException_SetTraceback(value, tb);
    failure = ShortName(model.name()) + raised_in + " raised " + DescribeException(value);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(tb);
  }
  if (!failure.empty()) {
    Release();
    PyGILState_Release(gil_state_);
    throw MonitorFailure(failure);
  }
  saved_ = PyEval_SaveThread();
}

PythonMonitor::~PythonMonitor() {
  PyEval_RestoreThread(saved_);
  Release();
  PyGILState_Release(gil_state_);
}

std::string PythonMonitor::ReadStatistics(const py::object& instance) {
  const py::object declared = py::getattr(instance, "statistics", py::tuple());
  const std::string who = ShortName(model_.name());
  if (declared.is_none()) return "";
  if (!py::isinstance<py::sequence>(declared) || py::isinstance<py::str>(declared)) {
    return who + ".statistics must be a sequence of armfault.Statistic";
  }
  for (py::handle item : declared) {
    try {
      StatisticInfo info;
      info.name = py::getattr(item, "name").cast<std::string>();
      info.family = py::getattr(item, "family").cast<std::string>();
      info.threshold = py::getattr(item, "threshold").cast<double>();
      info.setting = py::getattr(item, "setting", py::str("")).cast<std::string>();
      statistics_.push_back(std::move(info));
    } catch (const std::exception&) {
      PyErr_Clear();
      return who + ".statistics holds a " + py::str(py::type::handle_of(item).attr("__name__")).cast<std::string>() +
             ", expected armfault.Statistic(name, family, threshold, setting)";
    }
  }
  if (statistics_.empty()) return "";
  if (std::string why = CheckStatistics(statistics_); !why.empty()) return who + ".statistics: " + why;
  const py::object values = py::getattr(instance, "values", py::none());
  const py::ssize_t rows = model_.joints(), columns = static_cast<py::ssize_t>(statistics_.size());
  bool usable = py::isinstance<py::array>(values);
  if (usable) {
    const py::array a = py::reinterpret_borrow<py::array>(values);
    usable = a.dtype().is(py::dtype::of<double>()) && (a.flags() & py::array::c_style) && a.ndim() == 2 &&
             a.shape(0) == rows && a.shape(1) == columns;
  }
  if (!usable) {
    return who + " declares statistics but its `values` is not a float64 array of shape (" + std::to_string(rows) +
           ", " + std::to_string(columns) + "): call armfault.Monitor.__init__ (super().__init__(robot))";
  }
  values_ = values.inc_ref().ptr();
  values_data_ = static_cast<const double*>(py::reinterpret_borrow<py::array>(values).data());
  return "";
}

std::unique_ptr<DecisionTap> PythonMonitor::NewDecisionTap(double onset_s) const {
  if (statistics_.empty()) return nullptr;
  auto tap = std::make_unique<ThresholdTap>(statistics_, model_.joints(), onset_s);
  recorder_ = tap->recorder();
  return tap;
}

void PythonMonitor::Release() {
  Py_CLEAR(values_);
  values_data_ = nullptr;
  Py_CLEAR(signals_);
  Py_CLEAR(array_);
  Py_CLEAR(finish_);
  Py_CLEAR(step_);
  Py_CLEAR(instance_);
  Py_CLEAR(error_);
  rows_ = nullptr;
}

PyObject* PythonMonitor::TakeError() {
  PyObject* e = error_;
  error_ = nullptr;
  return e;
}

double* PythonMonitor::Keep(double t_s) {
  kept_t_s_.push_back(t_s);
  kept_rows_.resize(kept_t_s_.size() * row_size_);
  return kept_rows_.data() + (kept_t_s_.size() - 1) * row_size_;
}

void PythonMonitor::Flush() {
  if (kept_t_s_.empty()) return;
  struct Clear {  // whatever happens, these ticks are done with
    PythonMonitor* m;
    ~Clear() { m->kept_t_s_.clear(); }
  } clear{this};
  GilHold hold(&saved_);
  for (size_t k = 0; k < kept_t_s_.size(); ++k) {
    std::memcpy(rows_, kept_rows_.data() + k * row_size_, sizeof(double) * row_size_);
    Call(step_, commissioning_mode_ ? "commission_tick" : "step", kept_t_s_[k], true);
    if (recorder_) RecordValues(kept_t_s_[k]);
  }
}

void PythonMonitor::RecordValues(double t_s) {
  // The values are read in place: the array must stay the one declared at the start.
  PyObject* now = PyObject_GetAttrString(instance_, "values");
  if (!now) Fail("values", t_s);
  Py_DECREF(now);
  if (now != values_) {
    throw MonitorFailure(ShortName(model_.name()) + ".values at t_s " + FormatNumber(t_s) +
                         " is another object than at the start: write into it (self.values[j, s] = v), do not "
                         "assign a new one");
  }
  recorder_->Record(t_s, values_data_);
}

void PythonMonitor::Observe(double t_s, const std::vector<JointSignals>& joints) {
  const size_t n = static_cast<size_t>(model_.joints());
  double* r = Keep(t_s);
  for (size_t j = 0; j < n; ++j) {
    if (j >= joints.size()) {
      for (size_t f = 0; f < kSignalFields.size(); ++f) r[f * n + j] = std::nan("");
      continue;
    }
    const JointSignals& s = joints[j];
    r[0 * n + j] = s.q_ref_rad;
    r[1 * n + j] = s.qd_ref_rad_s;
    r[2 * n + j] = s.q_meas_rad;
    r[3 * n + j] = s.qd_est_rad_s;
    r[4 * n + j] = s.tau_sensor_Nm;
    r[5 * n + j] = s.i_cmd_A;
    r[6 * n + j] = s.i_supply_meas_A;
    r[7 * n + j] = s.v_bus_meas_V;
    r[8 * n + j] = s.winding_temp_C;
  }
  if (kept_t_s_.size() >= kBatchTicks) Flush();
}

void PythonMonitor::ObserveRows(double t_s, const double* rows) {
  std::memcpy(Keep(t_s), rows, sizeof(double) * row_size_);
  if (kept_t_s_.size() >= kBatchTicks) Flush();
}

void PythonMonitor::Finish(double t_end_s) {
  Flush();
  if (!finish_) return;
  GilHold hold(&saved_);
  Call(finish_, "finish", t_end_s, false);
}

void PythonMonitor::Call(PyObject* method, const char* what, double t_s, bool with_signals) {
  PyObject* t = PyFloat_FromDouble(t_s);
  if (!t) Fail(what, t_s);
  PyObject* args[3] = {nullptr, t, signals_};
  const size_t nargs = with_signals ? 2 : 1;
#if PY_VERSION_HEX >= 0x03090000
  PyObject* result = PyObject_Vectorcall(method, args + 1, nargs | PY_VECTORCALL_ARGUMENTS_OFFSET, nullptr);
#else
  PyObject* result = with_signals ? PyObject_CallFunctionObjArgs(method, t, signals_, nullptr)
                                  : PyObject_CallFunctionObjArgs(method, t, nullptr);
#endif
  Py_DECREF(t);
  if (!result) Fail(what, t_s);
  Collect(result, what, t_s);
}

void PythonMonitor::Fail(const char* what, double t_s) {
  PyObject *type, *value, *tb;
  PyErr_Fetch(&type, &value, &tb);
  PyErr_NormalizeException(&type, &value, &tb);
  if (tb) PyException_SetTraceback(value, tb);
  const std::string text = value ? DescribeException(value) : "an unknown error";
  Py_XDECREF(type);
  Py_XDECREF(tb);
  Py_XDECREF(error_);
  error_ = value;
  throw MonitorFailure(ShortName(model_.name()) + "." + what + " at t_s " + FormatNumber(t_s) + ": " + text);
}

void PythonMonitor::Collect(PyObject* result_ptr, const char* what, double t_s) {
  if (result_ptr == Py_None) {
    Py_DECREF(result_ptr);
    return;
  }
  py::object result = py::reinterpret_steal<py::object>(result_ptr);
  if (commissioning_mode_) {
    throw MonitorFailure(ShortName(model_.name()) + "." + what + " at t_s " + FormatNumber(t_s) + " returned a " +
                         py::str(py::type::handle_of(result).attr("__name__")).cast<std::string>() +
                         ", expected None (commission_end returns what was learned)");
  }
  auto add = [&](py::handle item) {
    if (!py::isinstance<PyVerdict>(item)) {
      throw MonitorFailure(ShortName(model_.name()) + "." + what + " at t_s " + FormatNumber(t_s) + " returned " +
                           (item.ptr() == result.ptr() ? "" : "a list holding ") + "a " +
                           py::str(py::type::handle_of(item).attr("__name__")).cast<std::string>() +
                           ", expected None, an armfault.Verdict or a list of them");
    }
    const PyVerdict& pv = item.cast<const PyVerdict&>();
    Verdict v = pv.verdict;
    if (!pv.has_time) v.t_s = t_s;
    output_.verdicts.push_back(std::move(v));
  };
  if (PyList_Check(result.ptr()) || PyTuple_Check(result.ptr())) {
    for (py::handle item : result) add(item);
  } else {
    add(result);
  }
}

}  // namespace armfault::python

namespace armfault::python {

std::shared_ptr<const PythonCommissioningBlob> PythonMonitor::EndCommissioning(double t_end_s) {
  Flush();
  GilHold hold(&saved_);
  PyObject* t = PyFloat_FromDouble(t_end_s);
  if (!t) Fail("commission_end", t_end_s);
  PyObject* result = PyObject_CallFunctionObjArgs(finish_, t, nullptr);
  Py_DECREF(t);
  if (!result) Fail("commission_end", t_end_s);
  const py::object r = py::reinterpret_steal<py::object>(result);
  if (r.is_none()) return nullptr;
  auto blob = std::make_shared<PythonCommissioningBlob>();
  if (PyBytes_Check(r.ptr())) {
    blob->is_bytes = true;
    blob->data.assign(PyBytes_AS_STRING(r.ptr()), static_cast<size_t>(PyBytes_GET_SIZE(r.ptr())));
  } else if (PyByteArray_Check(r.ptr())) {
    blob->is_bytes = true;
    blob->data.assign(PyByteArray_AS_STRING(r.ptr()), static_cast<size_t>(PyByteArray_GET_SIZE(r.ptr())));
  } else {
    // Anything else as JSON (json.dumps, no NaN: the runs read it back with json.loads).
    try {
      const py::object text = py::module_::import("json").attr("dumps")(r, py::arg("allow_nan") = false);
      blob->data = text.cast<std::string>();
    } catch (py::error_already_set& e) {
      e.restore();
      Fail("commission_end (its result as JSON: return bytes, or a value json.dumps takes)", t_end_s);
    }
  }
  return blob;
}

}  // namespace armfault::python

namespace armfault::python {

namespace {

// The current Python exception, described and cleared. Needs the GIL.
std::string TakePythonError(py::error_already_set& e) {
  e.restore();
  PyObject *type, *value, *tb;
  PyErr_Fetch(&type, &value, &tb);
  PyErr_NormalizeException(&type, &value, &tb);
  if (tb && value) PyException_SetTraceback(value, tb);
  const std::string text = value ? DescribeException(value) : "an unknown error";
  Py_XDECREF(type);
  Py_XDECREF(value);
  Py_XDECREF(tb);
  return text;
}

std::string TypeName(py::handle object) {
  return py::str(py::type::handle_of(object).attr("__name__")).cast<std::string>();
}

}  // namespace

std::shared_ptr<const MonitorModel> BuildPythonMonitor(const nlohmann::json& settings, const MonitorContext& context,
                                                       const std::string& pointer) {
  const std::string& source = context.input.source;
  if (!settings.contains("class")) {
    throw InputError(source, PointerJoin(pointer, "factory"),
                     "a Python monitor passed to run_campaign (factory \"" + settings.value("factory", "") +
                         "\") cannot be rebuilt: it was not named by import path; run it again from Python "
                         "(run_campaign(..., monitor=...)), or name it in the campaign as \"class\": "
                         "\"package.module:Class\"");
  }
  const std::string at = PointerJoin(pointer, "class");
  const std::string path = settings.at("class").get<std::string>();
  const size_t colon = path.find(':');
  const std::string module_name = path.substr(0, colon), qualname = path.substr(colon + 1);
  py::gil_scoped_acquire gil;
  py::object object;
  try {
    object = py::module_::import(module_name.c_str());
  } catch (py::error_already_set& e) {
    throw InputError(source, at, "\"" + path + "\": cannot import module \"" + module_name + "\": " + TakePythonError(e) +
                                     " (imported as Python imports it: from sys.path, which holds the current "
                                     "directory under `python3 -m armfault`, and PYTHONPATH)");
  }
  std::string where = "module \"" + module_name + "\"";
  size_t start = 0;
  for (;;) {
    const size_t dot = qualname.find('.', start);
    const std::string part = qualname.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    py::object next;
    try {
      next = py::getattr(object, part.c_str(), py::none());
      if (next.is_none() && !py::hasattr(object, part.c_str())) {
        std::vector<std::string> names;
        for (py::handle n : py::reinterpret_steal<py::list>(PyObject_Dir(object.ptr()))) {
          const std::string name = py::str(n).cast<std::string>();
          if (!name.empty() && name[0] != '_') names.push_back(name);
        }
        const std::string near = NearestWord(part, names);
        throw InputError(source, at, "\"" + path + "\": " + where + " has no \"" + part + "\"",
                         near.empty() ? "" : "did you mean \"" + module_name + ":" +
                                                 qualname.substr(0, start) + near + "\"?");
      }
    } catch (py::error_already_set& e) {
      throw InputError(source, at, "\"" + path + "\": reading \"" + part + "\" of " + where + " raised " + TakePythonError(e));
    }
    object = next;
    if (dot == std::string::npos) break;
    where = "\"" + qualname.substr(0, dot) + "\"";
    start = dot + 1;
  }
  const py::object monitor_base = py::module_::import("armfault").attr("Monitor");
  if (!PyType_Check(object.ptr())) {
    throw InputError(source, at, "\"" + path + "\" is a " + TypeName(object) +
                                     ", not a class: name a subclass of armfault.Monitor");
  }
  const int is_monitor = PyObject_IsSubclass(object.ptr(), monitor_base.ptr());
  if (is_monitor != 1) {
    if (is_monitor < 0) PyErr_Clear();
    throw InputError(source, at, "\"" + path + "\" is the class " +
                                     py::str(object.attr("__qualname__")).cast<std::string>() +
                                     ", which is not a subclass of armfault.Monitor");
  }
  // factory(robot): the class, each instance with a fresh dict of the settings as self.settings
  // before its __init__ runs (armfault._Configured).
  const py::object factory = py::module_::import("armfault").attr("_Configured")(object, settings.value("settings", nlohmann::json::object()).dump());
  return std::make_shared<PythonMonitorModel>(factory, module_name + "." + qualname, RobotToJson(context.robot).dump(),
                                              static_cast<int>(context.robot.modules.size()));
}

}  // namespace armfault::python
