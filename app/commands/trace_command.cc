#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "core/base/output_file.h"
#include "app/commands/commands.h"
#include "campaigns/running/run_pipeline.h"
#include "core/base/json_input.h"
#include "core/monitors/power_monitor.h"
#include "core/observe.h"
#include "core/run_config.h"
#include "core/plant/simulation.h"
#include "faults/fault.h"
#include "reports/statistics_csv.h"
#include "reports/trace_csv.h"

namespace armfault {

namespace {

// Tracking and current statistics gathered from the ticks, for the printed summary.
struct JointStats {
  double sum_sq_error = 0, max_error = 0, peak_cmd = 0, sum_sq_cmd = 0;
  long count = 0;
};

nlohmann::json BuildRunJson(const TraceOptions& o, InputContext* context) {
  nlohmann::json run;
  if (o.run_file.empty()) {
    run = ThesisExperiment1Json();
    const bool overridden =
        !o.robot.empty() || o.duration_s || o.seed || !o.joint_specs.empty() || !o.fault_specs.empty();
    context->source = overridden ? "<command line>" : "<thesis experiment 1>";
  } else {
    run = ReadJsonFile(o.run_file);
    context->source = o.run_file;
    context->base_dir = std::filesystem::path(o.run_file).parent_path().string();
    if (context->base_dir.empty()) context->base_dir = ".";
    if (!run.is_object()) throw InputError(o.run_file, "", "expected a JSON object describing a run");
  }
  if (!o.robot.empty()) run["robot"] = o.robot;
  if (o.duration_s) run["duration_s"] = *o.duration_s;
  if (o.seed) run["seed"] = *o.seed;
  if (!o.joint_specs.empty() && run.contains("joints") && !run["joints"].is_object()) {
    throw InputError(context->source, "/joints",
                     "expected an object mapping joint numbers to trajectories, got " + Describe(run["joints"]));
  }
  for (const std::string& spec : o.joint_specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw InputError("--joint", "", "expected J=<trajectory JSON>, got \"" + spec + "\"");
    }
    run["joints"][spec.substr(0, eq)] = ParseJsonText(spec.substr(eq + 1), "--joint " + spec.substr(0, eq));
  }
  if (!o.fault_specs.empty() && run.contains("faults") && !run["faults"].is_array()) {
    throw InputError(context->source, "/faults", "expected an array of faults, got " + Describe(run["faults"]));
  }
  for (const std::string& spec : o.fault_specs) run["faults"].push_back(ParseJsonText(spec, "--fault"));
  return run;
}

void PrintMonitorSummary(const HealthMonitor& any) {
  const MonitorOutput& out = any.output();
  std::printf("monitor windows (used ones): joint, time [s], flow, eta, eta_m (expected), eta_e (expected)\n");
  for (const EfficiencyWindow& w : out.windows) {
    if (!w.used) continue;
    std::printf("  %d  %6.2f-%6.2f  %-8s  eta %6.3f  eta_m %6.3f (%6.3f)  eta_e %6.3f (%6.3f)\n", w.joint, w.t_start_s,
                w.t_end_s, w.flow.c_str(), w.eta, w.eta_m, w.eta_m_expected, w.eta_e, w.eta_e_expected);
  }
  // The power-efficiency monitor's estimates; another type shows its verdicts only.
  const auto* power = dynamic_cast<const PowerEfficiencyMonitor*>(&any);
  for (int j = 0; power && j < power->joint_count(); ++j) {
    const PowerEfficiencyMonitor::Estimates e = power->estimates(j);
    std::printf("  joint %d estimates: kt_factor %.4f (se %.4f), resistance_factor %.3f (se %.3f), friction_factor "
                "%.3f (se %.3f), sensor_drift %.3f N m (se %.3f), %d windows\n",
                j + 1, e.kt_factor, e.kt_factor_se, e.resistance_factor, e.resistance_factor_se, e.friction_factor,
                e.friction_factor_se, e.sensor_drift_Nm, e.sensor_drift_se, e.windows_in_fit);
  }
  for (const Verdict& v : out.verdicts) {
    std::printf("  verdict t=%.3f s joint %d: %s%s%s%s\n", v.t_s, v.joint, HealthStateName(v.state),
                v.family.empty() ? "" : (" " + v.family).c_str(),
                v.magnitude_name.empty() ? "" : (" " + v.magnitude_name + "=").c_str(),
                v.magnitude_name.empty() ? "" : FormatNumber(std::round(v.magnitude * 1e4) / 1e4).c_str());
  }
  const Diagnosis d = Diagnose(out);
  if (d.detected) {
    // The estimate the alarm gave when it was raised, and the run's last one, apart: the
    // detection time with the final magnitude would read as what was known at that time.
    const Verdict* first = nullptr;
    for (const Verdict& v : out.verdicts) {
      if (v.alarm && v.joint == d.joint && v.family == d.family && v.t_s >= d.detection_time_s) {
        first = &v;
        break;
      }
    }
    if (first && !d.magnitude_name.empty()) {
      std::printf("monitor: ALARM at %.3f s, joint %d, %s, %s %.4g at the alarm, %.4g at the end (confidence %.2f)\n",
                  d.detection_time_s, d.joint, d.family.c_str(), d.magnitude_name.c_str(), first->magnitude, d.magnitude,
                  d.confidence);
    } else {
      std::printf("monitor: ALARM at %.3f s, joint %d, %s%s%s (confidence %.2f)\n", d.detection_time_s, d.joint,
                  d.family.c_str(), d.magnitude_name.empty() ? "" : (", " + d.magnitude_name + " ").c_str(),
                  d.magnitude_name.empty() ? "" : FormatNumber(d.magnitude).c_str(), d.confidence);
    }
  } else {
    std::printf("monitor: no alarm\n");
  }
}

}  // namespace

int RunTrace(const TraceOptions& o) {
  InputContext context;
  const RunConfig run = RunConfigFromJson(BuildRunJson(o, &context), "", context);
  const ArmModel model(run.robot);
  const int n = model.joint_count();
  std::vector<std::unique_ptr<Fault>> made;
  try {
    made = MakeFaults(run.faults_json, "/faults", run.robot);
  } catch (const InputError& e) {
    throw e.WithSource(context.source);  // errors that name a file keep it
  }
  RunSpec spec = MakeRunSpec(run);
  // Conditional onsets: when each fires in this run (faults/fault.h), before the run itself.
  std::vector<Fault*> conditional;
  for (auto& fault : made) conditional.push_back(fault.get());
  ResolveConditionalOnsets(model, spec, conditional);
  std::vector<std::shared_ptr<const Fault>> faults;
  for (auto& fault : made) faults.push_back(std::move(fault));
  if (!faults.empty()) spec.hardware = std::make_shared<FaultSchedule>(faults);
  AtomicOutputFile file(o.output);  // the trace appears whole, or not at all
  TraceCsvWriter writer([&file](std::string_view text) { file.Write(text); }, n);
  std::vector<JointStats> stats(n);
  std::shared_ptr<const MonitorModel> monitor_model;
  try {
    monitor_model = MakeRunMonitor(run);
  } catch (const InputError& e) {
    throw e.WithSource(context.source);
  }
  // The run pipeline's plant, monitor and effect meters (campaigns/running/run_pipeline.h); nothing is
  // scored here, so scoring's tap needs no onset.
  // --statistics: every published statistic at every tick, whole or not at all, as the trace.
  std::unique_ptr<AtomicOutputFile> statistics_file;
  std::unique_ptr<StatisticsCsvWriter> statistics;
  if (!o.statistics_output.empty()) {
    statistics_file = std::make_unique<AtomicOutputFile>(o.statistics_output);
    statistics = std::make_unique<StatisticsCsvWriter>([&](std::string_view text) { statistics_file->Write(text); });
  }
  const ExecutedRun run_out = Execute(model, spec, faults, *monitor_model, 0.0, [&](const Tick& tick) {
    writer.Write(tick);
    for (int j = 0; j < n; ++j) {
      const JointTick& jt = (*tick.joints)[j];
      const double err = (jt.q_rad - jt.signals.q_ref_rad) * 180.0 / M_PI;
      JointStats& s = stats[j];
      s.sum_sq_error += err * err;
      s.max_error = std::max(s.max_error, std::fabs(err));
      s.peak_cmd = std::max(s.peak_cmd, std::fabs(jt.signals.i_cmd_A));
      s.sum_sq_cmd += jt.signals.i_cmd_A * jt.signals.i_cmd_A;
      ++s.count;
    }
  }, true, statistics.get());
  if (!run_out.monitor_failure.empty()) {
    std::fprintf(stderr, "armfault: error: monitor failed: %s\n", run_out.monitor_failure.c_str());
    return 3;
  }
  const RunResult& result = run_out.result;
  const HealthMonitor& monitor = *run_out.monitor;
  file.Commit();
  if (statistics_file) {
    if (!statistics->declared()) statistics->Declare({}, n);
    statistics_file->Commit();
  }
  WriteTraceChannels(o.output, n);  // what each column is, beside it

  if (!o.quiet) {
    std::printf("run: robot %s, %.3g s, seed %llu -> %s\n", run.robot.name.c_str(), run.duration_s,
                static_cast<unsigned long long>(run.seed), o.output.c_str());
    if (statistics) PrintStatistics(*statistics, o.statistics_output);
    std::printf("%-5s %12s %12s %10s %10s %10s %10s %10s %10s\n", "joint", "rms_err_deg", "max_err_deg",
                "peak_i_A", "rms_i_A", "supply_J", "copper_J", "friction_J", "mech_out_J");
    double supply = 0, losses = 0;
    for (int j = 0; j < n; ++j) {
      const JointStats& s = stats[j];
      const JointEnergy& e = result.energy[j];
      std::printf("%-5d %12.4f %12.4f %10.3f %10.3f %10.3f %10.3f %10.3f %10.3f\n", j + 1,
                  std::sqrt(s.sum_sq_error / std::max(1L, s.count)), s.max_error, s.peak_cmd,
                  std::sqrt(s.sum_sq_cmd / std::max(1L, s.count)), e.supply_J, e.copper_J, e.friction_J,
                  e.mech_out_J);
      supply += e.supply_J;
      losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
    }
    const double stored = (result.kinetic_end_J - result.kinetic_start_J) + (result.potential_end_J - result.potential_start_J);
    std::printf("energy balance: supply %.4f J = stored %.4f J + losses %.4f J; residual %.4f J (%.3f %% of supply)\n",
                supply, stored, losses, supply - stored - losses, 100.0 * (supply - stored - losses) / supply);
  }
  if (!o.quiet && !faults.empty()) {
    const std::vector<FaultEffect>& measured = run_out.effects;
    for (size_t k = 0; k < faults.size(); ++k) {
      const FaultEffect& e = measured[k];
      std::printf("fault %s -> %s: healthy %.4g, faulty %.4g: %s\n", faults[k]->ToJson().dump().c_str(),
                  e.measure.c_str(), e.healthy, e.faulty, e.took_effect ? "took effect" : ("NO EFFECT (" + e.note + ")").c_str());
      if (const FaultTiming& t = faults[k]->timing(); t.condition) {
        const std::string not_injected = NotInjectedReason(*faults[k], result.end_time_s);
        if (not_injected.empty()) {
          std::printf("  onset condition (%s) fired at %.6g s: onset %.6g s\n", t.condition->Text().c_str(), t.fired_s, t.onset_s);
        } else {
          std::printf("  NOT INJECTED: %s\n", not_injected.c_str());
        }
      }
    }
  }
  if (!o.monitor_output.empty()) {
    WriteAtomically(o.monitor_output, ToJson(monitor.output()).dump(1) + "\n");
  }
  if (!o.quiet) PrintMonitorSummary(monitor);
  if (!result.ok) {
    std::fprintf(stderr, "armfault: run failed: %s\n", result.failure_reason.c_str());
    return 3;
  }
  return 0;
}

}  // namespace armfault
