// Threshold tuning from a campaign's stored decision statistics, without simulating again
// (`armfault tune DIR`). Every run's line of decisions.jsonl (inline in results.jsonl before
// it had a file of its own) carries the held statistics of the power monitor's swept
// detectors (core/monitors/detector_statistics.h); re-scoring a threshold setting is exact: the same
// decision rule the monitor ran, on the same numbers.
//
// Outputs (docs/tuning.md): the rates of every setting of a grid of worn limits, the ROC
// frontier overall and per swept detector with its AUC over the measured points only (curves
// that were not swept have none), the campaign hash, detection probability against magnitude
// at the chosen operating point (a logistic hit/miss fit in log severity with a 95 % band,
// a90 and a90/95 as in MIL-HDBK-1823A), latency against each detector's threshold, and a
// tuned monitor JSON.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <string>
#include <vector>

#include "core/monitors/detector_statistics.h"
#include "core/monitors/power_monitor.h"
#include "campaigns/scoring/pod.h"
#include "campaigns/scoring/tune_options.h"

namespace armfault {

// One swept worn limit, "kt_factor.worn" etc., and its values.
struct SweepAxis {
  Detector detector = Detector::kKtFactor;
  std::vector<double> worn_values;
};
// The grid of settings: one worn-limit axis per detector (in Detector order) times the
// significance (standard errors) all detectors share.
struct SweepGrid {
  std::vector<SweepAxis> axes;
  std::vector<double> significance;
};
// Indices of one setting: the axes in Detector order, then the significance.
using SettingIndex = std::array<int, kDetectorCount + 1>;

// The default grid around a monitor's limits, or one edited by a spec:
// "kt_factor.worn=0.85:0.99:15,friction_factor.worn=1.3,significance=2:5:7" (FROM:TO:STEPS,
// inclusive; or one value). The monitor's own values are always included. Throws InputError
// (source "--sweep") on a bad spec.
SweepGrid MakeSweepGrid(const MonitorConfig& base, const std::string& spec);
long SettingCount(const SweepGrid& grid);

struct TuningResult {
  nlohmann::json report;       // DIR/tuning.json
  MonitorConfig tuned;         // power_efficiency: the campaign's monitor with the operating point's limits
  // What tuned-monitor.json holds: MonitorConfigToJson(tuned) for power_efficiency; for a monitor
  // that publishes statistics, its "monitor" value with each threshold written at its setting.
  nlohmann::json tuned_monitor;
  long settings = 0;
  long runs = 0;  // scored
  // Left out of every rate (as summary.json): not excited (0 when the campaign includes them),
  // not injected (a conditional onset that never fired).
  long not_excited = 0, not_injected = 0;
  // Compound runs (several faults at once), which summary.json scores but tune does not (no
  // single family or magnitude to re-score and fit): the one difference left between them.
  long compound = 0;
};

// Reads DIR/campaign.json, DIR/results.jsonl and DIR/decisions.jsonl (line for line, of the
// same runs; without it, results.jsonl's inline "decision", as older versions wrote). Throws
// InputError naming the file and line on missing, malformed, cut or mismatched input, when
// no decision statistics are stored, when a run's stored decision does not reproduce its
// recorded outcome (results of another monitor version), or when the directory mixes
// campaigns: a summary.json whose campaign hash is not campaign.json's, or a results.jsonl
// line that is not a case of campaign.json (campaigns/scoring/provenance.h). The report carries
// "campaign_hash".
TuningResult TuneCampaignDir(const std::string& dir, const TuneOptions& options);

}  // namespace armfault
