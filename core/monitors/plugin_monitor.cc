#include "core/monitors/plugin_monitor.h"

#include <dlfcn.h>

#include <cstring>
#include <functional>
#include <filesystem>
#include <type_traits>
#include <utility>
#include <vector>

#include "armfault/monitor_plugin.h"
#include "core/monitors/threshold_statistics.h"
#include "core/plant/simulation.h"

namespace armfault {

namespace fs = std::filesystem;

namespace {

// Room for a plugin's message; longer ones are cut by the plugin (it is told the size).
constexpr size_t kErrorSize = 1024;
// More verdicts than any run can mean (one per joint and tick of an hour at 1 kHz is 1e7 for
// three joints): a count beyond it is garbage, not read.
constexpr int kMaxVerdicts = 50'000'000;
// The largest commissioning blob armfault copies (docs/assumptions.md): one per unit is kept for
// the whole campaign, so a size beyond it is a plugin's bug, not a model.
constexpr size_t kMaxCommissioningBytes = size_t{1} << 30;

std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

// The plugin's message from its error buffer, NUL-terminated whatever it wrote.
std::string MessageOf(char* error, int code) {
  error[kErrorSize - 1] = '\0';
  if (error[0] == '\0') return "code " + std::to_string(code) + ", no message";
  return error;
}

}  // namespace

struct PluginLibrary {
  std::string path;
  void* handle = nullptr;
  armfault_monitor_abi_version_fn abi_version = nullptr;
  armfault_monitor_create_fn create = nullptr;
  // Optional (ABI minor 1), called instead of create when exported: create or it is required.
  armfault_monitor_create_v2_fn create_v2 = nullptr;
  // Optional (minor 1), all four or none, with create_v2: commissioning.
  armfault_monitor_commission_begin_fn commission_begin = nullptr;
  armfault_monitor_commission_tick_fn commission_tick = nullptr;
  armfault_monitor_commission_end_fn commission_end = nullptr;
  armfault_monitor_commission_free_fn commission_free = nullptr;
  armfault_monitor_step_fn step = nullptr;
  armfault_monitor_finish_fn finish = nullptr;
  armfault_monitor_verdicts_fn verdicts = nullptr;
  armfault_monitor_destroy_fn destroy = nullptr;
  // Optional, both or neither: the statistics behind the alarms (tune).
  armfault_monitor_statistics_fn statistics = nullptr;
  armfault_monitor_statistic_values_fn statistic_values = nullptr;

  PluginLibrary() = default;
  PluginLibrary(const PluginLibrary&) = delete;
  PluginLibrary& operator=(const PluginLibrary&) = delete;
  ~PluginLibrary() {
    if (handle) dlclose(handle);
  }
};

namespace {

// A tick's signals as the C ABI lays them out.
void ToPluginSignals(const std::vector<JointSignals>& joints, std::vector<armfault_joint_signals>* out) {
  out->resize(joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    const JointSignals& s = joints[j];
    (*out)[j] = {s.q_ref_rad, s.qd_ref_rad_s,    s.q_meas_rad,   s.qd_est_rad_s,  s.tau_sensor_Nm,
                 s.i_cmd_A,   s.i_supply_meas_A, s.v_bus_meas_V, s.winding_temp_C};
  }
}

// The statistics an instance declares (none without the optional functions), or why they break
// the contract ("" when they keep it).
std::string DeclaredStatistics(const PluginLibrary& library, void* self, std::vector<StatisticInfo>* out) {
  out->clear();
  if (!library.statistics) return "";
  const armfault_statistic* declared = nullptr;
  const int count = library.statistics(self, &declared);
  if (count < 0 || count > 64 || (count > 0 && !declared)) {
    return "armfault_monitor_statistics returned the count " + std::to_string(count) + (declared ? "" : " and NULL");
  }
  for (int k = 0; k < count; ++k) {
    const armfault_statistic& in = declared[k];
    if (!std::memchr(in.name, '\0', sizeof in.name) || !std::memchr(in.family, '\0', sizeof in.family) ||
        !std::memchr(in.setting, '\0', sizeof in.setting)) {
      return "statistic " + std::to_string(k + 1) + ": a name that is not NUL-terminated";
    }
    out->push_back({in.name, in.family, in.threshold, in.setting});
  }
  return CheckStatistics(*out);
}

// One run's plugin instance. Its first error is thrown as a MonitorFailure, which fails the
// run; after it the plugin is never called again (only destroyed) and later calls do nothing,
// so a caller that goes on to Finish() (the report's second look at a run) does not fail twice.
class PluginMonitor : public HealthMonitor {
 public:
  // `self` NULL: create failed with `failure`, thrown at the first Observe() (as are statistics
  // declared against the contract).
  // `commissioning`: the unit's blob create was given, kept while the instance lives.
  PluginMonitor(std::shared_ptr<const PluginLibrary> library, void* self, std::string failure, int joints,
                std::shared_ptr<const std::string> commissioning)
      : library_(std::move(library)), self_(self), pending_failure_(std::move(failure)), joints_(joints),
        commissioning_(std::move(commissioning)) {
    if (self_) {
      if (std::string why = DeclaredStatistics(*library_, self_, &statistics_); !why.empty()) {
        pending_failure_ = why;
        statistics_.clear();
      }
    }
  }
  ~PluginMonitor() override {
    if (self_) library_->destroy(self_);
  }
  PluginMonitor(const PluginMonitor&) = delete;
  PluginMonitor& operator=(const PluginMonitor&) = delete;

  void Observe(double t_s, const std::vector<JointSignals>& joints) override {
    if (!pending_failure_.empty()) Fail(std::exchange(pending_failure_, ""));
    if (!self_) return;
    if (failed_) return;
    ToPluginSignals(joints, &signals_);
    error_[0] = '\0';
    const int code = library_->step(self_, t_s, signals_.data(), static_cast<int>(signals_.size()), error_, kErrorSize);
    if (code != 0) Fail("step returned error: " + MessageOf(error_, code));
    PullVerdicts();
    if (recorder_) {
      const double* values = library_->statistic_values(self_);
      if (!values) Fail("statistic_values returned NULL after the step at t_s " + FormatNumber(t_s));
      recorder_->Record(t_s, values);
    }
  }

  void Finish(double t_end_s) override {
    if (!pending_failure_.empty()) Fail(std::exchange(pending_failure_, ""));
    if (!self_) return;
    if (failed_) return;
    error_[0] = '\0';
    const int code = library_->finish(self_, t_end_s, error_, kErrorSize);
    if (code != 0) Fail("finish returned error: " + MessageOf(error_, code));
    PullVerdicts();
  }

  const MonitorOutput& output() const override { return output_; }

  // The plugin's statistics, recorded after every step (threshold_statistics.h).
  std::unique_ptr<DecisionTap> NewDecisionTap(double onset_s) const override {
    if (statistics_.empty()) return nullptr;
    auto tap = std::make_unique<ThresholdTap>(statistics_, joints_, onset_s);
    recorder_ = tap->recorder();
    return tap;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    failed_ = true;
    throw MonitorFailure(library_->path + ": " + what);
  }

  // Copies the verdicts not seen yet. What CheckOutput cannot see once copied (a state outside
  // the enum, a name without its NUL, a list that shrank) fails the run here.
  void PullVerdicts() {
    const armfault_verdict* verdicts = nullptr;
    const int count = library_->verdicts(self_, &verdicts);
    const size_t seen = output_.verdicts.size();
    if (count < 0 || count > kMaxVerdicts) Fail("verdicts returned the count " + std::to_string(count));
    if (static_cast<size_t>(count) < seen) {
      Fail("verdicts returned " + std::to_string(count) + " verdicts after " + std::to_string(seen) +
           ": the list must only grow");
    }
    if (static_cast<size_t>(count) == seen) return;
    if (!verdicts) Fail("verdicts returned " + std::to_string(count) + " verdicts and a NULL pointer");
    for (size_t k = seen; k < static_cast<size_t>(count); ++k) {
      const armfault_verdict& in = verdicts[k];
      const std::string which = "verdict " + std::to_string(k + 1) + ": ";
      if (in.state < ARMFAULT_STATE_HEALTHY || in.state > ARMFAULT_STATE_DEFECTIVE) {
        Fail(which + "state " + std::to_string(in.state) + ", expected 0 (healthy), 1 (worn) or 2 (defective)");
      }
      if (!std::memchr(in.family, '\0', sizeof in.family)) Fail(which + "family is not NUL-terminated");
      if (!std::memchr(in.magnitude_name, '\0', sizeof in.magnitude_name)) {
        Fail(which + "magnitude_name is not NUL-terminated");
      }
      Verdict v;
      v.t_s = in.t_s;
      v.joint = in.joint;
      v.state = in.state == ARMFAULT_STATE_HEALTHY ? HealthState::kHealthy
                : in.state == ARMFAULT_STATE_WORN  ? HealthState::kWorn
                                                   : HealthState::kDefective;
      v.alarm = v.state != HealthState::kHealthy;
      v.family = in.family;
      v.magnitude_name = in.magnitude_name;
      v.magnitude = in.magnitude;
      v.confidence = in.confidence;
      output_.verdicts.push_back(std::move(v));
    }
  }

  std::shared_ptr<const PluginLibrary> library_;
  void* self_;
  std::vector<armfault_joint_signals> signals_;  // reused at every tick
  char error_[kErrorSize];
  std::string pending_failure_;
  bool failed_ = false;
  MonitorOutput output_;
  int joints_;
  std::vector<StatisticInfo> statistics_;
  std::shared_ptr<const std::string> commissioning_;  // what create_v2 was pointed to
  // The tap's recorder: set by NewDecisionTap, whose tap the runner keeps for the whole run.
  mutable ThresholdRecorder* recorder_ = nullptr;
};

// Opens the library and resolves its functions; errors are InputErrors at `pointer`.
std::shared_ptr<const PluginLibrary> OpenLibrary(const std::string& path, const std::string& source,
                                                 const std::string& pointer) {
  const std::string named = "plugin library " + Quoted(path);
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(source, pointer, named + " does not exist");
  if (fs::is_directory(status)) throw InputError(source, pointer, named + " is a directory");

  auto library = std::make_shared<PluginLibrary>();
  library->path = path;
  // RTLD_LOCAL: two plugins may define the same names; RTLD_NOW: a missing dependency is an error
  // here, not a crash in the middle of a run.
  library->handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!library->handle) {
    const char* why = dlerror();
    throw InputError(source, pointer, named + " cannot be loaded: " + (why ? why : "dlopen failed"));
  }
  std::string missing;
  auto resolve = [&](const char* name, auto* out) {
    dlerror();
    void* symbol = dlsym(library->handle, name);
    if (!symbol) {
      missing += (missing.empty() ? "" : ", ") + std::string(name);
      return;
    }
    *out = reinterpret_cast<std::remove_pointer_t<decltype(out)>>(symbol);
  };
  resolve("armfault_monitor_abi_version", &library->abi_version);
  // create_v2 (ABI minor 1) when exported, else create: one of them.
  library->create_v2 = reinterpret_cast<armfault_monitor_create_v2_fn>(dlsym(library->handle, "armfault_monitor_create_v2"));
  if (!library->create_v2) {
    library->create = reinterpret_cast<armfault_monitor_create_fn>(dlsym(library->handle, "armfault_monitor_create"));
    if (!library->create) missing += std::string(missing.empty() ? "" : ", ") + "armfault_monitor_create (or armfault_monitor_create_v2)";
  }
  resolve("armfault_monitor_step", &library->step);
  resolve("armfault_monitor_finish", &library->finish);
  resolve("armfault_monitor_verdicts", &library->verdicts);
  resolve("armfault_monitor_destroy", &library->destroy);
  // The two optional functions come together or not at all.
  library->statistics = reinterpret_cast<armfault_monitor_statistics_fn>(dlsym(library->handle, "armfault_monitor_statistics"));
  library->statistic_values =
      reinterpret_cast<armfault_monitor_statistic_values_fn>(dlsym(library->handle, "armfault_monitor_statistic_values"));
  // Commissioning: all four or none, and only with create_v2 (its args carry the blob).
  library->commission_begin =
      reinterpret_cast<armfault_monitor_commission_begin_fn>(dlsym(library->handle, "armfault_monitor_commission_begin"));
  library->commission_tick =
      reinterpret_cast<armfault_monitor_commission_tick_fn>(dlsym(library->handle, "armfault_monitor_commission_tick"));
  library->commission_end =
      reinterpret_cast<armfault_monitor_commission_end_fn>(dlsym(library->handle, "armfault_monitor_commission_end"));
  library->commission_free =
      reinterpret_cast<armfault_monitor_commission_free_fn>(dlsym(library->handle, "armfault_monitor_commission_free"));
  const int commissioning = !!library->commission_begin + !!library->commission_tick + !!library->commission_end +
                            !!library->commission_free;
  if (commissioning != 0 && commissioning != 4) {
    std::string absent;
    for (const auto& [name, present] :
         {std::pair<const char*, bool>{"armfault_monitor_commission_begin", library->commission_begin != nullptr},
          {"armfault_monitor_commission_tick", library->commission_tick != nullptr},
          {"armfault_monitor_commission_end", library->commission_end != nullptr},
          {"armfault_monitor_commission_free", library->commission_free != nullptr}}) {
      if (!present) absent += std::string(absent.empty() ? "" : ", ") + name;
    }
    missing += std::string(missing.empty() ? "" : ", ") + absent + " (it exports the other commissioning functions)";
  }
  if (commissioning == 4 && !library->create_v2) {
    missing += std::string(missing.empty() ? "" : ", ") +
               "armfault_monitor_create_v2 (it exports the commissioning functions, whose blob create_v2 gets)";
  }
  if (!library->statistics != !library->statistic_values) {
    missing += std::string(missing.empty() ? "" : ", ") +
               (library->statistics ? "armfault_monitor_statistic_values (it exports armfault_monitor_statistics)"
                                    : "armfault_monitor_statistics (it exports armfault_monitor_statistic_values)");
  }
  if (!missing.empty()) {
    throw InputError(source, pointer,
                     named + " does not export " + missing + " (include/armfault/monitor_plugin.h, ABI version " +
                         std::to_string(ARMFAULT_MONITOR_PLUGIN_ABI_VERSION) + "." +
                         std::to_string(ARMFAULT_MONITOR_PLUGIN_ABI_MINOR) + ")");
  }
  const int version = library->abi_version();
  if (version != ARMFAULT_MONITOR_PLUGIN_ABI_VERSION) {
    throw InputError(source, pointer,
                     named + " was built for monitor plugin ABI version " + std::to_string(version) +
                         ", this armfault loads version " + std::to_string(ARMFAULT_MONITOR_PLUGIN_ABI_VERSION) +
                         ": rebuild it against this armfault's include/armfault/monitor_plugin.h");
  }
  return library;
}

}  // namespace

PluginMonitorModel::PluginMonitorModel(const std::string& library, const nlohmann::json& settings,
                                       const RobotConfig& robot, const std::string& source,
                                       const std::string& pointer)
    : robot_json_(RobotToJson(robot).dump()), settings_json_(settings.dump()),
      joints_(static_cast<int>(robot.modules.size())), dt_s_(ArmModel(robot).control_dt_s()) {
  const std::string at = PointerJoin(pointer, "library");
  library_ = OpenLibrary(library, source, at);
  // One instance at load, so settings the plugin refuses stop the campaign before any run.
  char error[kErrorSize] = {};
  void* probe = Create(error);
  if (!probe) {
    throw InputError(source, at,
                     "plugin library " + Quoted(library) + ": armfault_monitor_create" +
                         (library_->create_v2 ? "_v2" : "") + " returned NULL for the settings " +
                         settings_json_ + ": " + MessageOf(error, 0));
  }
  // Statistics declared against the contract are the plugin's input error too.
  std::vector<StatisticInfo> statistics;
  const std::string bad_statistics = DeclaredStatistics(*library_, probe, &statistics);
  library_->destroy(probe);
  if (!bad_statistics.empty()) {
    throw InputError(source, at, "plugin library " + Quoted(library) + ": " + bad_statistics);
  }
}

const std::string& PluginMonitorModel::library() const { return library_->path; }

void PluginMonitorModel::FillCreateArgs(armfault_monitor_create_args* args) const {
  *args = armfault_monitor_create_args{};
  args->struct_size = sizeof *args;
  args->robot_json = robot_json_.c_str();
  args->settings_json = settings_json_.c_str();
  args->dt_s = dt_s_;
  args->joint_count = joints_;
}

void* PluginMonitorModel::Create(char* error) const {
  if (library_->create_v2) {
    armfault_monitor_create_args args;
    FillCreateArgs(&args);
    if (commissioning_) {
      args.commissioning = commissioning_->data();
      args.commissioning_size = commissioning_->size();
    }
    return library_->create_v2(&args, error, kErrorSize);
  }
  return library_->create(robot_json_.c_str(), settings_json_.c_str(), error, kErrorSize);
}

std::unique_ptr<HealthMonitor> PluginMonitorModel::NewMonitor() const {
  char error[kErrorSize] = {};
  void* self = Create(error);
  // Thrown where every caller expects a monitor to fail, at its first tick.
  return std::make_unique<PluginMonitor>(library_, self, self ? "" : "create returned NULL: " + MessageOf(error, 0),
                                         joints_, commissioning_);
}

namespace {

// One unit's commissioning streamed to the plugin (commission_begin .. commission_free); its
// blob, copied, becomes the unit's PluginMonitorModel. Failures throw MonitorFailure naming the
// library; commission_free follows every handle begin returned.
class PluginCommissioning : public CommissioningSink {
 public:
  PluginCommissioning(std::shared_ptr<const PluginLibrary> library, void* self,
                      std::function<std::shared_ptr<const MonitorModel>(std::shared_ptr<const std::string>)> with_blob)
      : library_(std::move(library)), self_(self), with_blob_(std::move(with_blob)) {}
  ~PluginCommissioning() override {
    if (self_) library_->commission_free(self_);
  }
  PluginCommissioning(const PluginCommissioning&) = delete;
  PluginCommissioning& operator=(const PluginCommissioning&) = delete;

  void Tick(double t_s, const std::vector<JointSignals>& joints) override {
    ToPluginSignals(joints, &signals_);
    error_[0] = '\0';
    const int code = library_->commission_tick(self_, t_s, signals_.data(), static_cast<int>(signals_.size()), error_,
                                               kErrorSize);
    if (code != 0) Fail("commission_tick returned error at t_s " + FormatNumber(t_s) + ": " + MessageOf(error_, code));
  }

  std::shared_ptr<const MonitorModel> End(double t_end_s) override {
    const void* blob = nullptr;
    size_t size = 0;
    error_[0] = '\0';
    const int code = library_->commission_end(self_, t_end_s, &blob, &size, error_, kErrorSize);
    if (code != 0) Fail("commission_end returned error: " + MessageOf(error_, code));
    if (size > kMaxCommissioningBytes) {
      Fail("commission_end returned a blob of " + std::to_string(size) + " bytes, more than the 1 GiB armfault keeps");
    }
    if (size > 0 && !blob) Fail("commission_end returned " + std::to_string(size) + " bytes and a NULL pointer");
    auto copy = std::make_shared<const std::string>(static_cast<const char*>(blob), size);
    library_->commission_free(std::exchange(self_, nullptr));
    return with_blob_(std::move(copy));
  }

 private:
  [[noreturn]] void Fail(const std::string& what) { throw MonitorFailure(library_->path + ": " + what); }

  std::shared_ptr<const PluginLibrary> library_;
  void* self_;
  std::function<std::shared_ptr<const MonitorModel>(std::shared_ptr<const std::string>)> with_blob_;
  std::vector<armfault_joint_signals> signals_;
  char error_[kErrorSize];
};

}  // namespace

bool PluginMonitorModel::LearnsFromCommissioning() const { return library_->commission_begin != nullptr; }

std::unique_ptr<CommissioningSink> PluginMonitorModel::BeginCommissioning(double control_dt_s) const {
  (void)control_dt_s;  // the robot's, which dt_s_ is already
  if (!library_->commission_begin) return nullptr;
  armfault_monitor_create_args args;
  FillCreateArgs(&args);
  char error[kErrorSize] = {};
  void* self = library_->commission_begin(&args, error, kErrorSize);
  if (!self) throw MonitorFailure(library_->path + ": commission_begin returned NULL: " + MessageOf(error, 0));
  return std::make_unique<PluginCommissioning>(library_, self, [model = *this](std::shared_ptr<const std::string> blob) {
    auto unit = std::make_shared<PluginMonitorModel>(model);
    unit->commissioning_ = std::move(blob);
    return std::shared_ptr<const MonitorModel>(std::move(unit));
  });
}

nlohmann::json ParsePluginSettings(const nlohmann::json& object, const std::string& pointer,
                                   const InputContext& context) {
  try {
    ObjectReader reader(object, pointer);
    ErrorList errors;
    errors.Try([&] { reader.AllowOnly({"library", "settings"}); });
    nlohmann::json out = {{"library", ""}, {"settings", nlohmann::json::object()}};
    errors.Try([&] {
      const std::string at = reader.PointerTo("library");
      const std::string given = reader.RequireString("library");
      if (given.empty()) throw InputError("", at, "expected the path of a shared library, got an empty string");
      // Relative to the file that names it, as a csv trajectory's path; recorded absolute.
      fs::path path = given;
      if (path.is_relative() && !context.base_dir.empty()) path = fs::path(context.base_dir) / path;
      const std::string resolved = fs::absolute(path).lexically_normal().string();
      const std::string named =
          "plugin library " + Quoted(resolved) + (resolved == given ? "" : " (resolved from " + Quoted(given) + ")");
      std::error_code ec;
      const fs::file_status status = fs::status(resolved, ec);
      if (!fs::exists(status)) throw InputError("", at, named + " does not exist");
      if (fs::is_directory(status)) throw InputError("", at, named + " is a directory");
      out["library"] = resolved;
    });
    errors.Try([&] {
      if (const nlohmann::json* s = reader.Find("settings")) {
        if (!s->is_object()) {
          throw InputError("", reader.PointerTo("settings"),
                           "expected an object (the plugin's settings), got " + Describe(*s));
        }
        out["settings"] = *s;
      }
    });
    errors.ThrowIfAny();
    return out;
  } catch (const InputError& e) {
    throw e.WithSource(context.source);
  }
}

std::shared_ptr<const MonitorModel> BuildPluginModel(const nlohmann::json& settings, const MonitorContext& context,
                                                     const std::string& pointer) {
  return std::make_shared<PluginMonitorModel>(settings.at("library").get<std::string>(), settings.at("settings"),
                                              context.robot, context.input.source, pointer);
}

}  // namespace armfault
