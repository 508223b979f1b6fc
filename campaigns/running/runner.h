// Runs a campaign's cases in parallel (oneTBB) and streams one RunRecord per line to
// DIR/results.jsonl in case order, so the file is the same for any thread count and a
// killed run resumes from its last complete line. Files in DIR:
//   campaign.json    the resolved campaign (+ version and shard), written first
//   decisions.jsonl  each run's decision statistics (DecisionLine), one line per run in the
//                    same order, written just before the run's results.jsonl line
//   results.jsonl    one line per run, appended in case order as runs finish
// The summary, junit.xml and the rest are written from results.jsonl by the one table of the
// run directory's outputs (campaigns/running/run_outputs.h, FinishRunDirectory).
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/early_stop.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/running/run_pipeline.h"
#include "campaigns/scoring/run_record.h"
#include "core/base/exit_gate.h"
#include "core/plant/simulation.h"

namespace armfault {


struct RunnerOptions {
  std::string output_dir = "out";
  int threads = 0;  // 0: all cores
  ShardSpec shard;
  bool resume = false;
  // Called after each run is written, with runs done (including resumed ones) and the total.
  std::function<void(long done, long total)> progress;
  // Set (from a signal handler, say) to stop: no run starts after it, the runs in flight
  // finish and are written, and the result says `interrupted`. May be null.
  const std::atomic<bool>* stop = nullptr;
  // Held while a run's lines are written, so that a signal handler ending the process at once
  // (a second Ctrl-C) never cuts them. May be null.
  ExitGate* exit_gate = nullptr;
  // Stop as soon as every floor is decided (campaigns/scoring/early_stop.h); not with a shard.
  std::optional<EarlyStopOptions> early_stop;
};

struct RunnerResult {
  long total = 0;    // cases in this shard
  long resumed = 0;  // found complete in results.jsonl and decisions.jsonl and not run again
  long ran = 0;
  long failed = 0;   // in the whole results file
  bool interrupted = false;  // stopped before every case ran (RunnerOptions::stop)
  nlohmann::json early_stop;  // --early-stop: what early_stop.json holds (null otherwise)
};
// The lines `run` prints about an early stop: the runs saved and each floor's decision.
std::string EarlyStopSummaryLine(const nlohmann::json& early_stop_json);

RunnerResult RunCampaign(const Campaign& campaign, const RunnerOptions& options);

}  // namespace armfault
