// `armfault report DIR`: the campaign report, DIR/report.html and DIR/report.md
// (reports/page/campaign_report.h).
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "app/commands/commands.h"
#include "core/base/json_input.h"
#include "core/plant/robot/robot_config.h"
#include "reports/page/campaign_report.h"

namespace armfault {

int ReportCommand(const ReportCommandOptions& o) {
  ReportOptions options;
  options.dir = o.dir;
  options.run_id = o.run_id;
  options.output = o.output;
  if (o.twin_file.empty()) {
    if (!o.twin_run.empty()) throw InputError("--twin-run", "", "names the run compared with --twin: give --twin too");
    if (!o.recorded_dir.empty()) throw InputError("--recorded", "", "names the signals compared with --twin: give --twin too");
  } else {
    const std::vector<std::string> presets = RobotPresetNames();
    if (std::find(presets.begin(), presets.end(), o.twin_file) == presets.end() && !std::filesystem::is_regular_file(o.twin_file)) {
      throw InputError("--twin", "", "no such file \"" + o.twin_file + "\" (expected the robot file `armfault calibrate` writes, or a robot preset)");
    }
    if (!o.recorded_dir.empty() && !std::filesystem::is_directory(o.recorded_dir)) {
      throw InputError("--recorded", "", "no such directory \"" + o.recorded_dir + "\" (expected the output of armfault export or import)");
    }
    TwinCompareOptions twin;
    twin.twin_file = o.twin_file;
    twin.twin = ReadRobotArgument(o.twin_file);
    twin.recorded_dir = o.recorded_dir;
    twin.run_id = o.twin_run;
    options.twin = twin;
  }
  const ReportPaths paths = WriteCampaignReport(options);
  std::printf("wrote %s and %s\n", paths.html.c_str(), paths.markdown.c_str());
  return 0;
}

}  // namespace armfault
