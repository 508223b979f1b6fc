// `armfault merge DIR... -o DIR`: the shards of one campaign joined into the outputs of an
// unsharded run (campaigns/merge.h), then scored like `armfault run`.
#include <sys/resource.h>

#include <cstdio>

#include "app/commands.h"
#include "campaigns/runner.h"
#include "campaigns/merge.h"

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
  const int status = FinishCampaignOutputs(o.output_dir, merged.campaign);
  std::printf("wrote %s/campaign.json, results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml\n",
              o.output_dir.c_str());
  return status;
}

}  // namespace armfault
