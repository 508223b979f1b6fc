// `armfault export CAMPAIGN`: labeled signals for data-driven detectors; `armfault score DIR
// VERDICTS`: verdicts made offline, scored as a live monitor is (campaigns/data/export.h).
#include <cstdio>
#include <filesystem>

#include "app/commands/commands.h"
#include "app/commands/progress.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/data/export.h"
#include "campaigns/running/run_outputs.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"

namespace armfault {

int ExportCommand(const ExportCommandOptions& o) {
  const Campaign campaign = ReadCampaignFile(o.campaign_file);
  if (o.threads < 0) throw InputError("-j", "", "expected a thread count >= 1 (0: all cores), got " + std::to_string(o.threads));
  CampaignRunOptions shard;
  shard.shard = o.shard;
  shard.shard_count = o.shard_count;
  ExportOptions eo;
  eo.output_dir = o.output_dir;
  eo.threads = o.threads;
  eo.shard = ResolveShard(shard);
  eo.split = ParseSplit(o.split);
  CheckGzipLevel(o.gzip_level);
  eo.gzip_level = o.gzip_level;
  Progress progress(!o.quiet);  // the same line as `armfault run`'s
  eo.progress = [&](long done, long total) { progress.Update(done, total); };
  const OutputLock lock(o.output_dir, "armfault export " + o.campaign_file);
  const ExportResult r = ExportCampaign(campaign, eo);
  std::printf("exported %ld runs of %s (%ld failed) -> %s/manifest.jsonl, manifest.csv, runs/*.csv.gz\n", r.runs,
              campaign.name.c_str(), r.failed, o.output_dir.c_str());
  if (!o.quiet) {
    std::printf("next: pandas.read_csv(\"%s/manifest.csv\") for the labels, pandas.read_csv(\"%s/runs/000000.csv.gz\") for a run;\n"
                "      armfault score %s VERDICTS.jsonl  (scores verdicts your detector wrote)\n",
                o.output_dir.c_str(), o.output_dir.c_str(), o.output_dir.c_str());
  }
  return r.failed > 0 ? 3 : 0;
}

int ScoreCommand(const ScoreCommandOptions& o) {
  namespace fs = std::filesystem;
  const CampaignSpec campaign = ReadRunDirCampaign(o.dir);
  const std::string out = o.output_dir.empty() ? (fs::path(o.dir) / "scored").string() : o.output_dir;
  const OutputLock lock(out, "armfault score " + o.dir + " " + o.verdicts_file);
  const ScoreResult r = ScoreExternalVerdicts(campaign, o.dir, o.verdicts_file, out);
  std::printf("scored %ld verdicts on %ld runs (%ld runs without a verdict) -> %s\n", r.verdicts, r.runs,
              r.runs_without_verdicts, out.c_str());
  const int status = FinishRunDirectory(out, r.campaign, {}).status;  // the campaign of the verdicts (its monitor)
  std::printf("wrote %s/results.jsonl, results.csv, summary.json, junit.xml\nnext: armfault report %s\n", out.c_str(),
              out.c_str());
  return status;
}

}  // namespace armfault
