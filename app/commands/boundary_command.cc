// `armfault boundary CAMPAIGN`: the magnitude at which each cell's detection probability
// reaches the campaign's search target (90 % at 95 % confidence by default), found in batches
// of runs (campaigns/tuning/boundary.h); `armfault boundary --from DIR`: the same estimate from the
// runs already in a directory (a grid run, say).
#include <atomic>
#include <csignal>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "app/commands/commands.h"
#include "campaigns/tuning/boundary.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/running/run_outputs.h"
#include "campaigns/running/runner.h"
#include "core/base/json_input.h"
#include "core/base/quote.h"

namespace armfault {

namespace {

namespace fs = std::filesystem;

std::atomic<bool> g_boundary_stop{false};

extern "C" void OnBoundaryInterrupt(int) {
  g_boundary_stop.store(true);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

}  // namespace

int BoundaryCommand(const BoundaryCommandOptions& o) {
  if (!o.from_dir.empty()) {
    if (!o.campaign_file.empty()) throw InputError("--from", "", "give a campaign or --from DIR, not both");
    const fs::path dir(o.from_dir);
    const CampaignSpec campaign = ReadRunDirCampaign(dir);
    if (!campaign.search.present) {
      throw InputError((dir / run_dir::kCampaign).string(), "/campaign/search",
                       "missing: the campaign has no \"search\" block saying what to estimate");
    }
    std::vector<RunRecord> records;
    ReadRunRecords(dir / run_dir::kResults, {}, [&](RunRecord&& r, long) { records.push_back(std::move(r)); });
    const nlohmann::json report = BoundaryReport(campaign, records, {}, 0);
    WriteAtomically(dir / "boundary.json", report.dump(2) + "\n");
    std::printf("campaign %s: boundary estimated from %ld runs in %s\n", campaign.name.c_str(), report["runs"].get<long>(),
                o.from_dir.c_str());
    std::fputs(BoundaryTable(report).c_str(), stdout);
    std::printf("wrote %s\n", (dir / "boundary.json").string().c_str());
    return 0;
  }
  if (o.campaign_file.empty()) throw InputError("boundary", "", "give the campaign: armfault boundary CAMPAIGN.json");
  if (o.threads < 0) throw InputError("-j", "", "expected a thread count >= 1 (0: all cores), got " + std::to_string(o.threads));
  if (o.max_batches < 0) throw InputError("--max-batches", "", "expected a whole number >= 0, got " + std::to_string(o.max_batches));
  const Campaign campaign = ReadCampaignFile(o.campaign_file);
  if (!campaign.search.present) {
    throw InputError(o.campaign_file, "/search",
                     "missing: a boundary search needs a \"search\" block (docs/campaign-format.md, \"Boundary search\"), "
                     "e.g. \"search\": {\"target\": 0.9, \"confidence\": 0.95}");
  }
  std::printf("campaign %s: boundary search of %zu cells, target %.3g at %.3g confidence, batches of %d, at most %d runs "
              "a cell -> %s\n",
              campaign.name.c_str(), campaign.trajectories.size() * [&] {
                size_t n = 0;
                for (const FaultEntry& e : campaign.faults) n += e.joints.size();
                return n;
              }(),
              campaign.search.target, campaign.search.confidence, campaign.search.batch, campaign.search.max_runs,
              o.output_dir.c_str());
  BoundaryOptions bo;
  bo.output_dir = o.output_dir;
  bo.threads = o.threads;
  bo.resume = o.resume;
  bo.max_batches = o.max_batches;
  if (!o.quiet) bo.log = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  g_boundary_stop.store(false);
  bo.stop = &g_boundary_stop;
  const OutputLock lock(o.output_dir, "armfault boundary " + o.campaign_file);
  std::signal(SIGINT, OnBoundaryInterrupt);
  std::signal(SIGTERM, OnBoundaryInterrupt);
  const auto start = std::chrono::steady_clock::now();
  const BoundaryResult r = RunBoundary(campaign, bo);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string resume = "armfault boundary " + ShellQuote(o.campaign_file) + " -o " + ShellQuote(o.output_dir) + " --resume" +
                             (o.threads > 0 ? " -j " + std::to_string(o.threads) : std::string());
  if (r.interrupted) {
    std::fprintf(stderr, "\ninterrupted: kept %ld runs in %s/results.jsonl (no boundary.json written)\nresume with: %s\n",
                 r.runs, o.output_dir.c_str(), resume.c_str());
    return 130;
  }
  std::printf("ran %ld runs in %d batches in %.1f s (%ld resumed, %ld failed)\n", r.runs - r.resumed, r.batches, seconds,
              r.resumed, r.failed);
  std::fputs(BoundaryTable(r.report).c_str(), stdout);
  // summary.json, junit.xml and results.csv of the runs made, as `run` writes them, so that
  // report and diff read the directory; the floors are printed but judge runs placed near the
  // boundary on purpose, so they do not set the exit status.
  const int status = FinishRunDirectory(o.output_dir, ReadRunDirCampaign(o.output_dir), {}).status;
  std::printf("wrote %s/boundary.json, campaign.json, results.jsonl, decisions.jsonl, results.csv, summary.json, junit.xml\n",
              o.output_dir.c_str());
  if (r.stopped) std::printf("stopped after %d batches (--max-batches); continue with: %s\n", r.batches, resume.c_str());
  if (!o.quiet) std::printf("next: armfault report %s  (the detection-probability plot of each cell)\n", o.output_dir.c_str());
  return status == 3 ? 3 : 0;
}

}  // namespace armfault
