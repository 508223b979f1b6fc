// The monitor types: one row each. A new built-in monitor is a new file plus a row here.
#include "core/monitors/registry.h"

#include <filesystem>

#include "core/base/suggest.h"
#include "core/monitors/commissioning.h"
#include "core/monitors/plugin_monitor.h"

namespace armfault {

// Each type parses its settings (the "monitor" object without "type") into their resolved
// JSON, throwing InputErrors with pointers, and builds its model from resolved settings.
using ParseMonitorSettings = nlohmann::json (*)(const nlohmann::json& object, const std::string& pointer,
                                                const InputContext& context);
using BuildMonitorModel = std::shared_ptr<const MonitorModel> (*)(const nlohmann::json& settings,
                                                                  const MonitorContext& context,
                                                                  const std::string& pointer);

// power_efficiency (below) and plugin (core/monitors/plugin_monitor.cc).
nlohmann::json ParsePowerEfficiencySettings(const nlohmann::json& object, const std::string& pointer,
                                            const InputContext& context);
std::shared_ptr<const MonitorModel> BuildPowerEfficiencyModel(const nlohmann::json& settings,
                                                              const MonitorContext& context, const std::string& pointer);

namespace {

struct MonitorType {
  const char* type;
  const char* description;
  ParseMonitorSettings parse;
  BuildMonitorModel build;
  bool runs_user_code;  // building the model runs code the campaign names
};

// A Python monitor (docs/monitor-api.md, "A monitor in Python"), in one of two forms:
//   {"type": "python", "class": "package.module:Class", "settings": {...}}
//       a class named by its import path, which any command that runs the campaign rebuilds
//       where Python is hosted (`python3 -m armfault ...`, the Python package); settings
//       (default {}) are the instance's self.settings;
//   {"type": "python", "factory": "module.Class"}
//       written by the Python package for a class or factory passed to run_campaign that cannot
//       be imported by name: a record of what ran, readable (merge, tune, score, diff, boundary
//       --from read only the spec) but never rebuilt.
// Only a host can build either (SetMonitorHost): without one the builder says where it runs.
bool IsIdentifierPath(const std::string& text) {
  if (text.empty()) return false;
  bool start = true;
  for (const char c : text) {
    const bool letter = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' ||
                        static_cast<unsigned char>(c) >= 0x80;  // Python identifiers may be non-ASCII
    const bool digit = c >= '0' && c <= '9';
    if (c == '.') {
      if (start) return false;
      start = true;
    } else if (letter || (digit && !start)) {
      start = false;
    } else {
      return false;
    }
  }
  return !start;
}

nlohmann::json ParsePythonSettings(const nlohmann::json& object, const std::string& pointer, const InputContext& context) {
  try {
    ObjectReader reader(object, pointer);
    if (!object.contains("class")) {
      reader.AllowOnly({"factory"});
      if (!object.contains("factory")) {
        throw InputError("", PointerJoin(pointer, "class"),
                         "a Python monitor names its class by import path: \"class\": \"package.module:Class\"");
      }
      return {{"factory", reader.RequireString("factory")}};
    }
    reader.AllowOnly({"class", "settings"});
    const std::string path = reader.RequireString("class");
    const size_t colon = path.find(':');
    if (colon == std::string::npos || !IsIdentifierPath(path.substr(0, colon)) ||
        !IsIdentifierPath(path.substr(colon + 1))) {
      throw InputError("", PointerJoin(pointer, "class"),
                       "expected an import path \"package.module:Class\" (a module Python imports, a colon, the "
                       "class in it), got \"" + path + "\"");
    }
    nlohmann::json settings = nlohmann::json::object();
    if (const auto it = object.find("settings"); it != object.end()) {
      if (!it->is_object()) {
        throw InputError("", PointerJoin(pointer, "settings"),
                         "expected the monitor's settings as an object (its self.settings), got " + Describe(*it));
      }
      settings = *it;
    }
    return {{"class", path}, {"settings", settings}};
  } catch (const InputError& e) {
    throw e.WithSource(context.source);
  }
}

std::shared_ptr<const MonitorModel> BuildPythonModel(const nlohmann::json& settings, const MonitorContext& context,
                                                     const std::string& pointer) {
  if (settings.contains("class")) {
    const std::string path = settings.value("class", "");
    throw InputError(context.input.source, PointerJoin(pointer, "class"),
                     "the Python monitor \"" + path + "\" runs where Python is hosted: run this command as "
                     "`python3 -m armfault ...` (the same arguments, with the armfault Python package and the "
                     "module of \"" + path + "\" importable, docs/monitor-api.md)");
  }
  throw InputError(context.input.source, PointerJoin(pointer, "factory"),
                   "a Python monitor passed to run_campaign (factory \"" + settings.value("factory", "") +
                       "\") cannot be rebuilt: it was not named by import path; run it again from Python "
                       "(run_campaign(..., monitor=...)), or name it in the campaign as \"class\": "
                       "\"package.module:Class\"");
}

// The monitor of a directory `armfault score` wrote: the verdicts file that was scored, as
// given on the command line, and the SHA-256 of its bytes (64 lowercase hex digits), so that
// two scorings of different verdicts are different campaigns (campaign hash, `diff`). Such a
// monitor is a record of where verdicts came from, not code: it cannot be built to run, and
// `tune` refuses it (campaigns/tuning/tuning.cc).
nlohmann::json ParseVerdictsSettings(const nlohmann::json& object, const std::string& pointer, const InputContext& context) {
  try {
    ObjectReader reader(object, pointer);
    reader.AllowOnly({"file", "sha256"});
    const std::string file = reader.RequireString("file");
    const std::string sha256 = reader.RequireString("sha256");
    if (sha256.size() != 64 || sha256.find_first_not_of("0123456789abcdef") != std::string::npos) {
      throw InputError("", PointerJoin(pointer, "sha256"),
                       "expected the SHA-256 of the verdicts file as 64 lowercase hex digits, got \"" + sha256 + "\"");
    }
    return {{"file", file}, {"sha256", sha256}};
  } catch (const InputError& e) {
    throw e.WithSource(context.source);
  }
}

std::shared_ptr<const MonitorModel> BuildVerdictsModel(const nlohmann::json& settings, const MonitorContext& context,
                                                       const std::string& pointer) {
  throw InputError(context.input.source, PointerJoin(pointer, "type"),
                   "the verdicts in \"" + settings.value("file", "") +
                       "\" were made offline and scored by armfault score: there is no monitor to run (run the "
                       "detector that wrote them, or score its verdicts again)");
}

const MonitorType kMonitorTypes[] = {
    {"power_efficiency", "the thesis's power-efficiency monitor, extended to isolate and size faults (docs/monitor.md)",
     &ParsePowerEfficiencySettings, &BuildPowerEfficiencyModel, false},
    {"plugin", "a compiled monitor in a shared library, C ABI include/armfault/monitor_plugin.h (docs/monitor-api.md)",
     &ParsePluginSettings, &BuildPluginModel, true},
    {"python", "a class written in Python, run by the armfault Python package (docs/monitor-api.md)",
     &ParsePythonSettings, &BuildPythonModel, true},
    {"verdicts", "verdicts made offline, scored by armfault score (the file and its SHA-256; cannot be run)",
     &ParseVerdictsSettings, &BuildVerdictsModel, false},
};

const MonitorType* FindType(const std::string& type) {
  for (const MonitorType& t : kMonitorTypes) {
    if (type == t.type) return &t;
  }
  return nullptr;
}

// The builders hosts installed (SetMonitorHost), by type. Set before any campaign is read, on
// one thread; read by every build after.
std::vector<std::pair<std::string, BuildMonitorModel>>& Hosts() {
  static std::vector<std::pair<std::string, BuildMonitorModel>> hosts;
  return hosts;
}

std::vector<std::string> TypeNames() {
  std::vector<std::string> names;
  for (const MonitorType& t : kMonitorTypes) names.push_back(t.type);
  return names;
}

}  // namespace

nlohmann::json ParsePowerEfficiencySettings(const nlohmann::json& object, const std::string& pointer,
                                            const InputContext& context) {
  return MonitorConfigToJson(MonitorConfigFromJson(object, pointer, context.source));
}

std::shared_ptr<const MonitorModel> BuildPowerEfficiencyModel(const nlohmann::json& settings,
                                                              const MonitorContext& context, const std::string& pointer) {
  const MonitorConfig as_given = MonitorConfigFromJson(settings, pointer, context.input.source);
  ValidateDecisionRate(as_given, context.robot.modules.at(0).controller.rate_Hz, pointer, context.input.source);
  return std::make_shared<PowerEfficiencyModel>(as_given, MakePowerMonitorModel(context.robot, PowerEfficiencyConfig(as_given, context)));
}

MonitorConfig PowerEfficiencyConfig(const MonitorConfig& as_given, const MonitorContext& context) {
  // A monitor left with the datasheet must allow for the tolerances the datasheet states.
  return context.has_tolerances && !context.commissioning ? WidenedForTolerances(as_given, context.stated, context.robot)
                                                          : as_given;
}

PowerEfficiencyModel::PowerEfficiencyModel(const MonitorConfig& as_given, PowerMonitorModel model)
    : as_given_(as_given), model_(std::move(model)) {}

namespace {

// The built-in monitor fits the unit as the ticks come (core/monitors/commissioning.h).
class PowerEfficiencySink : public CommissioningSink {
 public:
  PowerEfficiencySink(const PowerEfficiencyModel& model, double control_dt_s)
      : model_(model), fit_(model.model(), control_dt_s) {}
  void Tick(double t_s, const std::vector<JointSignals>& joints) override {
    (void)t_s;
    fit_.Tick(joints);
  }
  std::shared_ptr<const MonitorModel> End(double t_end_s) override {
    (void)t_end_s;
    return std::make_shared<PowerEfficiencyModel>(model_.as_given(), fit_.End());
  }

 private:
  const PowerEfficiencyModel& model_;  // outlives the sink
  PowerMonitorCommissioning fit_;
};

}  // namespace

std::unique_ptr<CommissioningSink> PowerEfficiencyModel::BeginCommissioning(double control_dt_s) const {
  return std::make_unique<PowerEfficiencySink>(*this, control_dt_s);
}

std::unique_ptr<HealthMonitor> PowerEfficiencyModel::NewMonitor() const {
  return std::make_unique<PowerEfficiencyMonitor>(model_);
}

nlohmann::json MonitorSpec::ToJson() const {
  if (type == "power_efficiency") return settings;
  nlohmann::json out = {{"type", type}};
  for (const auto& [key, value] : settings.items()) out[key] = value;
  return out;
}

MonitorSpec MonitorSpecFromJson(const nlohmann::json& value, const std::string& pointer, const InputContext& context) {
  if (value.is_string()) {
    std::filesystem::path path = value.get<std::string>();
    if (path.is_relative() && !context.base_dir.empty()) path = std::filesystem::path(context.base_dir) / path;
    InputContext file;
    file.source = path.string();
    file.base_dir = path.parent_path().string();
    return MonitorSpecFromJson(ReadJsonFile(path.string()), "", file);
  }
  if (!value.is_object()) {
    throw InputError(context.source, pointer,
                     "expected a monitor (an object, {\"type\": ..., settings}) or the name of a JSON file of one, got " +
                         Describe(value));
  }
  MonitorSpec spec;
  nlohmann::json settings = value;
  if (const auto it = value.find("type"); it != value.end()) {
    if (!it->is_string()) {
      throw InputError(context.source, PointerJoin(pointer, "type"), "expected a monitor type name, got " + Describe(*it));
    }
    spec.type = it->get<std::string>();
    settings.erase("type");
  }
  const MonitorType* type = FindType(spec.type);
  if (!type) {
    const std::string near = NearestWord(spec.type, TypeNames());
    std::string known;
    for (const std::string& n : TypeNames()) known += (known.empty() ? "" : ", ") + n;
    throw InputError(context.source, PointerJoin(pointer, "type"),
                     "unknown monitor type \"" + spec.type + "\" (known: " + known + ")",
                     near.empty() ? "" : "did you mean \"" + near + "\"?");
  }
  spec.settings = type->parse(settings, pointer, context);
  return spec;
}

std::shared_ptr<const MonitorModel> MakeMonitorModel(const MonitorSpec& spec, const MonitorContext& context,
                                                     const std::string& pointer) {
  const MonitorType* type = FindType(spec.type);
  if (!type) throw InputError(context.input.source, pointer, "unknown monitor type \"" + spec.type + "\"");
  for (const auto& [name, build] : Hosts()) {
    if (name == spec.type) return build(spec.settings, context, pointer);
  }
  return type->build(spec.settings, context, pointer);
}

void SetMonitorHost(const std::string& type, MonitorHostBuilder builder) {
  for (auto& [name, build] : Hosts()) {
    if (name == type) {
      build = builder;
      return;
    }
  }
  Hosts().emplace_back(type, builder);
}

bool MonitorRunsUserCode(const std::string& type) {
  const MonitorType* t = FindType(type);
  return t != nullptr && t->runs_user_code;
}

std::vector<MonitorTypeInfo> MonitorTypes() {
  std::vector<MonitorTypeInfo> out;
  for (const MonitorType& t : kMonitorTypes) out.push_back({t.type, t.description});
  return out;
}

}  // namespace armfault
