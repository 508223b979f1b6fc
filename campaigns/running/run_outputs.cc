#include "campaigns/running/run_outputs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

namespace armfault {

namespace fs = std::filesystem;

namespace {

std::string MedianText(std::vector<double> v) {
  if (v.empty()) return "-";
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f s", n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2);
  return buf;
}

void PrintFloor(const char* name, bool met, const std::string& message) {
  std::printf("floor %-50s %s  %s\n", name, met ? "met   " : "MISSED", message.c_str());
}

}  // namespace

FinishedRunDir FinishRunDirectory(const fs::path& dir, const CampaignSpec& campaign, const FinishOptions& options) {
  RecordOutputOptions record_options;
  record_options.monitor_cost = options.monitor_cost;
  FinishedRunDir out{0, WriteRecordOutputs(dir, campaign, options.summary_only, record_options)};
  if (options.summary_only) RemoveNotKeptBySummaryOnly(dir);
  const SummaryBuilder& builder = out.written.summary;
  if (builder.not_excited_runs() > 0) {
    std::printf("%ld runs not excited (their fault could not act; %s): see not_excited_runs in %s\n",
                builder.not_excited_runs(), campaign.include_not_excited ? "scored, as the campaign asks" : "left out of the rates",
                (dir / run_dir::kSummary).string().c_str());
  }
  if (builder.not_injected_runs() > 0) {
    std::printf("%ld runs not injected (their onset condition never fired; left out of the rates): see not_injected_runs in %s\n",
                builder.not_injected_runs(), (dir / run_dir::kSummary).string().c_str());
  }
  for (const auto& [joint, tally] : builder.sensor_saturation()) {
    // Saturation is no fault, but the built-in monitor cannot read the sensor there.
    std::fprintf(stderr,
                 "armfault: warning: joint %d's torque went beyond its torque sensor's range in %ld of %ld runs (up to "
                 "%.2f s in one; sensor_saturated_s in results.jsonl): a saturated reading is no evidence for the "
                 "built-in monitor; widen torque_sensor/full_scale_Nm or ease the motion\n",
                 joint, tally.runs, builder.runs(), tally.longest_s);
  }
  // Per joint, compactly: where the misses, misnamings and false alarms are (summary.json
  // "per_joint"; per family x joint there and in junit.xml).
  const std::map<int, internal::SummaryTally> joints = builder.JointTallies();
  if (!joints.empty()) std::printf("per joint (summary.json per_joint, per_family_joint, confusion_by_joint):\n");
  for (const auto& [joint, t] : joints) {
    std::printf("  joint %d: detection %ld/%ld, isolation %ld/%ld, latency median %s, false alarms naming it %ld/%ld%s\n",
                joint, t.detected, t.faulty, t.isolated, t.detected, MedianText(t.latencies_s).c_str(), t.healthy_alarms,
                t.healthy,
                t.not_excited > 0 ? ("; " + std::to_string(t.not_excited) + " not excited" +
                                     (campaign.include_not_excited ? " (scored)" : ", left out")).c_str()
                                  : "");
  }
  // `replay` prints its own, over the hours it replayed (alarms_per_hour.json).
  if (builder.healthy_runs() > 0 && !fs::exists(dir / run_dir::kAlarmsPerHour)) {
    std::printf("%s (summary.json healthy_operation)\n", HealthyOperationOf(builder, campaign.duration_s, StatedFalseAlarmsPerHour(campaign)).Line().c_str());
  }
  bool all_met = true;
  for (const FloorVerdict& v : out.written.verdicts) {
    PrintFloor(v.name.c_str(), v.met, v.message);
    bool met = v.met;
    const auto& decided = out.written.early_stop_decided;
    if (auto it = decided.find(v.name); it != decided.end() && it->second != v.met) {
      // Decided on the runs up to its decision; the runs made after it for other floors moved
      // the rate across the bound. The decision is the prediction for the whole campaign.
      std::printf("      early stop decided this floor %s for the whole campaign; the exit status follows that\n",
                  it->second ? "met" : "missed");
      met = it->second;
    }
    all_met = all_met && met;
  }
  if (builder.failed_runs() > 0) {
    // The first failure with its reason: a count alone is easy to miss and says nothing.
    std::fprintf(stderr, "armfault: %ld of %ld runs failed (see %s); first failed %s\n", builder.failed_runs(),
                 builder.runs(), (dir / run_dir::kSummary).string().c_str(), builder.FirstFailureText().c_str());
    out.status = 3;
  } else {
    out.status = all_met ? 0 : 1;
  }
  return out;
}

int ReportMonitorCost(const FinishedRunDir& finished, const std::string& monitor_type, bool mean_line) {
  int status = finished.status;
  if (!finished.written.monitor_cost) return status;
  const nlohmann::json& cost = *finished.written.monitor_cost;
  if (mean_line && !cost["mean_us_per_tick"].is_null()) {
    const nlohmann::json& heap = cost["heap_bytes"];
    std::printf("monitor %s: %.3f us per tick on average (run medians %.3f us, 99th percentiles %.3f us), %s heap%s\n",
                monitor_type.c_str(), cost["mean_us_per_tick"].get<double>(), cost["median_of_run_medians_us"].get<double>(),
                cost["median_of_run_p99s_us"].get<double>(),
                heap.is_number()
                    ? (std::to_string(static_cast<long>(std::lround(heap.get<double>() / 1024))) + " KiB").c_str()
                    : "unmeasured",
                " (monitor_cost.json)");
  }
  if (cost.contains("floor")) {
    const bool met = cost["floor"]["met"].get<bool>();
    PrintFloor("monitor_us_per_tick", met, cost["floor"]["message"].get<std::string>());
    if (!met && status == 0) status = 1;
  }
  return status;
}

}  // namespace armfault
