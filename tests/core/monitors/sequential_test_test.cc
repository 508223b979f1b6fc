// The sequential decision (core/monitors/sequential_test.h): Siegmund's run length, its
// inverse, a CUSUM on a known stream against it, the thresholds' split over an arm's tests, and
// the settings' errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

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

// A healthy residual as the model states it: a bias that wanders (clamped at its bound), seen
// through white noise of a known standard error. The walks below use a bound of 10 that the
// bias never reaches, walking 0.019 per look as a bias bound at 0.15 wandering over it in 60 s:
// the filter is then the exact Kalman filter of the walk, and its innovations are white.
struct Residual {
  double bound, wander_s, se, look_s;
  std::mt19937_64 rng;
  double beta = 0;
  double Next() {
    std::normal_distribution<double> n(0.0, 1.0);
    beta = std::clamp(beta + bound * std::sqrt(look_s / wander_s) * n(rng), -bound, bound);
    return beta + se * n(rng);
  }
};

TEST(SequentialTest, TheBiasFiltersInnovationsOfAHealthyResidualAreWhite) {
  Residual r{10.0, 60.0 * (10.0 / 0.15) * (10.0 / 0.15), 0.02, 1.0, std::mt19937_64(11)};
  BiasFilter filter(r.bound, r.wander_s, 0.0, 1.0, false);
  const int looks = 200000;
  double sum = 0, sum2 = 0, lag = 0, last = 0;
  for (int i = 0; i < looks; ++i) {
    const BiasFilter::Innovation in = filter.Look(r.look_s, r.Next(), r.se);
    const double z = in.nu / in.sd;
    sum += z;
    sum2 += z * z;
    lag += z * last;
    last = z;
  }
  const double mean = sum / looks;
  EXPECT_NEAR(mean, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(sum2 / looks - mean * mean), 1.0, 0.05);
  EXPECT_NEAR(lag / looks, 0.0, 0.03);
}

// Looks until alarm of the full test (filter and CUSUM) on a healthy residual, against the
// CUSUM's own run length on white noise: the target rate holds through the filter.
TEST(SequentialTest, TheFilteredCusumOnAHealthyResidualRunsAsLongAsSiegmundSays) {
  const double h = 4.0;
  double total = 0;
  const int runs = 2000;
  for (int k = 0; k < runs; ++k) {
    Residual r{10.0, 60.0 * (10.0 / 0.15) * (10.0 / 0.15), 0.02, 1.0, std::mt19937_64(100 + static_cast<uint64_t>(k))};
    SequentialTest test(1.0, 0.5, r.bound, r.wander_s, 0.0, 1.0, false);
    const auto whiten = [](double nu, double sd) { return nu / sd; };
    long looks = 0;
    do ++looks;
    while (test.Tick(1.0, r.Next(), r.se, whiten) <= h && looks < 100000);
    total += static_cast<double>(looks);
  }
  EXPECT_NEAR(total / runs, SiegmundArl(h, 0.5), 0.12 * SiegmundArl(h, 0.5));
}

// Wear is never learned away: the bias may follow a deviation only up to its bound, so friction
// worn 1.5x from the start, a 1.5x reached over five minutes, and an abrupt 1.1x K_T loss are
// each found, while the bias estimate never passes m.
TEST(SequentialTest, WearBeyondTheBoundIsFoundHoweverItComes) {
  const auto whiten = [](double nu, double sd) { return nu / sd; };
  const double h = 8.0;  // an arm's threshold at about 1 alarm per hour
  struct Case {
    const char* name;
    double bound, se, onset_s, ramp_s, size;
    double max_latency_s;
  };
  for (const Case& w : {Case{"from the start", 0.15, 0.03, 0, 0, 0.5, 10}, Case{"ramp", 0.15, 0.03, 60, 300, 0.5, 300},
                        Case{"abrupt", 0.03, 0.01, 60, 0, 0.1, 3}}) {
    SequentialTest test(1.0, 0.5, w.bound, 60.0, 60.0, 1.0, false);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> n(0.0, w.se);
    double found_s = -1;
    for (int i = 1; i <= 1200 && found_s < 0; ++i) {
      const double t = i;
      const double share = t < w.onset_s ? 0.0 : (w.ramp_s > 0 ? std::min(1.0, (t - w.onset_s) / w.ramp_s) : 1.0);
      if (test.Tick(1.0, w.size * share + n(rng), w.se, whiten) > h) found_s = t;
      EXPECT_LE(test.bias().bias(), w.bound + 1e-12) << w.name;
    }
    EXPECT_GE(found_s, w.onset_s) << w.name;
    EXPECT_LE(found_s, w.onset_s + w.ramp_s + w.max_latency_s) << w.name;
  }
}

// The drift's bias is signed: the filter holds it inside [-m, m], and both of its CUSUMs see
// an offset beyond.
TEST(SequentialTest, TheSignedDriftIsBoundedBothWays) {
  const auto whiten = [](double nu, double sd) { return nu / sd; };
  for (double offset : {-1.0, 1.0}) {
    SequentialTest test(8.0, 0.5, 0.3, 60.0, 60.0, 1.0, true);
    double s = 0;
    for (int i = 0; i < 20; ++i) s = test.Tick(8.0, offset, 0.05, whiten);
    EXPECT_NEAR(test.bias().bias(), 0.3 * offset, 1e-12) << offset;
    EXPECT_GT(s, 50.0) << offset;
  }
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
  // The residual model's constants have their ranges: a scale of 0 or a wander time of 0 would
  // make every innovation infinite or the bias stand still.
  for (const char* key : {"kt_se_scale", "friction_factor_bias_wander_s", "sequential_settle_s"}) {
    const InputError range = ErrorOf([&] {
      MonitorConfigFromJson(json{{"decision", "sequential"}, {key, key == std::string("sequential_settle_s") ? -1.0 : 0.0}},
                            "/monitor", "c.json");
    });
    EXPECT_EQ(range.source(), "c.json");
    EXPECT_EQ(range.pointer(), std::string("/monitor/") + key);
  }
  const InputError misplaced =
      ErrorOf([] { MonitorConfigFromJson(json{{"sensor_drift_se_scale", 0.1}}, "/monitor", "c.json"); });
  EXPECT_EQ(misplaced.pointer(), "/monitor/sensor_drift_se_scale");
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
