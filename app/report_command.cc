// `armfault report DIR`: the campaign report, DIR/report.html and DIR/report.md
// (reports/campaign_report.h).
#include <cstdio>

#include "app/commands.h"
#include "reports/campaign_report.h"

namespace armfault {

int ReportCommand(const ReportCommandOptions& o) {
  ReportOptions options;
  options.dir = o.dir;
  options.run_id = o.run_id;
  options.output = o.output;
  const ReportPaths paths = WriteCampaignReport(options);
  std::printf("wrote %s and %s\n", paths.html.c_str(), paths.markdown.c_str());
  return 0;
}

}  // namespace armfault
