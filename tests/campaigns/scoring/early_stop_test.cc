// `run --early-stop` (campaigns/scoring/early_stop.h): the prediction is exact when nothing is left; the
// order visits every case once; an early-stopped run keeps the same runs and bytes for any thread
// count, resumes to the same bytes, writes its files in case order, and decides each floor as the
// whole campaign does; bad combinations are input errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <set>

#include "campaigns/scoring/early_stop.h"
#include "campaigns/running/runner.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ReadAll;
using testing_support::ScratchDir;

TEST(EarlyStopPrediction, IsExactWhenNoRunIsLeftAndFollowsTheData) {
  EXPECT_EQ(PredictiveMet(9, 10, 0, 0.9, true), 1.0);
  EXPECT_EQ(PredictiveMet(8, 10, 0, 0.9, true), 0.0);
  EXPECT_EQ(PredictiveMet(0, 20, 0, 0.05, false), 1.0);
  EXPECT_EQ(PredictiveMet(2, 20, 0, 0.05, false), 0.0);
  EXPECT_EQ(PredictiveMet(0, 0, 0, 0.5, true), 0.0);  // nothing to measure: not met
  // 20 of 20 detected with 20 to come: the whole campaign reaching 80 % is all but sure; 10 of
  // 20 with 20 to come, hopeless; a bound within reach is in between.
  EXPECT_GT(PredictiveMet(20, 20, 20, 0.8, true), 0.99);
  EXPECT_LT(PredictiveMet(10, 20, 20, 0.8, true), 0.01);
  const double middle = PredictiveMet(16, 20, 20, 0.8, true);
  EXPECT_GT(middle, 0.3);
  EXPECT_LT(middle, 0.8);
  // More runs seen at the same rate: more certain.
  EXPECT_GT(PredictiveMet(0, 60, 20, 0.05, false), PredictiveMet(0, 20, 60, 0.05, false));
  // Large remainders take the beta limit: 99 of 100 with 100000 to come reaches 95 % with
  // probability 0.98336 (the exact sum of the 100000 terms); the normal approximation said
  // 0.998, past a 0.99 confidence.
  EXPECT_NEAR(PredictiveMet(99, 100, 100000, 0.95, true), 0.9833566420590406, 1e-4);
}

// Brute force for the beta-binomial (Boost.Math has none): the Polya urn. With a Jeffreys
// prior, after j successes in i further runs the next succeeds with probability
// (s + 1/2 + j) / (n + 1 + i); every one of the 2^remaining sequences is weighed and those
// whose final count meets the bound are summed.
double BruteForcePredictiveMet(long s, long n, long remaining, double bound, bool is_min) {
  const double total = static_cast<double>(n + remaining);
  double met = 0;
  for (unsigned long seq = 0; seq < (1ul << remaining); ++seq) {
    double p = 1;
    long j = 0;
    for (long i = 0; i < remaining; ++i) {
      const double up = (s + 0.5 + j) / (n + 1.0 + i);
      if (seq >> i & 1ul) {
        p *= up;
        ++j;
      } else {
        p *= 1 - up;
      }
    }
    const double final_successes = static_cast<double>(s + j);
    if (is_min ? final_successes >= bound * total - 1e-9 : final_successes <= bound * total + 1e-9) met += p;
  }
  return met;
}

TEST(EarlyStopPrediction, MatchesThePolyaUrnByEnumeration) {
  for (long n : {1L, 4L, 10L, 30L}) {
    for (long s = 0; s <= n; s += (n > 4 ? 3 : 1)) {
      for (long remaining : {1L, 5L, 12L}) {
        for (double bound : {0.05, 0.5, 0.8, 0.95}) {
          for (bool is_min : {true, false}) {
            EXPECT_NEAR(PredictiveMet(s, n, remaining, bound, is_min),
                        BruteForcePredictiveMet(s, n, remaining, bound, is_min), 1e-12)
                << s << " of " << n << ", " << remaining << " to come, bound " << bound << (is_min ? " min" : " max");
          }
        }
      }
    }
  }
}

// Beyond 5000 runs to come the prediction is the beta limit of the beta-binomial: within 0.002
// of the exact sum, where the normal approximation it replaced was off by up to 0.08 (9 of 10
// seen, bound 0.9: exact 0.439, normal 0.357).
TEST(EarlyStopPrediction, LargeRemaindersStayCloseToTheExactSum) {
  auto exact = [](long s, long n, long remaining, double bound) {  // is_min
    const double a = s + 0.5, b = n - s + 0.5;
    const long need = static_cast<long>(std::ceil(bound * static_cast<double>(n + remaining) - 1e-9)) - s;
    auto log_beta = [](double x, double y) { return std::lgamma(x) + std::lgamma(y) - std::lgamma(x + y); };
    double sum = 0;
    for (long k = std::max(0L, need); k <= remaining; ++k) {
      sum += std::exp(std::lgamma(remaining + 1.0) - std::lgamma(k + 1.0) - std::lgamma(remaining - k + 1.0) +
                      log_beta(k + a, remaining - k + b) - log_beta(a, b));
    }
    return sum;
  };
  for (auto [s, n] : {std::pair<long, long>{9, 10}, {95, 100}, {190, 200}, {900, 1000}, {20, 20}}) {
    for (double bound : {0.5, 0.8, 0.9, 0.95, 0.99}) {
      EXPECT_NEAR(PredictiveMet(s, n, 6000, bound, true), exact(s, n, 6000, bound), 2e-3)
          << s << " of " << n << ", bound " << bound;
    }
  }
}

TEST(EarlyStopOrder, VisitsEveryCaseOnce) {
  for (long n : {1L, 2L, 7L, 52L, 176L, 208L, 1000L}) {
    const EarlyStopOrder order(n, 2026);
    std::set<long> seen;
    for (long k = 0; k < n; ++k) seen.insert(order.CaseIndex(k));
    EXPECT_EQ(static_cast<long>(seen.size()), n);
    EXPECT_EQ(*seen.begin(), 0);
    EXPECT_EQ(*seen.rbegin(), n - 1);
  }
}

// 1.5-s runs: K_T loss on the moving joint, and healthy runs; floors the first runs decide.
json SmallCampaign() {
  return json::parse(R"({
    "name": "early", "seed": 9, "duration_s": 1.5,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.3, 0.5], "onset_s": 0.5}],
    "healthy": 40, "repetitions": 10,
    "floors": {"false_alarm_rate": 0.2, "detection_rate": 0.01}
  })");
}

struct Outcome {
  RunnerResult result;
  std::string results, decisions, early;
};

Outcome RunInto(const ScratchDir& dir, const json& campaign_json, int threads, bool resume = false, long stop_after = -1) {
  const Campaign c = CampaignFromJson(campaign_json, "early.json", ".");
  RunnerOptions o;
  o.output_dir = dir.path().string();
  o.threads = threads;
  o.resume = resume;
  o.early_stop = EarlyStopOptions();
  std::atomic<bool> stop{false};
  o.stop = &stop;
  o.progress = [&](long done, long) {
    if (stop_after >= 0 && done >= stop_after) stop.store(true);
  };
  Outcome r;
  r.result = RunCampaign(c, o);
  r.results = ReadAll(dir.path() / "results.jsonl");
  r.decisions = ReadAll(dir.path() / "decisions.jsonl");
  if (std::filesystem::exists(dir.path() / "early_stop.json")) r.early = ReadAll(dir.path() / "early_stop.json");
  return r;
}

TEST(EarlyStopRun, SameRunsForAnyThreadCountInCaseOrderAndResumable) {
  ScratchDir one("early_one"), two("early_two"), resumed("early_resumed");
  const Outcome a = RunInto(one, SmallCampaign(), 1);
  const Outcome b = RunInto(two, SmallCampaign(), 2);
  EXPECT_EQ(a.results, b.results);
  EXPECT_EQ(a.decisions, b.decisions);
  EXPECT_EQ(a.early, b.early);
  const json report = json::parse(a.early);
  EXPECT_TRUE(report["decided"]);
  EXPECT_EQ(report["cases"], 60);
  EXPECT_LT(report["runs"].get<long>(), 60);  // it stopped early
  EXPECT_EQ(report["runs"].get<long>() + report["saved"].get<long>(), 60);
  EXPECT_EQ(a.result.ran, report["runs"].get<long>());
  // Written in case order, as every reader expects.
  long previous = -1, lines = 0;
  std::istringstream text(a.results);
  for (std::string line; std::getline(text, line); ++lines) {
    const long index = json::parse(line)["case"].get<long>();
    EXPECT_GT(index, previous);
    previous = index;
  }
  EXPECT_EQ(lines, report["runs"].get<long>());

  // Interrupted after 7 runs, then resumed: the same bytes as never interrupted.
  const Outcome cut = RunInto(resumed, SmallCampaign(), 2, false, 7);
  EXPECT_TRUE(cut.result.interrupted);
  EXPECT_TRUE(cut.early.empty());
  const Outcome rest = RunInto(resumed, SmallCampaign(), 2, true);
  EXPECT_GE(rest.result.resumed, 7);
  EXPECT_EQ(rest.results, a.results);
  EXPECT_EQ(rest.decisions, a.decisions);
  EXPECT_EQ(rest.early, a.early);
  // Resuming a finished one runs nothing.
  const Outcome again = RunInto(resumed, SmallCampaign(), 2, true);
  EXPECT_EQ(again.result.ran, 0);
  EXPECT_EQ(again.results, a.results);
}

TEST(EarlyStopRun, DecidesEachFloorAsTheWholeCampaign) {
  // A false-alarm floor the healthy runs meet and a detection floor of 100 %, which the short
  // runs' misses break: each decided on part of the runs, as the full run decides it.
  json campaign = SmallCampaign();
  campaign["floors"] = {{"false_alarm_rate", 0.2}, {"detection_rate", 1.0}};
  ScratchDir early_dir("early_decides"), full_dir("early_full");
  const Outcome early = RunInto(early_dir, campaign, 2);
  const Campaign c = CampaignFromJson(campaign, "early.json", ".");
  RunnerOptions o;
  o.output_dir = full_dir.path().string();
  o.threads = 2;
  RunCampaign(c, o);
  SummaryBuilder full;
  std::istringstream text(ReadAll(full_dir.path() / "results.jsonl"));
  for (std::string line; std::getline(text, line);) full.Add(RunRecordFromJson(json::parse(line)));
  const std::vector<FloorVerdict> truth = full.Verdicts(c.floors);
  const json report = json::parse(early.early);
  ASSERT_EQ(report["floors"].size(), truth.size());
  for (size_t f = 0; f < truth.size(); ++f) {
    EXPECT_EQ(report["floors"][f]["name"], truth[f].name);
    EXPECT_TRUE(report["floors"][f]["decided"]) << truth[f].name;
    EXPECT_EQ(report["floors"][f]["met"], truth[f].met) << truth[f].name << ": " << truth[f].message;
  }
}

TEST(EarlyStopRun, NotWithAShardNorWithoutFloors) {
  ScratchDir dir("early_bad");
  const Campaign c = CampaignFromJson(SmallCampaign(), "early.json", ".");
  RunnerOptions o;
  o.output_dir = dir.path().string();
  o.early_stop = EarlyStopOptions();
  o.shard = {0, 2};
  EXPECT_THAT(ErrorOf([&] { RunCampaign(c, o); }).what(), HasSubstr("--early-stop: decides the campaign's floors"));
  json no_floors = SmallCampaign();
  no_floors.erase("floors");
  o.shard = {};
  const InputError e = ErrorOf([&] { RunCampaign(CampaignFromJson(no_floors, "early.json", "."), o); });
  EXPECT_EQ(e.pointer(), "/floors");
  EXPECT_THAT(e.what(), HasSubstr("this campaign sets none"));
}

}  // namespace
}  // namespace armfault
