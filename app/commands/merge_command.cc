// `armfault merge DIR... -o DIR`: the shards of one campaign joined into the outputs of an
// unsharded run (campaigns/running/merge.h), then scored like `armfault run`.
#include <sys/resource.h>

#include <cstdio>

#include "app/commands/commands.h"
#include "campaigns/running/runner.h"
#include "campaigns/running/merge.h"
#include "campaigns/running/monitor_cost.h"
#include "campaigns/running/run_outputs.h"

namespace armfault {

namespace {

// Merge keeps every shard's results.jsonl and decisions.jsonl open at once: lift the soft
// open-file limit to the hard one so a few thousand shards do not hit the usual default of 1024.
void RaiseOpenFileLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur < limit.rlim_max) {
    limit.rlim_cur = limit.rlim_max;
    setrlimit(RLIMIT_NOFILE, &limit);
  }
}

}  // namespace

int MergeCommand(const MergeOptions& o) {
  RaiseOpenFileLimit();
  const OutputLock lock(o.output_dir, "armfault merge");
  const MergeResult merged = MergeShards(o.input_dirs, o.output_dir);
  std::printf("campaign %s: merged %d shards, %ld runs -> %s\n", merged.campaign.name.c_str(), merged.shards,
              merged.runs, o.output_dir.c_str());
  // The monitor's cost (campaigns/running/monitor_cost.h), when every shard measured it.
  FinishOptions finish;
  finish.monitor_cost = JoinShardMonitorCost(o.input_dirs, o.output_dir);
  const bool cost = finish.monitor_cost.write;
  const FinishedRunDir finished = FinishRunDirectory(o.output_dir, merged.campaign, finish);
  const int status = ReportMonitorCost(finished, merged.campaign.monitor.type, false);
  std::printf("wrote %s/campaign.json, results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml%s\n",
              o.output_dir.c_str(), cost ? ", monitor_cost.jsonl, monitor_cost.json" : "");
  return status;
}

}  // namespace armfault
