#include "campaigns/thesis/thesis.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <memory>

#include "campaigns/running/run_pipeline.h"
#include "core/monitors/power_monitor.h"
#include "core/observe.h"
#include "core/run_config.h"
#include "core/plant/simulation.h"
#include "faults/fault.h"

namespace armfault {

namespace {

constexpr int kTopJoint = 3;

struct Case {
  size_t experiment, row;
  nlohmann::json run;  // a run file, as `armfault trace` reads it
};

nlohmann::json SinePair(double amplitude_deg) {
  return {{"type", "sine_pair"}, {"amplitude_deg", amplitude_deg}, {"omega_rad_s", 8.0 / (2.0 * M_PI)}};
}

nlohmann::json KtFault(double n) {
  return nlohmann::json::array({{{"family", "kt_degradation"}, {"joint", kTopJoint}, {"kt_factor", n}, {"onset_s", 0}}});
}

// The thesis judges whole experiments, including short and slow ones (exp. 3 moves 3 deg):
// windows are kept down to 0.1 s and 0.02 J.
MonitorConfig ThesisWindows() {
  MonitorConfig c;
  c.min_window_s = 0.1;
  c.min_window_energy_J = 0.02;
  return c;
}

// eq 5-5 over the forward-flow windows of the top joint: sum tau_s dq / sum (ratio K_T i - f) dq.
// The last window may end with the run instead of at zero velocity; its kinetic energy at
// these speeds is below 1 mJ, so it counts (exp. 2 is one window that ends with the run).
void Evaluate(const MonitorOutput& out, ThesisRow* row) {
  double num = 0, den = 0;
  int n = 0;
  for (const EfficiencyWindow& w : out.windows) {
    if (w.joint != kTopJoint || w.flow != "forward" || w.t_end_s - w.t_start_s < 0.1) continue;
    num += w.out_J;
    den += w.mesh_in_J;
    ++n;
  }
  row->windows = n;
  row->armfault_pct = den > 0 ? 100.0 * num / den : NAN;
}

}  // namespace

ThesisResults RunThesisExperiments(unsigned long long seed) {
  ThesisResults results;
  results.seed = seed;
  std::vector<Case> cases;
  auto add = [&](size_t e, const std::string& label, double factor, double thesis_pct, nlohmann::json joints,
                 nlohmann::json faults) {
    ThesisRow row;
    row.label = label;
    row.factor = factor;
    row.thesis_pct = thesis_pct;
    results.experiments[e].rows.push_back(row);
    cases.push_back({e, results.experiments[e].rows.size() - 1,
                     {{"robot", "mrr-config1"}, {"duration_s", 10}, {"seed", seed}, {"joints", joints}, {"faults", faults}}});
  };

  results.experiments.push_back({"exp1", "Experiment 1: K_T degradation, top joint (table 5-3)",
                                 "joint 3: q = 25 (sin(8t/2pi) - 0.5 sin(16t/2pi)) deg, 10 s",
                                 "kt_degradation on joint 3 from t = 0 (the thesis multiplies the command by n)", {}});
  const double kt[] = {1.0, 0.9, 0.8, 0.7, 0.6, 0.5};
  const double table_5_3[] = {80.5, 73.7, 54.49, 53.4, 43.74, 38.19};
  for (int k = 0; k < 6; ++k) {
    char label[32];
    std::snprintf(label, sizeof label, "n = %g", kt[k]);
    add(0, label, kt[k], table_5_3[k], {{"3", SinePair(25)}}, k == 0 ? nlohmann::json::array() : KtFault(kt[k]));
  }

  results.experiments.push_back({"exp2", "Experiment 2: K_T degradation, top and second joints moving",
                                 "joints 2 and 3: q = 25 (1 - cos(pi t / 20)) deg, 10 s",
                                 "kt_degradation on joint 3 from t = 0", {}});
  const nlohmann::json ramp = {{"type", "cosine_ramp"}, {"amplitude_deg", 25}, {"period_s", 40}};
  add(1, "n = 1", 1.0, 62.28, {{"2", ramp}, {"3", ramp}}, nlohmann::json::array());
  add(1, "n = 0.5", 0.5, 50.96, {{"2", ramp}, {"3", ramp}}, KtFault(0.5));

  results.experiments.push_back({"exp3", "Experiment 3: mechanical degradation (spring load), top joint",
                                 "joint 3: q = 3 (sin(8t/2pi) - 0.5 sin(16t/2pi)) deg, 10 s",
                                 "spring load: brake_lock drag_fraction 0.005 (0.01 N m on the motor shaft)", {}});
  add(2, "no load", 0, 66.45, {{"3", SinePair(3)}}, nlohmann::json::array());
  add(2, "spring load", 1, 58.39, {{"3", SinePair(3)}},
      nlohmann::json::array({{{"family", "brake_lock"}, {"joint", kTopJoint}, {"drag_fraction", 0.005}, {"onset_s", 0}}}));

  const ArmModel model(RobotPreset("mrr-config1"));
  MonitorContext monitor_context;
  monitor_context.robot = model.config();
  MonitorSpec windows;  // the power-efficiency monitor with the thesis's windows
  windows.settings = MonitorConfigToJson(ThesisWindows());
  const std::shared_ptr<const MonitorModel> monitor_model = MakeMonitorModel(windows, monitor_context);
  tbb::parallel_for(size_t{0}, cases.size(), [&](size_t i) {
    const Case& c = cases[i];
    InputContext context;
    context.source = "<thesis " + results.experiments[c.experiment].id + ">";
    const RunConfig run = RunConfigFromJson(c.run, "", context);
    RunSpec spec = MakeRunSpec(run);
    std::vector<std::shared_ptr<const Fault>> faults;
    for (auto& f : MakeFaults(run.faults_json, "/faults", run.robot)) faults.push_back(std::move(f));
    if (!faults.empty()) spec.hardware = std::make_shared<FaultSchedule>(faults);
    // The run pipeline's plant and monitor (campaigns/running/run_pipeline.h); nothing here is scored.
    const ExecutedRun run_out = Execute(model, spec, faults, *monitor_model, 0.0);
    ThesisRow& row = results.experiments[c.experiment].rows[c.row];
    row.ok = run_out.result.ok && run_out.monitor_failure.empty();
    row.failure = run_out.monitor_failure.empty() ? run_out.result.failure_reason : "monitor failed: " + run_out.monitor_failure;
    if (run_out.monitor_failure.empty()) Evaluate(run_out.monitor->output(), &row);
  });
  for (ThesisExperiment& e : results.experiments) {
    for (ThesisRow& r : e.rows) {
      r.thesis_ratio = r.thesis_pct / e.rows[0].thesis_pct;
      r.armfault_ratio = r.armfault_pct / e.rows[0].armfault_pct;
    }
  }
  return results;
}

}  // namespace armfault
