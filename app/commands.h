// The armfault subcommands. Each returns the process exit status:
// 0 success, 1 a floor missed, 2 invalid input or usage, 3 some runs failed.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "campaigns/thesis.h"

namespace armfault {

struct TraceOptions {
  std::string run_file;                 // empty: thesis experiment 1
  std::string robot;                    // overrides the file's robot (preset name)
  std::optional<double> duration_s;     // overrides the file's duration
  std::optional<long long> seed;        // overrides the file's seed
  std::vector<std::string> joint_specs; // "J=<trajectory JSON>"
  std::vector<std::string> fault_specs; // fault JSON objects, added to the file's "faults"
  std::string output = "trace.csv";
  std::string monitor_output;           // monitor verdicts and windows as JSON (optional)
  bool quiet = false;
};
int RunTrace(const TraceOptions& options);

struct ThesisOptions {
  std::string output_dir = "out";
  unsigned long long seed = 1;
};
// Runs the thesis experiments, prints them beside the thesis figures, writes thesis.json and
// thesis.md. Exit 0 if the trend holds (table 5-3 monotonic, ratios within 0.10 of the
// thesis, experiments 2 and 3 drop), else 1.
int RunThesis(const ThesisOptions& options);

struct ThesisTrend {
  static constexpr double kRatioLimit = 0.10;
  bool monotonic = true;
  double max_ratio_deviation = 0;
  bool same_direction = true;
  bool holds() const { return monotonic && max_ratio_deviation <= kRatioLimit && same_direction; }
};
ThesisTrend CheckThesisTrend(const ThesisResults& results);

struct CampaignRunOptions {
  std::string campaign_file;   // empty: the built-in thesis sweep
  std::string output_dir = "out";
  int threads = 0;             // 0: all cores
  std::string shard;           // "K/N"; empty: SLURM_ARRAY_TASK_ID/COUNT, JOB_COMPLETION_INDEX, or all
  int shard_count = 0;         // with JOB_COMPLETION_INDEX
  bool resume = false;
  bool quiet = false;
};
// Runs a campaign and writes DIR/{campaign.json, results.jsonl, summary.json, junit.xml}.
// 0 all floors met, 1 a floor missed, 3 some runs failed.
int RunCampaignCommand(const CampaignRunOptions& options);
// Writes summary.json and junit.xml from DIR/results.jsonl; prints the floors; exit status.
struct Campaign;
int FinishCampaignOutputs(const std::string& dir, const Campaign& campaign);
int ValidateCommand(const std::string& campaign_file);
// Prints the cost of a run against bare ODE ("ratio: X") and "parallel efficiency: Y".
int BenchCommand(int repeats);

}  // namespace armfault
