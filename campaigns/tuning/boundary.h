// The detection boundary of each cell (trajectory x fault entry x joint) of a campaign with a
// "search" block (`armfault boundary`, docs/campaign-format.md "Boundary search"): the
// magnitude at which the detection probability reaches the target (0.9) at the stated
// confidence (0.95), the a90/95 of MIL-HDBK-1823A, found with few runs.
//
// The search runs in batches. Each batch gives every unfinished cell `batch` runs whose
// magnitudes are chosen from the outcomes of the earlier batches only (never from which run
// finished first), so the results are the same for any thread count. The runs are ordinary
// campaign cases: the output directory's campaign.json lists them (search.runs), results.jsonl
// holds their records, and `trace --run`, `tune`, `report` and `diff` read the directory like
// any run's. A killed search resumes (--resume) and ends with the same bytes.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/scoring/pod.h"

namespace armfault {

// One cell's runs so far: magnitudes and outcomes of its scored runs (ok, and excited unless
// the campaign includes the others), and how many runs it made in all.
struct CellData {
  std::vector<double> magnitudes;
  std::vector<bool> detected;
  long runs = 0;  // every run of the cell, failed and not excited ones too
};

// What a cell's runs so far say: the fit and its a90, a90/95 and the interval of a90.
struct CellEstimate {
  PodFit fit;
  bool has_fit = false;                  // fit.ok with a rising curve
  std::optional<double> a90;             // magnitude where the fit reaches the target
  std::optional<double> a90_95;          // where its one-sided lower bound does (the boundary)
  std::optional<double> interval_low;    // where the one-sided upper bound does: [low, a90_95] holds a90
  std::optional<double> width;           // |a90_95 - interval_low| in magnitude units
};

// The estimate from a cell's runs, over the severities it tested (never extrapolated).
CellEstimate EstimateCell(const SearchSpec& spec, const SearchEntryRange& range, const CellData& data);

// The next step of a cell: its next batch's magnitudes, or why it stops ("converged",
// "budget", "above_range", "below_range").
struct CellStep {
  std::vector<double> magnitudes;  // empty: the cell stops
  std::string status;
};
CellStep PlanCell(const SearchSpec& spec, const SearchEntryRange& range, const CellData& data);

// The z of a one-sided bound at `confidence` (1.645 at 0.95).
double OneSidedZ(double confidence);

struct BoundaryOptions {
  std::string output_dir = "out";
  int threads = 0;        // 0: all cores; never changes a result
  bool resume = false;
  int max_batches = 0;    // > 0: stop after this many batches (a later --resume continues)
  std::function<void(const std::string& line)> log;  // one line per batch
  const std::atomic<bool>* stop = nullptr;           // Ctrl-C: stop after the runs in flight
};

struct BoundaryResult {
  nlohmann::json report;  // boundary.json (written by RunBoundary unless interrupted)
  int batches = 0;
  long runs = 0;
  long resumed = 0;       // runs found complete in the directory and not run again
  long failed = 0;
  bool interrupted = false;
  bool stopped = false;   // max_batches reached before every cell finished
};

// Runs the search into options.output_dir: campaign.json (rewritten before each batch with
// the runs planned), results.jsonl, decisions.jsonl, boundary.json. Throws InputError when
// the campaign has no "search" block or --resume finds another campaign.
BoundaryResult RunBoundary(const Campaign& campaign, const BoundaryOptions& options);

// boundary.json's cells estimated from records already run (a grid run of a campaign with a
// "search" block, or a boundary directory), grouped by cell.
nlohmann::json BoundaryReport(const CampaignSpec& campaign, const std::vector<RunRecord>& records,
                              const std::vector<std::string>& statuses, int batches);

// The boundary table printed by `armfault boundary` (one line per cell).
std::string BoundaryTable(const nlohmann::json& report);

}  // namespace armfault
