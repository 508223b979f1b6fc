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

#include "app/commands/commands.h"
#include "app/commands/progress.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/running/monitor_cost.h"
#include "campaigns/running/run_outputs.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "core/base/quote.h"
#include "campaigns/scoring/campaign_summary.h"

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
  // The lock file goes with every exit, the immediate one of a second Ctrl-C too (and the gate
  // lets go of its path before the lock does, however this function is left).
  g_exit_gate.RemoveOnExit(lock.path());
  struct ForgetLockPath {
    ~ForgetLockPath() { g_exit_gate.RemoveOnExit(nullptr); }
  } forget_lock_path;
  // Another campaign's results are kept unless asked (a rerun of this one, or --resume, is not).
  if (!o.resume) RequireNoOtherResults(o.output_dir, CampaignFileJson(campaign, ro.shard), o.force);
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
  FinishOptions finish;
  finish.summary_only = o.summary_only;
  // What the monitor cost (campaigns/running/monitor_cost.h): a measurement, in files of its own.
  if (fs::exists(fs::path(o.output_dir) / run_dir::kMonitorCost)) finish.monitor_cost = {true, ProbeMonitorHeapBytes(campaign)};
  const FinishedRunDir finished =
      ContinuableWith(resume, [&] { return FinishRunDirectory(o.output_dir, campaign, finish); });
  const int status = ReportMonitorCost(finished, campaign.monitor.type, true);
  if (o.summary_only) {
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
  auto count = [](long n, const char* one, const char* many) { return std::to_string(n) + " " + (n == 1 ? one : many); };
  std::printf("%s: valid campaign \"%s\": %s (%s, %s, %d healthy per trajectory, %s)\n", campaign_file.c_str(),
              campaign.name.c_str(), count(CaseCount(campaign), "run", "runs").c_str(),
              count(static_cast<long>(campaign.trajectories.size()), "trajectory", "trajectories").c_str(),
              count(static_cast<long>(campaign.faults.size()), "fault entry", "fault entries").c_str(), campaign.healthy,
              count(campaign.repetitions, "repetition", "repetitions").c_str());
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
