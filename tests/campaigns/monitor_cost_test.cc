// Monitor cost (campaigns/monitor_cost.h): the campaign's figures from the runs' lines, the floor
// verdict, a line per run in monitor_cost.jsonl kept by --resume, and the deterministic files
// untouched by the measurement.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "campaigns/monitor_cost.h"
#include "campaigns/runner.h"
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
  ASSERT_TRUE(MergeMonitorCost(shards, dir.path() / "out", 0.5, "x"));
  std::istringstream merged(ReadAll(dir.path() / "out" / "monitor_cost.jsonl"));
  long n = 0;
  for (std::string l; std::getline(merged, l); ++n) EXPECT_EQ(json::parse(l)["case"], n);
  EXPECT_EQ(n, 5);
  const json summary = json::parse(ReadAll(dir.path() / "out" / "monitor_cost.json"));
  EXPECT_EQ(summary["ticks"], 50);
  EXPECT_EQ(summary["heap_bytes"], 512.0);
  EXPECT_EQ(summary["floor"]["met"], false);
  // A shard without the file: nothing merged, and no stale file left.
  std::filesystem::remove(dir.path() / "s1" / "monitor_cost.jsonl");
  EXPECT_FALSE(MergeMonitorCost(shards, dir.path() / "out", std::nullopt, "x"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "monitor_cost.jsonl"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "monitor_cost.json"));
}

}  // namespace
}  // namespace armfault
