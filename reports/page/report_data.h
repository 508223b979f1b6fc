// What the campaign report (reports/page/campaign_report.h) shows, gathered from an output directory
// (report_data.cc): the files read, the as-run detection per family, the runs listed, and one
// run re-simulated. The page's sections (report_sections.h) read only this.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/thesis/thesis.h"
#include "campaigns/data/twin_compare.h"
#include "core/monitors/monitor.h"

namespace armfault {

// DIR/tuning.json, or nullopt when there is none. Throws InputError if it is not JSON. The
// report's only source of tuning results, so that it can be swapped for a call into the tuner.
std::optional<nlohmann::json> ReadTuning(const std::string& dir);
// DIR/tuning.json, else the tuner's result with its defaults (TuneCampaignDir, not written
// to DIR): what `armfault report` shows.
std::optional<nlohmann::json> TuningOrDefault(const std::string& dir);

struct ReportOptions {
  std::string dir = "out";
  // The run whose time series is plotted (a run_id); empty: the first faulty run that was
  // missed, else the first detected faulty run, else the first run (case order).
  std::string run_id;
  // The HTML file; empty: DIR/report.html. The Markdown goes beside it with the extension .md.
  std::string output;
  std::function<std::optional<nlohmann::json>(const std::string& dir)> tuning = TuningOrDefault;
  unsigned long long thesis_seed = 1;  // when DIR/thesis.json is missing
  // `--twin`: a twin run along one recorded run's reference, against the recording (a section
  // of its own; without it the page is as before). Its recorded_dir empty: DIR when it holds a
  // manifest.jsonl (an export or import), else the source DIR/replay.json names (replay's
  // output), else DIR's parent (replay's default output is SRC/replayed).
  std::optional<TwinCompareOptions> twin;
};

// One run re-simulated with RunCase (campaigns/running/run_pipeline.h), which hands back its own
// monitor's output.
struct RunSeries {
  std::string run_id;
  std::string why;                  // how the run was chosen, for the page
  RunRecord record;                 // as re-simulated
  std::optional<RunRecord> stored;  // its line in results.jsonl, to show they agree
  std::vector<int> joints;          // plotted joints (1-based): every joint, the faulted one first
  std::vector<double> t_s;          // controller ticks
  // Per plotted joint (same order as `joints`), per tick.
  std::vector<std::vector<double>> i_cmd_A, i_supply_A, tau_sensor_Nm;
  MonitorOutput monitor;
  std::optional<double> first_alarm_s;  // the monitor's first alarm (before the onset too)
  std::string first_alarm_family;
  std::string error;                // set when the run could not be re-simulated
};

// Re-simulates one case, recording every joint's signals.
RunSeries SimulateRunSeries(const Campaign& campaign, const CaseSpec& spec);

// Detection as run, per family, from results.jsonl: the outcome of every faulty run against
// its magnitude (numeric, or named: a stuck sensor's lead).
struct PodAsRun {
  struct Cell {
    long runs = 0, detected = 0;
    // The first kMaxListed run ids of each outcome (case order), for the plotted dots.
    std::vector<std::string> hit_ids, miss_ids;
    std::vector<int> hit_joints, miss_joints;  // their faulted joints (1-based), same order
  };
  static constexpr size_t kMaxListed = 40;
  std::string magnitude_key;             // "" when no run has a numeric magnitude
  std::string name_key;                  // "lead" or "kind" for named magnitudes
  std::map<double, Cell> by_magnitude;   // runs with a numeric magnitude
  std::map<std::string, Cell> by_name;   // the others, by PodCategory ("" when none)
  std::vector<double> severities;        // per run with severity > 0, for the fit
  std::vector<bool> hits;
};

struct ReportData {
  std::string dir;
  nlohmann::json summary;               // summary.json
  std::optional<nlohmann::json> tuning; // tuning.json, or the tuner's defaults computed now
  std::string tuning_source;            // where `tuning` came from, or why there is none
  std::string campaign_hash;            // the one campaign of the files ("" when none names one)
  std::vector<std::string> hashed_files;  // the files that carry it (for the page)
  std::map<std::string, PodAsRun> pod;  // per family, as run
  // From results.jsonl: latencies of detected faulty runs and the misses, per family.
  std::map<std::string, std::vector<double>> latencies_s;
  // The run (id, faulted joint) of each latency, same order as latencies_s.
  std::map<std::string, std::vector<std::pair<std::string, int>>> latency_runs;
  std::map<std::string, long> misses;
  long records = 0;
  // Runs scored wrong (missed, wrong family or joint, healthy runs that alarmed) with the
  // record's reason, and runs whose fault could not act: the first kListedRuns of each.
  struct ListedRun {
    std::string run_id, reason;
  };
  static constexpr size_t kListedRuns = 50;
  std::vector<ListedRun> wrong, not_excited;
  long wrong_count = 0, not_excited_count = 0;
  bool not_excited_included = false;  // the campaign scores them like any other run
  // DIR/boundary.json (`armfault boundary`), when there: each cell's detection-probability fit
  // and its boundary, drawn in a section of its own. Without it the page is as before.
  std::optional<nlohmann::json> boundary;
  std::vector<ThesisRow> table_5_3;     // K_T factor 1 ... 0.5
  std::string thesis_source;            // "DIR/thesis.json" or "simulated, seed 1"
  RunSeries run;
  // The missed and misnamed faulty runs (the faulty ones of `wrong`, case order), the first
  // kSmallMultiples re-simulated, each with its record's reason as `why`: one small plot each.
  static constexpr size_t kSmallMultiples = 12;
  std::vector<RunSeries> wrong_runs;
  // Set for a replay of an import (DIR/replay.json): why the sections that re-simulate a run
  // from campaign.json (one run, the missed runs) are empty.
  std::string recorded_runs;
  // ReportOptions::twin's comparison, when asked for.
  std::optional<TwinComparison> twin;
};

// Reads everything the report shows and re-simulates the chosen run. Throws InputError for a
// missing or invalid summary.json, campaign.json or results.jsonl, or an unknown run_id; with
// a twin, for what CompareRecordedRun refuses and a recorded directory that is not found.
ReportData GatherReportData(const ReportOptions& options);

}  // namespace armfault
