// Monitor cost (campaigns/running/monitor_cost.h): the campaign's figures from the runs' lines, the floor
// verdict, a line per run in monitor_cost.jsonl kept by --resume, and the deterministic files
// untouched by the measurement.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "campaigns/running/monitor_clock.h"
#include "campaigns/running/monitor_cost.h"
#include "campaigns/running/run_pipeline.h"
#include "campaigns/running/runner.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ReadAll;
using testing_support::ScratchDir;

TEST(MonitorCost, CampaignFiguresFromTheRunsLines) {
  ScratchDir dir("monitor_cost_lines");
  const std::string path = dir.Write("monitor_cost.jsonl",
                                     R"({"case":0,"run_id":"a","ticks":100,"mean_us":2,"median_us":1,"p99_us":5,"max_us":9,"finish_us":1}
{"case":1,"run_id":"b","ticks":0}
{"case":2,"run_id":"c","ticks":300,"mean_us":1,"median_us":0.5,"p99_us":3,"max_us":20,"finish_us":1}
)");
  const json met = SummarizeMonitorCost(path, 4096.0, 1.5, "plugin");
  EXPECT_EQ(met["runs"], 2);
  EXPECT_EQ(met["ticks"], 400);
  EXPECT_EQ(met["mean_us_per_tick"], 1.25);  // (2 x 100 + 1 x 300) / 400
  EXPECT_EQ(met["median_of_run_medians_us"], 0.75);
  EXPECT_EQ(met["max_of_run_p99s_us"], 5.0);
  EXPECT_EQ(met["max_tick_us"], 20.0);
  EXPECT_EQ(met["heap_bytes"], 4096.0);
  EXPECT_EQ(met["floor"]["met"], true);
  EXPECT_EQ(met["floor"]["message"], "monitor_us_per_tick 1.250 <= 1.500 (mean over 400 ticks of 2 runs)");
  const json missed = SummarizeMonitorCost(path, std::nullopt, 1.0, "plugin");
  EXPECT_EQ(missed["floor"]["met"], false);
  EXPECT_TRUE(missed["heap_bytes"].is_null());
  EXPECT_FALSE(SummarizeMonitorCost(path, std::nullopt, std::nullopt, "plugin").contains("floor"));
  const std::string bad = dir.Write("bad.jsonl", "{\"ticks\": 5}\n");
  EXPECT_THAT(testing_support::ErrorOf([&] { SummarizeMonitorCost(bad, std::nullopt, std::nullopt, "x"); }).what(),
              HasSubstr("bad.jsonl: line 1: "));
}

// The clock keeps a histogram: its quantiles within a bin (0.1 %) of the exact ones, its mean
// and maximum exact, and its bins as many after a million ticks as after a thousand of the
// same times (a run's clock does not grow with the run).
TEST(MonitorClock, AHistogramThatDoesNotGrowWithTheTicks) {
  MonitorClock clock;
  for (int k = 1; k <= 1000; ++k) clock.Add(static_cast<float>(k));
  json j = clock.ToJson();
  EXPECT_EQ(j["ticks"], 1000);
  EXPECT_EQ(j["mean_us"], 500.5);
  EXPECT_EQ(j["max_us"], 1000.0);
  EXPECT_NEAR(j["median_us"].get<double>(), 500.0, 0.5);  // nearest rank: the 500th
  EXPECT_NEAR(j["p99_us"].get<double>(), 990.0, 1.0);
  const size_t bins = clock.bins();
  for (int r = 0; r < 999; ++r) {
    for (int k = 1; k <= 1000; ++k) clock.Add(static_cast<float>(k));
  }
  EXPECT_EQ(clock.bins(), bins);
  j = clock.ToJson();
  EXPECT_EQ(j["ticks"], 1000000);
  EXPECT_NEAR(j["median_us"].get<double>(), 500.0, 0.5);
}

// A healthy run of every joint moving, `duration_s` long.
Campaign AllJointsHealthy(double duration_s) {
  json c = json::parse(R"({
    "name": "shift", "seed": 7, "robot": "mrr-config1",
    "trajectories": [{"name": "all3", "joints": {
      "1": {"type": "sine_pair", "amplitude_deg": 30, "omega_rad_s": 0.8},
      "2": {"type": "sine_pair", "amplitude_deg": 20, "omega_rad_s": 1.0},
      "3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "healthy": 1
  })");
  c["duration_s"] = duration_s;
  return CampaignFromJson(c, "shift.json", ".");
}

// What the monitor holds during a campaign's run does not grow with the run's length:
// its heap (mallinfo2, in the plant's loop) after 300 s is that after 30 s, within the
// allocator's slack (it kept every window before: about 250 KiB more). A run whose output is
// asked for keeps the windows; a campaign's does not.
TEST(MonitorCost, TheMonitorsHeapDoesNotGrowWithTheRunsLength) {
  const std::optional<double> short_run = ProbeMonitorHeapBytes(AllJointsHealthy(30));
  const std::optional<double> long_run = ProbeMonitorHeapBytes(AllJointsHealthy(300));
  ASSERT_TRUE(short_run && long_run);
  EXPECT_GT(*short_run, 0);
  EXPECT_LE(*long_run, *short_run + 8192) << "30 s: " << *short_run << " B, 300 s: " << *long_run << " B";

  const Campaign c = AllJointsHealthy(20);
  const PreparedRun p = PrepareCase(c, CaseAt(c, 0), nullptr);
  const ExecutedRun campaign_run = Execute(*p.model, p.spec, p.faults, *p.monitor, p.record.onset_s, nullptr, false);
  EXPECT_TRUE(campaign_run.monitor->output().windows.empty());
  MonitorOutput asked;
  const RunRecord r = RunCase(c, CaseAt(c, 0), nullptr, nullptr, &asked);
  EXPECT_GT(asked.windows.size(), 10u);
  EXPECT_EQ(ToJson(r).dump(), ToJson(ScoreRun(p, campaign_run)).dump());  // the same score
}

TEST(MonitorCost, ALinePerRunThatResumeKeepsAndNothingElseChanges) {
  const json campaign = json::parse(R"({
    "name": "cost", "seed": 3, "duration_s": 0.6,
    "trajectories": [{"name": "a", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.5, "onset_s": 0.2}],
    "healthy": 4
  })");
  const Campaign c = CampaignFromJson(campaign, "cost.json", ".");
  ScratchDir whole("monitor_cost_whole"), cut("monitor_cost_cut");
  RunnerOptions o;
  o.output_dir = whole.path().string();
  o.threads = 2;
  RunCampaign(c, o);
  std::istringstream lines(ReadAll(whole.path() / "monitor_cost.jsonl"));
  long n = 0;
  for (std::string line; std::getline(lines, line); ++n) {
    const json j = json::parse(line);
    EXPECT_EQ(j["case"], n);
    EXPECT_EQ(j["ticks"], 301);  // 0.6 s at 500 Hz, both ends
    EXPECT_GE(j["p99_us"].get<double>(), j["median_us"].get<double>());
    EXPECT_GE(j["max_us"].get<double>(), j["p99_us"].get<double>());
  }
  EXPECT_EQ(n, 5);
  // Stopped after 2 runs, then resumed: the same runs, a cost line each.
  std::atomic<bool> stop{false};
  o.output_dir = cut.path().string();
  o.threads = 1;
  o.stop = &stop;
  o.progress = [&](long done, long) { stop.store(done >= 2); };
  RunCampaign(c, o);
  o.stop = nullptr;
  o.resume = true;
  RunCampaign(c, o);
  EXPECT_EQ(ReadAll(cut.path() / "results.jsonl"), ReadAll(whole.path() / "results.jsonl"));
  std::istringstream resumed(ReadAll(cut.path() / "monitor_cost.jsonl"));
  n = 0;
  for (std::string line; std::getline(resumed, line); ++n) EXPECT_EQ(json::parse(line)["case"], n);
  EXPECT_EQ(n, 5);
  EXPECT_GT(ProbeMonitorHeapBytes(c).value_or(-1), 0.0);
}

TEST(MonitorCost, MergeJoinsTheShardsLinesInCaseOrder) {
  ScratchDir dir("monitor_cost_merge");
  const std::string line = R"(,"ticks":10,"mean_us":1,"median_us":1,"p99_us":2,"max_us":3,"finish_us":1})";
  std::filesystem::create_directories(dir.path() / "s0");
  std::filesystem::create_directories(dir.path() / "s1");
  std::filesystem::create_directories(dir.path() / "out");
  dir.Write("s0/monitor_cost.jsonl", "{\"case\":0" + line + "\n{\"case\":2" + line + "\n{\"case\":4" + line + "\n");
  dir.Write("s1/monitor_cost.jsonl", "{\"case\":1" + line + "\n{\"case\":3" + line + "\n");
  dir.Write("s1/monitor_cost.json", R"({"heap_bytes": 512})");
  const std::vector<std::string> shards = {(dir.path() / "s0").string(), (dir.path() / "s1").string()};
  const MonitorCostInput joined = JoinShardMonitorCost(shards, dir.path() / "out");
  ASSERT_TRUE(joined.write);
  EXPECT_EQ(joined.heap_bytes, std::optional<double>(512.0));  // the largest shard's
  std::istringstream merged(ReadAll(dir.path() / "out" / "monitor_cost.jsonl"));
  long n = 0;
  for (std::string l; std::getline(merged, l); ++n) EXPECT_EQ(json::parse(l)["case"], n);
  EXPECT_EQ(n, 5);
  // monitor_cost.json as the run directory's table writes it from the joined lines.
  const json summary = SummarizeMonitorCost(dir.path() / "out" / "monitor_cost.jsonl", joined.heap_bytes, 0.5, "x");
  EXPECT_EQ(summary["ticks"], 50);
  EXPECT_EQ(summary["heap_bytes"], 512.0);
  EXPECT_EQ(summary["floor"]["met"], false);
  // A shard without the file: nothing merged, and no stale file left.
  dir.Write("out/monitor_cost.json", "{}");
  std::filesystem::remove(dir.path() / "s1" / "monitor_cost.jsonl");
  EXPECT_FALSE(JoinShardMonitorCost(shards, dir.path() / "out").write);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "monitor_cost.jsonl"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "monitor_cost.json"));
}

}  // namespace
}  // namespace armfault
