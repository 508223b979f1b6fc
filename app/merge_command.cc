// `armfault merge DIR... -o DIR`: the shards of one campaign joined into the outputs of an
// unsharded run (campaigns/merge.h), then scored like `armfault run`.
#include <sys/resource.h>

#include <cstdio>

#include "app/commands.h"
#include "campaigns/runner.h"
#include "campaigns/merge.h"
#include "campaigns/monitor_cost.h"

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
  int status = FinishCampaignOutputs(o.output_dir, merged.campaign);
  // The monitor's cost (campaigns/monitor_cost.h), when every shard measured it.
  const bool cost = MergeMonitorCost(o.input_dirs, o.output_dir, merged.campaign.floors.monitor_us_per_tick,
                                     merged.campaign.monitor.type);
  if (cost) {
    const nlohmann::json c = ReadJsonFile((std::filesystem::path(o.output_dir) / "monitor_cost.json").string());
    if (c.contains("floor")) {
      const bool met = c["floor"]["met"].get<bool>();
      std::printf("floor %-50s %s  %s\n", "monitor_us_per_tick", met ? "met   " : "MISSED",
                  c["floor"]["message"].get<std::string>().c_str());
      if (!met && status == 0) status = 1;
    }
  }
  std::printf("wrote %s/campaign.json, results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml%s\n",
              o.output_dir.c_str(), cost ? ", monitor_cost.jsonl, monitor_cost.json" : "");
  return status;
}

}  // namespace armfault
