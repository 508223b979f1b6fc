// The sequential decision (core/monitors/sequential_test.h): Siegmund's run length, its
// inverse, a CUSUM on a known stream against it, the thresholds' split over an arm's tests, and
// the settings' errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/monitors/monitor_config.h"
#include "core/monitors/sequential_test.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;

TEST(SequentialTest, SiegmundsRunLengthHasItsPublishedValue) {
  // k = 0.5: Siegmund's approximation gives 338 looks at h = 4 and 938 at h = 5; the exact
  // one-sided in-control ARLs are 336 and 930 (twice the two-sided 168 and 465 of Montgomery,
  // Introduction to Statistical Quality Control, table 9.2).
  EXPECT_NEAR(SiegmundArl(4.0, 0.5), 338.1, 0.2);
  EXPECT_NEAR(SiegmundArl(5.0, 0.5), 938.5, 0.5);
  EXPECT_LT(SiegmundArl(4.0, 0.5), SiegmundArl(4.1, 0.5));
}

TEST(SequentialTest, TheThresholdIsTheRunLengthsInverse) {
  for (double arl : {50.0, 1e3, 1e5, 1e8}) {
    const double h = CusumThreshold(arl, 0.5);
    EXPECT_NEAR(SiegmundArl(h, 0.5), arl, 1e-6 * arl) << arl;
  }
  // Shorter than even h = 0 runs: the threshold is 0.
  EXPECT_EQ(CusumThreshold(1.0, 0.5), 0.0);
}

// Looks until S > h of a CUSUM fed iid N(mean, 1) innovations, one per look.
double MeanRunLength(double mean, double h, int runs, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z(mean, 1.0);
  double total = 0;
  for (int r = 0; r < runs; ++r) {
    Cusum cusum(1.0, 0.5);
    long looks = 0;
    do ++looks;
    while (cusum.Tick(1.0, z(rng)) <= h);
    total += static_cast<double>(looks);
  }
  return total / runs;
}

TEST(SequentialTest, ACusumOnWhiteNoiseRunsAsLongAsSiegmundSays) {
  // 3000 runs: the mean's standard error is ~2 % of it.
  const double healthy = MeanRunLength(0.0, 4.0, 3000, 7);
  EXPECT_NEAR(healthy, 336.0, 0.08 * 336.0);
  // A shift of 2k standard deviations (what k = 0.5 is optimal for) is found within ~10 looks
  // (Montgomery's table 9.2: 8.38).
  const double shifted = MeanRunLength(1.0, 4.0, 3000, 8);
  EXPECT_NEAR(shifted, 8.4, 1.0);
}

TEST(SequentialTest, ACusumLooksOnlyOnceALookHasPassed) {
  Cusum cusum(1.0, 0.5);
  // Ticks of 0.25 s: only every fourth adds its innovation.
  EXPECT_EQ(cusum.Tick(0.25, 3.0), 0.0);
  EXPECT_EQ(cusum.Tick(0.25, 3.0), 0.0);
  EXPECT_EQ(cusum.Tick(0.25, 3.0), 0.0);
  EXPECT_DOUBLE_EQ(cusum.Tick(0.25, 3.0), 2.5);
  EXPECT_DOUBLE_EQ(cusum.Tick(0.25, -10.0), 2.5);
  // S never falls below 0.
  for (int i = 0; i < 3; ++i) cusum.Tick(0.25, -10.0);
  EXPECT_EQ(cusum.statistic(), 0.0);
}

TEST(SequentialTest, ThresholdsSplitTheArmsRateOverItsTests) {
  MonitorConfig c;
  c.decision = kSequentialDecision;
  c.target_false_alarms_per_hour = 2.0;
  const DetectorThresholds h = SequentialThresholds(c, 15);
  const std::array<double, kDetectorCount> looks = SequentialLooks(c);
  for (int d = 0; d < kDetectorCount; ++d) {
    // each of the 15 CUSUMs raises 2 / 15 false alarms per hour
    EXPECT_NEAR(SiegmundArl(h[d], c.sequential_allowance_sd), 3600.0 / looks[d] * 15 / 2.0, 1e-3) << d;
    EXPECT_GT(SequentialThresholds(c, 30)[d], h[d]);        // more tests, higher thresholds
    EXPECT_LT(SequentialThresholds(c, 15, 20.0)[d], h[d]);  // a higher rate, lower ones
  }
  // Three joints with torque sensors: K_T, resistance and friction per joint, the drift both ways.
  EXPECT_EQ(SequentialTestCount(3, 3), 15);
  EXPECT_EQ(SequentialTestCount(6, 0), 18);
}

TEST(SequentialSettings, RoundTripOnlyWithTheSequentialDecision) {
  // The default decision writes none of the sequential fields: its settings read as before.
  const json defaults = MonitorConfigToJson(MonitorConfig());
  EXPECT_FALSE(defaults.contains("decision"));
  EXPECT_FALSE(defaults.contains("target_false_alarms_per_hour"));
  const MonitorConfig c = MonitorConfigFromJson(
      json{{"decision", "sequential"}, {"target_false_alarms_per_hour", 0.5}, {"kt_model_error", 0.04}}, "", "m.json");
  EXPECT_EQ(c.decision, kSequentialDecision);
  EXPECT_EQ(c.target_false_alarms_per_hour, 0.5);
  const json written = MonitorConfigToJson(c);
  EXPECT_EQ(written["decision"], "sequential");
  EXPECT_EQ(written["kt_model_error"], 0.04);
  EXPECT_EQ(MonitorConfigToJson(MonitorConfigFromJson(written, "", "m.json")), written);
}

TEST(SequentialSettings, ABadRateOrAMisplacedFieldNamesItsPointer) {
  for (double bad : {0.0, -1.0}) {
    const InputError e = ErrorOf([&] {
      MonitorConfigFromJson(json{{"decision", "sequential"}, {"target_false_alarms_per_hour", bad}}, "/monitor", "c.json");
    });
    EXPECT_EQ(e.source(), "c.json");
    EXPECT_EQ(e.pointer(), "/monitor/target_false_alarms_per_hour");
    EXPECT_THAT(e.message(), HasSubstr("alarms per hour must be > 0"));
  }
  const InputError alone =
      ErrorOf([] { MonitorConfigFromJson(json{{"target_false_alarms_per_hour", 1}}, "/monitor", "c.json"); });
  EXPECT_EQ(alone.pointer(), "/monitor/target_false_alarms_per_hour");
  EXPECT_THAT(alone.message(), HasSubstr("\"decision\": \"sequential\""));
  const InputError typo = ErrorOf([] { MonitorConfigFromJson(json{{"decision", "sequental"}}, "/monitor", "c.json"); });
  EXPECT_EQ(typo.pointer(), "/monitor/decision");
  EXPECT_THAT(typo.message(), HasSubstr("sequential"));
  // More than one alarm per controller tick is no rate a test can have.
  MonitorConfig c;
  c.decision = kSequentialDecision;
  c.target_false_alarms_per_hour = 2e6;
  const InputError tick = ErrorOf([&] { ValidateDecisionRate(c, 500.0, "/monitor", "c.json"); });
  EXPECT_EQ(tick.pointer(), "/monitor/target_false_alarms_per_hour");
  EXPECT_THAT(tick.message(), HasSubstr("more than one per controller tick"));
  c.target_false_alarms_per_hour = 1.8e6;  // one per tick at 500 Hz
  ValidateDecisionRate(c, 500.0, "/monitor", "c.json");
}

}  // namespace
}  // namespace armfault
