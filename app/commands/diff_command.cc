// `armfault diff DIR_A DIR_B`: what changed between two campaign results, with significance
// tests (reports/campaign_diff.h).
#include <cstdio>
#include <string>

#include "app/commands/commands.h"
#include "campaigns/running/runner.h"
#include "reports/campaign_diff.h"

namespace armfault {

int DiffCommand(const DiffCommandOptions& o) {
  DiffOptions options;
  options.alpha = o.alpha;
  options.rate_tolerance = o.tolerance;
  options.latency_tolerance_s = o.latency_tolerance_s;
  CheckDiffOptions(options);
  const CampaignResults a = ReadCampaignResults(o.dir_a);
  const CampaignResults b = ReadCampaignResults(o.dir_b);
  const DiffResult diff = DiffCampaigns(a, b, options);

  for (const std::string& w : diff.warnings) std::fprintf(stderr, "armfault: warning: %s\n", w.c_str());
  if (!diff.same_campaign) std::fprintf(stderr, "armfault: warning: %s\n", DiffCampaignLine(diff).c_str());
  std::fputs(DiffToText(diff).c_str(), stdout);
  if (!o.json_output.empty()) {
    WriteAtomically(o.json_output, DiffToJson(diff).dump(2) + "\n");
    std::printf("wrote %s\n", o.json_output.c_str());
  }
  if (!o.markdown_output.empty()) {
    WriteAtomically(o.markdown_output, DiffToMarkdown(diff));
    std::printf("wrote %s\n", o.markdown_output.c_str());
  }
  return diff.AnyWorse() ? 1 : 0;
}

}  // namespace armfault
