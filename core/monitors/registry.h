// The registry of monitor types: one table row per type (core/monitors/registry.cc). A campaign
// or run file names its monitor,
//     "monitor": {"type": "power_efficiency", ...that type's settings}
// ("type" absent: power_efficiency, so every older file keeps working; a string: the name of a
// JSON file holding that object). Every place that builds a monitor — the runner, `trace`,
// `trace --run`, `thesis`, the report, the bench — asks here, and scoring reads only what the
// monitor emits (MonitorOutput). See docs/monitor-api.md.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "core/base/json_input.h"
#include "core/monitors/monitor.h"
#include "core/monitors/power_monitor.h"
#include "core/plant/robot/robot_config.h"

namespace armfault {

// What a monitor may know before it sees a run: the robot as designed (datasheet values, not
// a unit's draw), the tolerances the datasheet states, and whether each unit is commissioned
// first. Never a run's truth.
struct MonitorContext {
  RobotConfig robot;                // nominal
  bool has_tolerances = false;      // the campaign states datasheet tolerances ...
  StatedTolerances stated;          // ... these (zeros when it does not)
  bool commissioning = false;       // each unit runs a healthy commissioning motion first
  InputContext input;               // where relative file names (a plugin library) resolve
};

class MonitorModel;

// One robot unit's healthy commissioning run, streamed to a monitor tick by tick (never the
// whole recording at once): made by MonitorModel::BeginCommissioning,
// given every controller tick in time order, then End once. Used by one thread. What the
// monitor learned becomes the unit's model, which the framework keeps once per unit and shares
// read-only by every run of that unit on any thread (campaigns/running/run_pipeline.h, UnitMonitors).
// A monitor's failure (its code raising, returning an error) throws MonitorFailure; the unit's
// runs then fail with it.
class CommissioningSink {
 public:
  virtual ~CommissioningSink() = default;
  virtual void Tick(double t_s, const std::vector<JointSignals>& joints) = 0;
  // After the last tick (at t_end_s): the model of the unit; nullptr: the campaign's model.
  virtual std::shared_ptr<const MonitorModel> End(double t_end_s) = 0;
};

// A configured monitor: built once per campaign or run file, immutable, shared read-only by
// every run and thread (the model; the per-run state lives in the HealthMonitor it makes).
class MonitorModel {
 public:
  virtual ~MonitorModel() = default;
  virtual std::string type() const = 0;
  // Where the monitor's code comes from, for messages: a plugin's library path, a Python
  // monitor's "module.Class"; "" for a built-in type (its type names it).
  virtual std::string source() const { return ""; }
  // Starts streaming one unit's healthy commissioning run (signals only; ticks every
  // control_dt_s) to the monitor. nullptr: this monitor learns nothing from commissioning.
  virtual std::unique_ptr<CommissioningSink> BeginCommissioning(double control_dt_s) const {
    (void)control_dt_s;
    return nullptr;
  }
  // Whether BeginCommissioning gives a sink (without running anything): false for a monitor
  // that learns nothing from commissioning, whose campaign then says so (CampaignWarnings).
  virtual bool LearnsFromCommissioning() const { return false; }
  // A fresh monitor for one run, used by one thread.
  virtual std::unique_ptr<HealthMonitor> NewMonitor() const = 0;
};

// A "monitor" value, parsed: the type and its settings as resolved (defaults filled in), which
// campaign.json and the campaign hash record.
struct MonitorSpec {
  std::string type = "power_efficiency";
  nlohmann::json settings = nlohmann::json::object();
  // The "monitor" value to write back: power_efficiency settings alone (the older shape, so a
  // campaign's hash does not change), other types {"type": ..., settings...}.
  nlohmann::json ToJson() const;
};

// Parses a "monitor" value (object, or a file name relative to context.base_dir). Unknown
// types and bad settings are InputErrors naming the file, the pointer and the value.
MonitorSpec MonitorSpecFromJson(const nlohmann::json& value, const std::string& pointer, const InputContext& context);

// Builds the model of a parsed spec for a robot. Errors (a plugin that does not load) are
// InputErrors naming `pointer` and the cause.
std::shared_ptr<const MonitorModel> MakeMonitorModel(const MonitorSpec& spec, const MonitorContext& context,
                                                     const std::string& pointer = "/monitor");

// A host that can run a type's code installs the builder of its models: the Python package
// (python/src/module.cc) for "python", whose monitors only an interpreter can make. Installed
// before any campaign is read, on one thread (the package does it when imported); MakeMonitorModel
// then calls it in place of the type's own builder, which without a host says where the type
// runs. Errors are InputErrors naming `pointer` and the cause, as for any builder.
using MonitorHostBuilder = std::shared_ptr<const MonitorModel> (*)(const nlohmann::json& settings,
                                                                   const MonitorContext& context,
                                                                   const std::string& pointer);
void SetMonitorHost(const std::string& type, MonitorHostBuilder builder);

// True for a type whose model runs the user's own code when built (a plugin library's
// constructors and armfault_monitor_create, a Python class): `validate` builds it only when asked.
bool MonitorRunsUserCode(const std::string& type);

// The registered types, in table order, with a one-line description each.
struct MonitorTypeInfo {
  std::string type;
  std::string description;
};
std::vector<MonitorTypeInfo> MonitorTypes();

// The built-in power-efficiency monitor as a registered type: its settings are MonitorConfig
// (docs/monitor.md); without commissioning, on a campaign that states tolerances, its limits
// widen by what those tolerances can bias (WidenedForTolerances).
class PowerEfficiencyModel : public MonitorModel {
 public:
  PowerEfficiencyModel(const MonitorConfig& as_given, PowerMonitorModel model);
  std::string type() const override { return "power_efficiency"; }
  // Fits the unit as the ticks come, keeping no recording (PowerMonitorCommissioning,
  // core/monitors/commissioning.h says what it keeps); End gives the unit's model.
  std::unique_ptr<CommissioningSink> BeginCommissioning(double control_dt_s) const override;
  bool LearnsFromCommissioning() const override { return true; }
  std::unique_ptr<HealthMonitor> NewMonitor() const override;
  const MonitorConfig& as_given() const { return as_given_; }  // the settings before widening
  const PowerMonitorModel& model() const { return model_; }

 private:
  MonitorConfig as_given_;
  PowerMonitorModel model_;
};

// The settings a power-efficiency monitor given `as_given` runs with in `context` (widened for
// the stated tolerances when it is not commissioned), without building its model: what
// `armfault tune` sweeps around, from the campaign's spec alone.
MonitorConfig PowerEfficiencyConfig(const MonitorConfig& as_given, const MonitorContext& context);

}  // namespace armfault
