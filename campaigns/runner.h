// Runs a campaign's cases in parallel (oneTBB) and streams one RunRecord per line to
// DIR/results.jsonl in case order, so the file is the same for any thread count and a
// killed run resumes from its last complete line. Files in DIR:
//   campaign.json   the resolved campaign (+ version and shard), written first
//   results.jsonl   one line per run, appended in case order as runs finish
// The summary and junit.xml are written by the caller from results.jsonl (reports/).
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "campaigns/campaign.h"
#include "campaigns/run_record.h"
#include "core/simulation.h"

namespace armfault {

struct ShardSpec {
  int index = 0;  // 0-based
  int count = 1;
  bool Contains(long case_index) const { return case_index % count == index; }
};

struct RunnerOptions {
  std::string output_dir = "out";
  int threads = 0;  // 0: all cores
  ShardSpec shard;
  bool resume = false;
  // Called after each run is written, with runs done (including resumed ones) and the total.
  std::function<void(long done, long total)> progress;
};

struct RunnerResult {
  long total = 0;    // cases in this shard
  long resumed = 0;  // found complete in results.jsonl and not run again
  long ran = 0;
  long failed = 0;   // in the whole results file
};

RunnerResult RunCampaign(const Campaign& campaign, const RunnerOptions& options);

// One case, fully: builds the varied robot, the faults and the monitor, simulates, diagnoses.
// Never throws for a failing run: the record says "failed" with the reason.
RunRecord RunCase(const Campaign& campaign, const CaseSpec& spec, const TickObserver& also = nullptr);

// The JSON written to campaign.json (the summary embeds `resolved` only, so shards merge to
// the same bytes).
nlohmann::json CampaignFileJson(const Campaign& campaign, const ShardSpec& shard);

// Writes `text` to `path` through a temporary file and a rename: a crash leaves the old file
// or the new one, never half of one. Throws InputError if it cannot write.
void WriteAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace armfault
