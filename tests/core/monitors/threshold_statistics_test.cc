// Published statistics (core/monitors/threshold_statistics.h): the compact record re-scores every
// level exactly (the first alarm under each level is the first tick above it, by brute force),
// ties go to the lower joint then the earlier statistic, as ScoreVerdicts does, and the record
// round-trips through JSON with the times as records hold them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/monitors/threshold_statistics.h"

namespace armfault {
namespace {

using testing::HasSubstr;

std::vector<StatisticInfo> TwoStatistics() {
  return {{"kt_deficit", "kt_degradation", 0.2, "/kt"}, {"drag", "friction_increase", 1.5, ""}};
}

TEST(ThresholdStatistics, EveryLevelReScoresToTheFirstTickAboveIt) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  const double onset_s = 1.0, h = 0.2;
  ThresholdRecorder recorder({{"x", "kt_degradation", h, ""}}, 1, onset_s);
  std::vector<std::pair<double, double>> ticks;
  double drift = 0;
  for (int k = 0; k < 3000; ++k) {
    const double t = 0.002 * k;
    if (t >= onset_s) drift += 1e-4;  // a fault that grows, with noise on it
    const double v = (k % 97 == 5) ? std::nan("") : 0.05 + drift + noise(rng);
    recorder.Record(t, &v);
    ticks.emplace_back(t, v);
  }
  const ThresholdStats& s = recorder.stats();
  ASSERT_EQ(s.traces.size(), 1u);
  const ThresholdStats::Trace& trace = s.traces[0];
  EXPECT_LE(trace.rise.size(), static_cast<size_t>(2 * kLevelSteps + 1));
  double pre_max = -INFINITY;
  for (const auto& [t, v] : ticks) {
    if (t < onset_s && !std::isnan(v)) pre_max = std::max(pre_max, v);
  }
  EXPECT_EQ(trace.pre_max, pre_max);
  for (int k = -kLevelSteps; k <= kLevelSteps; ++k) {
    const double level = LevelThreshold(h, k);
    double expected = -1;
    for (const auto& [t, v] : ticks) {
      if (t >= onset_s && v > level) {
        expected = t;
        break;
      }
    }
    const ThresholdStats::Rise* first = FirstAlarm(trace, level);
    if (expected < 0) {
      EXPECT_EQ(first, nullptr) << "level " << k;
    } else {
      ASSERT_NE(first, nullptr) << "level " << k;
      EXPECT_EQ(first->t_s, expected) << "level " << k;
    }
  }
  EXPECT_EQ(s.first_tick_s, 1.0);
}

TEST(ThresholdStatistics, TiesGoToTheLowerJointThenTheEarlierStatistic) {
  ThresholdRecorder recorder(TwoStatistics(), 2, 0.5);
  // joint-major: [j1 kt, j1 drag, j2 kt, j2 drag]
  const double before[4] = {0.25, 0, 0, 0};  // joint 1 alarms before the onset only
  const double quiet[4] = {0.1, 1.0, 0.1, 1.0};
  const double both[4] = {0.1, 2.0, 0.3, 2.0};  // at 0.6 s: joint 1 drag, joint 2 kt and drag
  recorder.Record(0.0, before);
  recorder.Record(0.5, quiet);
  recorder.Record(0.6, both);
  const ThresholdOutcome out = DecideThresholds(recorder.stats(), {0.2, 1.5});
  EXPECT_TRUE(out.alarm_before_onset);
  EXPECT_TRUE(out.detected);
  EXPECT_EQ(out.detection_time_s, 0.6);
  EXPECT_EQ(out.joint, 1);
  EXPECT_EQ(out.family, "friction_increase");
  // Only joint 2's kt_deficit under a higher drag threshold.
  const ThresholdOutcome kt = DecideThresholds(recorder.stats(), {0.2, 2.5});
  EXPECT_EQ(kt.joint, 2);
  EXPECT_EQ(kt.family, "kt_degradation");
  const ThresholdOutcome none = DecideThresholds(recorder.stats(), {0.4, 2.5});
  EXPECT_FALSE(none.detected);
  EXPECT_FALSE(none.alarm_before_onset);
}

TEST(ThresholdStatistics, RoundTripsThroughJsonWithTimesInMicroseconds) {
  ThresholdRecorder recorder(TwoStatistics(), 1, 0.0);
  const double v[2] = {0.5, 1.0};
  recorder.Record(0.1 + 0.2, v);  // 0.30000000000000004
  const nlohmann::json j = ToJson(recorder.stats());
  EXPECT_EQ(j["kind"], "threshold_statistics");
  const ThresholdStats back = ThresholdStatsFromJson(j);
  EXPECT_EQ(back.statistics.size(), 2u);
  EXPECT_EQ(back.statistics[0].setting, "/kt");
  ASSERT_EQ(back.traces.size(), 2u);
  EXPECT_EQ(back.traces[0].rise[0].t_s, 0.3);
  EXPECT_EQ(back.first_tick_s, 0.3);
  EXPECT_EQ(ToJson(back), j);
  nlohmann::json bad = j;
  bad["traces"][0]["statistic"] = 7;
  EXPECT_THROW(ThresholdStatsFromJson(bad), std::runtime_error);
  bad = j;
  bad["levels"]["steps"] = 3;
  EXPECT_THROW(ThresholdStatsFromJson(bad), std::runtime_error);
}

TEST(ThresholdStatistics, DeclarationsAgainstTheContractAreNamed) {
  EXPECT_EQ(CheckStatistics(TwoStatistics()), "");
  std::vector<StatisticInfo> s = TwoStatistics();
  s[1].name = "kt_deficit";
  EXPECT_THAT(CheckStatistics(s), HasSubstr("statistic 2 (\"kt_deficit\"): name declared twice"));
  s = TwoStatistics();
  s[0].threshold = 0;
  EXPECT_THAT(CheckStatistics(s), HasSubstr("threshold 0 is not a number > 0"));
  s = TwoStatistics();
  s[0].family = "";
  EXPECT_THAT(CheckStatistics(s), HasSubstr("names no family"));
  s = TwoStatistics();
  s[0].setting = "kt";
  EXPECT_THAT(CheckStatistics(s), HasSubstr("is not a JSON pointer"));
}

TEST(ThresholdStatistics, AMissIsExplainedByTheClosestStatisticOfTheFaultedJoint) {
  ThresholdRecorder recorder(TwoStatistics(), 2, 0.0);
  const double v[4] = {0.15, 0.5, 0.0, 0.0};
  recorder.Record(0.1, v);
  RunScore score;
  EXPECT_EQ(ExplainThresholds(recorder.stats(), score, "kt_degradation", 1),
            "no alarm: kt_deficit of joint 1 reached 0.15 at most, 75 % of its threshold 0.2");
  EXPECT_THAT(ExplainThresholds(recorder.stats(), score, "kt_degradation", 2), HasSubstr("no alarm: no statistic of joint 2"));
}

}  // namespace
}  // namespace armfault
