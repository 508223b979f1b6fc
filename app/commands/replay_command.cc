// `armfault replay DIR`: a monitor over recorded signals, scored as a live run (campaigns/data/replay.h).
#include <cstdio>
#include <filesystem>

#include "app/commands/commands.h"
#include "app/commands/progress.h"
#include "campaigns/running/monitor_cost.h"
#include "campaigns/data/replay.h"
#include "campaigns/running/run_dir.h"
#include "campaigns/running/run_outputs.h"
#include "core/base/json_input.h"

namespace armfault {

int ReplayCommand(const ReplayCommandOptions& o) {
  namespace fs = std::filesystem;
  if (o.threads < 0) throw InputError("-j", "", "expected a thread count >= 1 (0: all cores), got " + std::to_string(o.threads));
  ReplayOptions ro;
  ro.dir = o.dir;
  ro.output_dir = o.output_dir.empty() ? (fs::path(o.dir) / "replayed").string() : o.output_dir;
  ro.monitor_file = o.monitor_file;
  ro.commission_run = o.commission_run;
  ro.threads = o.threads;
  if (!fs::is_directory(o.dir)) {  // before the lock makes the output directory inside it
    throw InputError(o.dir, "", fs::exists(o.dir) ? "not a directory"
                                                  : "no such directory (expected the output of armfault export or import)");
  }
  Progress progress(!o.quiet);
  ro.progress = [&](long done, long total) { progress.Update(done, total); };
  const OutputLock lock(ro.output_dir, "armfault replay " + o.dir);
  const ReplayResult r = ReplayDirectory(ro);
  const std::string source = r.campaign.monitor_model ? r.campaign.monitor_model->source() : "";
  std::printf("replayed %ld runs of %s through monitor %s%s%s (%ld failed) -> %s\n", r.runs, r.campaign.name.c_str(),
              r.campaign.monitor.type.c_str(), source.empty() ? "" : " ", source.c_str(), r.failed, ro.output_dir.c_str());
  if (!o.commission_run.empty()) std::printf("commissioned on run %s (left out of the alarms per hour)\n", o.commission_run.c_str());
  FinishOptions finish;
  // The monitor's cost on this machine, as `run` measures it (no heap probe: nothing simulated).
  finish.monitor_cost.write = fs::exists(fs::path(ro.output_dir) / run_dir::kMonitorCost);
  const FinishedRunDir finished = FinishRunDirectory(ro.output_dir, r.campaign, finish);
  const AlarmRate& a = r.alarms;
  if (a.hours > 0) {
    const nlohmann::json j = a.ToJson();
    std::printf("alarms per hour of operation: %.4g (95 %% upper bound %.4g): %ld alarm onsets in %.4g h of %ld healthy and "
                "%ld unlabelled runs (summary.json alarms_per_hour)\n",
                j["per_hour"].get<double>(), j["per_hour_upper_95"].get<double>(), a.alarm_onsets, a.hours, a.healthy_runs,
                a.unlabelled_runs);
  } else {
    std::printf("alarms per hour of operation: no healthy or unlabelled run to count them on\n");
  }
  const int status = ReportMonitorCost(finished, r.campaign.monitor.type, false);
  std::printf("wrote %s/results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml, monitor_cost.jsonl, "
              "monitor_cost.json, alarms_per_hour.json, replay.json\n",
              ro.output_dir.c_str());
  if (!o.quiet) std::printf("next: armfault report %s\n", ro.output_dir.c_str());
  return status;  // 3 when a run failed (FinishRunDirectory)
}

}  // namespace armfault
