// The end of every command that writes a run directory (`run`, `merge`, `replay`, `score`,
// `boundary`, `export --score`): the outputs written from results.jsonl, one table of writers
// (campaigns/running/run_dir.h, RecordOutputs: results.csv, summary.json, junit.xml,
// monitor_cost.json), then the console lines every command prints of them: the runs not excited
// or not injected, saturated sensors, the per-joint tallies, healthy operation, each floor, the
// first failed run, the monitor's cost.
//
// Exit status, as every command returns it: 0 every floor met; 1 a floor missed (with
// --early-stop, as the floor's decision says); 3 a run failed.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>

#include "campaigns/running/run_dir.h"

namespace armfault {

// How one command finishes its directory.
struct FinishOptions {
  bool summary_only = false;  // `run --summary-only`: write and keep only what it keeps
  // monitor_cost.json (RecordOutputOptions): from DIR/monitor_cost.jsonl, with this heap figure.
  MonitorCostInput monitor_cost;
};

struct FinishedRunDir {
  int status = 0;  // 0, 1 or 3 (above), from the floors and the runs
  RecordOutputsResult written;
};

// Writes every output of DIR's results.jsonl (WriteRecordOutputs), removes what --summary-only
// does not keep, and prints the floors and tallies. An InputError from a write names the file.
FinishedRunDir FinishRunDirectory(const std::filesystem::path& dir, const CampaignSpec& campaign,
                                  const FinishOptions& options);

// The monitor's cost line (`run`: mean, run medians and 99th percentiles, heap) when `mean_line`,
// and its floor's line when monitor_cost.json has one; returns `status` made 1 by a missed floor.
int ReportMonitorCost(const FinishedRunDir& finished, const std::string& monitor_type, bool mean_line);

}  // namespace armfault
