// `armfault run CAMPAIGN`, `validate`: a campaign from file to results, summary and floors.
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <fstream>

#include "app/commands.h"
#include "app/progress.h"
#include "campaigns/campaign.h"
#include "campaigns/monitor_cost.h"
#include "campaigns/runner.h"
#include "core/base/json_input.h"
#include "campaigns/campaign_summary.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

}  // namespace

ShardSpec ResolveShard(const CampaignRunOptions& o) {
  ShardSpec s;
  auto parse_int = [](const std::string& text, const std::string& what) {
    char* end = nullptr;
    const long v = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || v < 0 || v > 1000000) {
      throw InputError(what, "", "expected a whole number >= 0, got \"" + text + "\"");
    }
    return static_cast<int>(v);
  };
  if (!o.shard.empty()) {
    const auto slash = o.shard.find('/');
    if (slash == std::string::npos) throw InputError("--shard", "", "expected K/N (K from 0 to N-1), got \"" + o.shard + "\"");
    s.index = parse_int(o.shard.substr(0, slash), "--shard");
    s.count = parse_int(o.shard.substr(slash + 1), "--shard");
  } else if (const char* id = std::getenv("SLURM_ARRAY_TASK_ID")) {
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    if (!count) throw InputError("SLURM_ARRAY_TASK_COUNT", "", "SLURM_ARRAY_TASK_ID is set but the task count is not");
    s.index = parse_int(id, "SLURM_ARRAY_TASK_ID");
    s.count = parse_int(count, "SLURM_ARRAY_TASK_COUNT");
    // Slurm arrays often start at 1 (--array=1-N): map task N to shard 0.
    if (s.index == s.count) s.index = 0;
  } else if (const char* index = std::getenv("JOB_COMPLETION_INDEX")) {
    if (o.shard_count <= 0) throw InputError("--shard-count", "", "JOB_COMPLETION_INDEX is set: give the job's completions as --shard-count");
    s.index = parse_int(index, "JOB_COMPLETION_INDEX");
    s.count = o.shard_count;
  } else if (o.shard_count > 0) {
    throw InputError("--shard-count", "", "gives N with the shard index from JOB_COMPLETION_INDEX, which is not set; "
                                          "for one shard by hand use --shard K/N");
  }
  if (!o.shard.empty() && o.shard_count > 0) {
    throw InputError("--shard-count", "", "--shard K/N already gives the count; drop --shard-count");
  }
  if (s.count < 1 || s.index >= s.count) {
    throw InputError("--shard", "", "shard " + std::to_string(s.index) + " of " + std::to_string(s.count) +
                                        " does not exist (K/N needs 0 <= K < N)");
  }
  return s;
}


namespace {

// Runs `step`; a write that failed (a full disk: "cannot write: No space left on device") gets
// the command that continues once there is room, since every complete line stays.
template <class Step>
auto ContinuableWith(const std::string& resume, Step step) {
  try {
    return step();
  } catch (const InputError& e) {
    if (e.message().rfind("cannot write", 0) != 0 && e.message().rfind("cannot open for writing", 0) != 0) throw;
    throw InputError(e.source(), e.pointer(), e.message(), "what is written is kept; once there is room, continue with: " + resume);
  }
}

void PrintWarnings(const std::string& campaign_file, const Campaign& campaign) {
  for (const std::string& w : CampaignWarnings(campaign)) {
    std::fprintf(stderr, "armfault: warning: %s: %s\n", campaign_file.c_str(), w.c_str());
  }
}

}  // namespace

int FinishCampaignOutputs(const std::string& dir_name, const CampaignSpec& campaign, bool summary_only) {
  const fs::path dir(dir_name);
  const RecordOutputsResult written = WriteRecordOutputs(dir, campaign, summary_only);
  const SummaryBuilder& builder = written.summary;
  const std::vector<FloorVerdict>& verdicts = written.verdicts;
  const std::map<std::string, bool>& decided = written.early_stop_decided;
  if (builder.not_excited_runs() > 0) {
    std::printf("%ld runs not excited (their fault could not act; %s): see not_excited_runs in %s\n",
                builder.not_excited_runs(), campaign.include_not_excited ? "scored, as the campaign asks" : "left out of the rates",
                (dir / run_dir::kSummary).string().c_str());
  }
  if (builder.not_injected_runs() > 0) {
    std::printf("%ld runs not injected (their onset condition never fired; left out of the rates): see not_injected_runs in %s\n",
                builder.not_injected_runs(), (dir / run_dir::kSummary).string().c_str());
  }
  for (const auto& [joint, tally] : builder.sensor_saturation()) {
    // Saturation is no fault, but the built-in monitor cannot read the sensor there.
    std::fprintf(stderr,
                 "armfault: warning: joint %d's torque went beyond its torque sensor's range in %ld of %ld runs (up to "
                 "%.2f s in one; sensor_saturated_s in results.jsonl): a saturated reading is no evidence for the "
                 "built-in monitor; widen torque_sensor/full_scale_Nm or ease the motion\n",
                 joint, tally.runs, builder.runs(), tally.longest_s);
  }
  // Per joint, compactly: where the misses, misnamings and false alarms are (summary.json
  // "per_joint"; per family x joint there and in junit.xml).
  const std::map<int, internal::SummaryTally> joints = builder.JointTallies();
  if (!joints.empty()) std::printf("per joint (summary.json per_joint, per_family_joint, confusion_by_joint):\n");
  for (const auto& [joint, t] : joints) {
    std::string latency = "-";
    if (!t.latencies_s.empty()) {
      std::vector<double> v = t.latencies_s;
      std::sort(v.begin(), v.end());
      const size_t n = v.size();
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.3f s", n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2);
      latency = buf;
    }
    std::printf("  joint %d: detection %ld/%ld, isolation %ld/%ld, latency median %s, false alarms naming it %ld/%ld%s\n",
                joint, t.detected, t.faulty, t.isolated, t.detected, latency.c_str(), t.healthy_alarms, t.healthy,
                t.not_excited > 0 ? ("; " + std::to_string(t.not_excited) + " not excited" +
                                     (campaign.include_not_excited ? " (scored)" : ", left out")).c_str()
                                  : "");
  }
  // `replay` prints its own, over the hours it replayed (alarms_per_hour.json).
  if (builder.healthy_runs() > 0 && !fs::exists(dir / run_dir::kAlarmsPerHour)) {
    std::printf("%s (summary.json healthy_operation)\n", HealthyOperationOf(builder, campaign.duration_s).Line().c_str());
  }
  bool all_met = true;
  for (const FloorVerdict& v : verdicts) {
    std::printf("floor %-50s %s  %s\n", v.name.c_str(), v.met ? "met   " : "MISSED", v.message.c_str());
    bool met = v.met;
    if (auto it = decided.find(v.name); it != decided.end() && it->second != v.met) {
      // Decided on the runs up to its decision; the runs made after it for other floors moved
      // the rate across the bound. The decision is the prediction for the whole campaign.
      std::printf("      early stop decided this floor %s for the whole campaign; the exit status follows that\n",
                  it->second ? "met" : "missed");
      met = it->second;
    }
    all_met = all_met && met;
  }
  if (builder.failed_runs() > 0) {
    // The first failure with its reason: a count alone is easy to miss and says nothing.
    std::fprintf(stderr, "armfault: %ld of %ld runs failed (see %s); first failed %s\n", builder.failed_runs(),
                 builder.runs(), (dir / run_dir::kSummary).string().c_str(), builder.FirstFailureText().c_str());
    return 3;
  }
  return all_met ? 0 : 1;
}

namespace {

std::atomic<bool> g_stop{false};
ExitGate g_exit_gate;
std::string g_exit_message;  // set before the handlers are installed, read by them only

// A second Ctrl-C (or TERM): ends the process at once, but never inside a run's lines.
extern "C" void OnSecondInterrupt(int) { g_exit_gate.RequestExit(130, g_exit_message.data(), g_exit_message.size()); }

// The first Ctrl-C asks the runner to stop after the runs in flight.
extern "C" void OnInterrupt(int) {
  g_stop.store(true);
  std::signal(SIGINT, OnSecondInterrupt);
  std::signal(SIGTERM, OnSecondInterrupt);
}

std::string ShellQuote(const std::string& s) {
  if (s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789/._-=:") == std::string::npos) return s;
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

int RunCampaignCommand(const CampaignRunOptions& o) {
  const Campaign campaign = o.campaign_file.empty() ? DefaultCampaign() : ReadCampaignFile(o.campaign_file);
  if (o.threads < 0) throw InputError("-j", "", "expected a thread count >= 1 (0: all cores), got " + std::to_string(o.threads));
  RunnerOptions ro;
  ro.output_dir = o.output_dir;
  ro.threads = o.threads;
  ro.shard = ResolveShard(o);
  ro.resume = o.resume;
  if (o.early_stop) {
    if (!(o.early_stop_confidence > 0.5 && o.early_stop_confidence < 1)) {
      throw InputError("--early-stop-confidence", "",
                       "expected a probability in (0.5, 1), got " + FormatNumber(o.early_stop_confidence));
    }
    EarlyStopOptions e;
    e.confidence = o.early_stop_confidence;
    ro.early_stop = e;
  }
  Progress progress(!o.quiet);
  ro.progress = [&](long done, long total) { progress.Update(done, total); };
  if (!o.campaign_file.empty()) PrintWarnings(o.campaign_file, campaign);
  const long total = CaseCount(campaign);
  std::printf("campaign %s: %ld runs%s -> %s\n", campaign.name.c_str(), total,
              ro.shard.count > 1 ? (", shard " + std::to_string(ro.shard.index) + "/" + std::to_string(ro.shard.count)).c_str() : "",
              o.output_dir.c_str());
  const auto start = std::chrono::steady_clock::now();
  // One writer per directory: a second `run` into it would interleave its lines with ours.
  const OutputLock lock(o.output_dir, "armfault run " + (o.campaign_file.empty() ? std::string("(built-in)") : o.campaign_file) +
                                          (ro.shard.count > 1 ? " --shard " + std::to_string(ro.shard.index) + "/" +
                                                                    std::to_string(ro.shard.count)
                                                              : ""));
  // Everything written so far is complete lines: --resume picks up from there.
  std::string resume = "armfault run";
  if (!o.campaign_file.empty()) resume += " " + ShellQuote(o.campaign_file);
  resume += " -o " + ShellQuote(o.output_dir) + " --resume";
  if (o.threads > 0) resume += " -j " + std::to_string(o.threads);
  if (ro.shard.count > 1) resume += " --shard " + std::to_string(ro.shard.index) + "/" + std::to_string(ro.shard.count);
  g_exit_message = "\ninterrupted again: stopped at once; every run written so far is kept whole in " + o.output_dir +
                   "/results.jsonl (no summary written)\nresume with: " + resume + "\n";
  g_stop.store(false);
  ro.stop = &g_stop;
  ro.exit_gate = &g_exit_gate;
  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
  const RunnerResult r = ContinuableWith(resume, [&] { return RunCampaign(campaign, ro); });
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (r.interrupted) {
    std::fprintf(stderr, "\ninterrupted: kept %ld of %ld runs in %s/results.jsonl (no summary written)\nresume with: %s\n",
                 r.resumed + r.ran, r.total, o.output_dir.c_str(), resume.c_str());
    return 130;
  }
  std::printf("ran %ld runs in %.1f s (%ld resumed, %ld failed)\n", r.ran, seconds, r.resumed, r.failed);
  if (!r.early_stop.is_null()) std::printf("%s\n", EarlyStopSummaryLine(r.early_stop).c_str());
  int status = ContinuableWith(resume, [&] { return FinishCampaignOutputs(o.output_dir, campaign, o.summary_only); });
  // What the monitor cost (campaigns/monitor_cost.h): a measurement, in files of its own.
  if (const fs::path cost_path = fs::path(o.output_dir) / run_dir::kMonitorCost; fs::exists(cost_path)) {
    const std::optional<double> heap = ProbeMonitorHeapBytes(campaign);
    const nlohmann::json cost = SummarizeMonitorCost(cost_path, heap, campaign.floors.monitor_us_per_tick, campaign.monitor.type);
    WriteAtomically(fs::path(o.output_dir) / run_dir::kMonitorCostSummary, cost.dump(2) + "\n");
    if (!cost["mean_us_per_tick"].is_null()) {
      std::printf("monitor %s: %.3f us per tick on average (run medians %.3f us, 99th percentiles %.3f us), %s heap%s\n",
                  campaign.monitor.type.c_str(), cost["mean_us_per_tick"].get<double>(),
                  cost["median_of_run_medians_us"].get<double>(), cost["median_of_run_p99s_us"].get<double>(),
                  heap ? (std::to_string(static_cast<long>(std::lround(*heap / 1024))) + " KiB").c_str() : "unmeasured",
                  " (monitor_cost.json)");
    }
    if (cost.contains("floor")) {
      const bool met = cost["floor"]["met"].get<bool>();
      std::printf("floor %-50s %s  %s\n", "monitor_us_per_tick", met ? "met   " : "MISSED",
                  cost["floor"]["message"].get<std::string>().c_str());
      if (!met && status == 0) status = 1;
    }
  }
  if (o.summary_only) {
    RemoveNotKeptBySummaryOnly(o.output_dir);
    std::printf("wrote %s/results.jsonl, summary.json, junit.xml, monitor_cost.json (--summary-only: decisions.jsonl, "
                "results.csv and monitor_cost.jsonl removed)\n",
                o.output_dir.c_str());
  } else {
    std::printf("wrote %s/results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml, monitor_cost.jsonl, "
                "monitor_cost.json\n",
                o.output_dir.c_str());
  }
  if (!o.quiet) {
    std::printf("next: armfault report %s  (the results as one page)\n", o.output_dir.c_str());
    if (o.summary_only) {
      std::printf("      (not tune: --summary-only removed the decision statistics it re-scores; run without it to tune)\n");
    } else {
      std::printf("      armfault tune %s    (thresholds re-scored from these runs)\n", o.output_dir.c_str());
    }
  }
  return status;
}

int ValidateCommand(const ValidateOptions& o) {
  const std::string& campaign_file = o.campaign_file;
  const Campaign campaign =
      ReadCampaignFile(campaign_file, o.load_plugins ? MonitorLoading::kBuild : MonitorLoading::kSkipUserCode);
  PrintWarnings(campaign_file, campaign);
  std::printf("%s: valid campaign \"%s\": %ld runs (%zu trajectories, %zu fault entries, %d healthy per trajectory, %d repetitions)\n",
              campaign_file.c_str(), campaign.name.c_str(), CaseCount(campaign), campaign.trajectories.size(),
              campaign.faults.size(), campaign.healthy, campaign.repetitions);
  if (campaign.search.present && !campaign.search.has_runs) {
    size_t cells = 0;
    for (const FaultEntry& e : campaign.faults) cells += e.joints.size() * campaign.trajectories.size();
    std::printf("%s: search (armfault boundary): %zu cells, batches of %d, at most %d runs a cell\n", campaign_file.c_str(),
                cells, campaign.search.batch, campaign.search.max_runs);
  }
  if (!campaign.monitor_model && MonitorRunsUserCode(campaign.monitor.type)) {
    std::printf("%s: monitor \"%s\" not loaded: loading it runs its code with your rights; "
                "--load-plugins loads it and checks its settings\n",
                campaign_file.c_str(), campaign.monitor.type.c_str());
  }
  return 0;
}

}  // namespace armfault
