// The "plugin" monitor type: a monitor compiled into a shared library behind the C ABI of
// include/armfault/monitor_plugin.h, named in a campaign as
//     "monitor": {"type": "plugin", "library": "path/to/lib.so", "settings": {...}}
// The library is loaded once per campaign (the model owns the handle, shared read-only by every
// thread); each run gets its own plugin instance behind a HealthMonitor. See docs/monitor-api.md,
// "C plugin".
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

#include "core/monitors/registry.h"

struct armfault_monitor_create_args;  // include/armfault/monitor_plugin.h

namespace armfault {

// A loaded library and its functions (plugin_monitor.cc). Closed when the model and every
// monitor it made are gone.
struct PluginLibrary;

class PluginMonitorModel : public MonitorModel {
 public:
  // Loads `library` (an absolute path), checks its ABI version and that create accepts
  // `settings` for `robot` (one instance, destroyed at once). Errors are InputErrors of `source`
  // at `pointer`/library naming the library: not found, not loadable, a missing function, another
  // ABI version, create returning NULL (with the plugin's message).
  PluginMonitorModel(const std::string& library, const nlohmann::json& settings, const RobotConfig& robot,
                     const std::string& source, const std::string& pointer);
  std::string type() const override { return "plugin"; }
  std::string source() const override { return library(); }
  // A new plugin instance for one run. If create returns NULL, its first Observe() throws the
  // MonitorFailure (create succeeded at load, so only a plugin that is not deterministic gets there).
  std::unique_ptr<HealthMonitor> NewMonitor() const override;
  // With the commissioning functions: streams the unit's commissioning run to the plugin; End
  // gives this model with the unit's blob, which create_v2 then gets for every run of the unit.
  // nullptr without them. Failures throw MonitorFailure naming the library.
  std::unique_ptr<CommissioningSink> BeginCommissioning(double control_dt_s) const override;
  bool LearnsFromCommissioning() const override;
  const std::string& library() const;
  // The unit's commissioning blob (null: not commissioned), for tests.
  const std::shared_ptr<const std::string>& commissioning() const { return commissioning_; }

 private:
  // A new instance: create_v2 when the library exports it (with dt_s_ and joints_), else
  // create; NULL with the plugin's message in `error` (kErrorSize bytes).
  void* Create(char* error) const;
  // Fills the arguments every create_v2 and commission_begin call shares (robot, settings,
  // dt_s_, joints_); the strings stay owned by this model.
  void FillCreateArgs(armfault_monitor_create_args* args) const;

  std::shared_ptr<const PluginLibrary> library_;
  std::string robot_json_, settings_json_;  // what create gets, the same for every run
  int joints_;
  double dt_s_;  // the control period [s] (ArmModel::control_dt_s: the ticks are k * dt_s_)
  std::shared_ptr<const std::string> commissioning_;  // the unit's blob, armfault's copy
};

// The registry's row (core/monitors/registry.cc). Settings: "library" (required; a path relative
// to the campaign's directory, context.base_dir) and "settings" (an object, default {}); other
// keys are rejected. Resolved: {"library": the absolute path, "settings": ...}, so campaign.json
// names the file that ran and `merge`, `tune`, `report` and `trace --run` load the same one.
nlohmann::json ParsePluginSettings(const nlohmann::json& object, const std::string& pointer,
                                   const InputContext& context);
std::shared_ptr<const MonitorModel> BuildPluginModel(const nlohmann::json& settings, const MonitorContext& context,
                                                     const std::string& pointer);

}  // namespace armfault
