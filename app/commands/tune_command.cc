// `armfault tune DIR`: re-scores threshold settings from a campaign's stored decision
// statistics, picks an operating point and writes the tuned monitor.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "app/commands/commands.h"
#include "campaigns/running/runner.h"
#include "campaigns/tuning/tuning.h"
#include "core/base/json_input.h"

namespace armfault {

namespace {

std::string RateText(const nlohmann::json& r) {
  if (r["value"].is_null()) return "n/a";
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.3f [%.3f, %.3f] (%ld/%ld)", r["value"].get<double>(), r["low"].get<double>(),
                r["high"].get<double>(), r["count"].get<long>(), r["runs"].get<long>());
  return buf;
}

// "; 32 not excited, left out" (the runs outside every rate, as `run` counts them), or "".
std::string LeftOutText(const TuningResult& r) {
  std::string text;
  if (r.not_excited > 0) text += "; " + std::to_string(r.not_excited) + " not excited, left out";
  if (r.not_injected > 0) text += "; " + std::to_string(r.not_injected) + " not injected, left out";
  if (r.compound > 0) text += "; " + std::to_string(r.compound) + " compound, left out (tune scores single faults)";
  return text;
}

void PrintPoint(const char* title, const nlohmann::json& p, const std::string& left_out) {
  std::printf("%s: %s\n", title, p["setting"].dump().c_str());
  std::printf("  detection %s%s\n  false alarms %s\n  isolation %s\n", RateText(p["detection_rate"]).c_str(),
              left_out.c_str(), RateText(p["false_alarm_rate"]).c_str(), RateText(p["isolation_accuracy"]).c_str());
}

}  // namespace

int TuneCommand(const TuneCommandOptions& o) {
  TuneOptions options;
  options.sweep = o.sweep;
  options.rule.kind = OperatingRuleKind(o.rule);
  if (!(o.false_alarm_ceiling >= 0 && o.false_alarm_ceiling <= 1)) {
    throw InputError("--false-alarm-ceiling", "", "expected a rate from 0 to 1, got " + std::to_string(o.false_alarm_ceiling));
  }
  if (!(o.miss_cost >= 0 && o.false_alarm_cost >= 0)) {
    throw InputError("--miss-cost", "", "costs must be >= 0");
  }
  options.rule.false_alarm_ceiling = o.false_alarm_ceiling;
  options.rule.miss_cost = o.miss_cost;
  options.rule.false_alarm_cost = o.false_alarm_cost;
  options.threads = o.threads;

  const auto start = std::chrono::steady_clock::now();
  const TuningResult r = TuneCampaignDir(o.dir, options);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::filesystem::path dir(o.dir);
  const std::string monitor_path = o.monitor_output.empty() ? (dir / "tuned-monitor.json").string() : o.monitor_output;
  WriteAtomically(dir / "tuning.json", r.report.dump(2) + "\n");
  WriteAtomically(monitor_path, r.tuned_monitor.dump(2) + "\n");

  std::printf("scored %ld threshold settings on %ld runs in %.2f s (rule %s)\n", r.settings, r.runs, seconds,
              r.report["rule"].dump().c_str());
  PrintPoint("as run", r.report["default_point"], LeftOutText(r));
  PrintPoint("operating point", r.report["operating_point"], LeftOutText(r));
  const nlohmann::json& sel = r.report["selection"];
  std::printf("operating point chosen on: %s\n", sel["split"].get<std::string>().c_str());
  if (sel.contains("held_out")) {
    std::printf("  on the runs it was chosen on: detection %s, false alarms %s\n",
                RateText(sel["chosen_on"]["detection_rate"]).c_str(), RateText(sel["chosen_on"]["false_alarm_rate"]).c_str());
    std::printf("  on the held-out runs (honest): detection %s, false alarms %s\n",
                RateText(sel["held_out"]["detection_rate"]).c_str(), RateText(sel["held_out"]["false_alarm_rate"]).c_str());
  }
  for (const auto& w : r.report["warnings"]) std::printf("warning: %s\n", w.get<std::string>().c_str());
  // AUCs cover only the measured false-alarm range (nothing extrapolated); curves that were
  // not swept have none.
  std::string aucs, unswept;
  for (const auto& [name, roc] : r.report["roc"].items()) {
    if (!roc.value("swept", false)) {
      unswept += (unswept.empty() ? "" : ", ") + name;
    } else if (roc["auc"].is_number()) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s%s %.3f over false alarms %.3g-%.3g", aucs.empty() ? "" : ", ", name.c_str(),
                    roc["auc"].get<double>(), roc["auc_false_alarm_range"][0].get<double>(),
                    roc["auc_false_alarm_range"][1].get<double>());
      aucs += buf;
    } else {
      aucs += (aucs.empty() ? "" : ", ") + name + " (no AUC: one false-alarm rate)";
    }
  }
  std::printf("ROC AUC (measured range only): %s\n", aucs.empty() ? "none" : aucs.c_str());
  if (!unswept.empty()) std::printf("not swept (no threshold of their own, or one point): %s\n", unswept.c_str());
  for (const auto& [family, pod] : r.report["detection_probability"].items()) {
    const nlohmann::json& fit = pod["fit"];
    if (fit.is_null()) continue;
    std::string a90_95 = "not reached in the tested range";
    if (fit.value("ok", false) && !fit["a90_95"].is_null()) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s = %.3g", pod["magnitude_key"].get<std::string>().c_str(),
                    fit["a90_95"]["magnitude"].get<double>());
      a90_95 = buf;
    } else if (!fit.value("ok", false)) {
      a90_95 = "no fit (" + fit.value("reason", std::string()) + ")";
    }
    std::printf("90 %% detection at 95 %% confidence, %s: %s\n", family.c_str(), a90_95.c_str());
  }
  if (r.report.contains("rate_calibration")) {
    // The sequential decision: the rate each target was set for beside the one measured.
    std::printf("false alarms per healthy hour, set for -> measured (exact 95 %% interval), detection, median latency:\n");
    for (const auto& p : r.report["rate_calibration"]["points"]) {
      const double target = p["target_per_hour"].get<double>();
      if (p["measured_per_hour"].is_null()) {
        std::printf("  %g /h: no healthy hours\n", target);
        continue;
      }
      auto g3 = [](const nlohmann::json& x, const char* unit) {
        if (x.is_null()) return std::string("-");
        char buf[48];
        std::snprintf(buf, sizeof buf, "%.3g%s", x.get<double>(), unit);
        return std::string(buf);
      };
      const std::string latency = g3(p["median_latency_s"], " s");
      const std::string detection = g3(p["detection_rate"], "");
      std::printf("  %g /h -> %.3g /h [%.3g, %.3g] (%ld in %.3g h: %s the target's 95 %% interval [%ld, %ld]), detection %s, %s\n",
                  target, p["measured_per_hour"].get<double>(), p["measured_interval_per_hour"][0].get<double>(),
                  p["measured_interval_per_hour"][1].get<double>(), p["false_alarms"].get<long>(),
                  p["healthy_hours"].get<double>(), p["consistent"].get<bool>() ? "inside" : "outside",
                  p["target_count_interval"][0].get<long>(), p["target_count_interval"][1].get<long>(), detection.c_str(),
                  latency.c_str());
    }
  }
  std::printf("campaign %s\n", r.report["campaign_hash"].get<std::string>().c_str());
  std::printf("wrote %s and %s\n", (dir / "tuning.json").string().c_str(), monitor_path.c_str());
  return 0;
}

}  // namespace armfault
