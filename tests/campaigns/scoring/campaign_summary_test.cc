#include "campaigns/scoring/campaign_summary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace armfault {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

const char kKt[] = "kt_degradation";
const char kStuck[] = "torque_sensor_stuck";
const char kKtGroup[] = "kt_degradation kt_factor=0.9 joint=2";
const char kStuckGroup[] = "torque_sensor_stuck joint=1";

RunRecord Faulty(const std::string& id, const std::string& family, int joint, const std::string& group) {
  RunRecord r;
  r.run_id = id;
  r.family = family;
  r.joint = joint;
  r.group = group;
  r.onset_s = 1.0;
  if (family == kKt) {
    r.magnitude_key = "kt_factor";
    r.magnitude = 0.9;
  }
  return r;
}

RunRecord Detect(RunRecord r, const std::string& isolated_family, int isolated_joint, double latency_s) {
  r.detected = true;
  r.isolated_family = isolated_family;
  r.isolated_joint = isolated_joint;
  r.latency_s = latency_s;
  r.detection_time_s = r.onset_s + latency_s;
  return r;
}

RunRecord Healthy(const std::string& id, bool alarm) {
  RunRecord r;
  r.run_id = id;
  r.group = "healthy";
  r.detected = alarm;
  if (alarm) {
    r.isolated_family = kKt;
    r.isolated_joint = 3;
  }
  return r;
}

// A small mixed campaign whose every number is worked out by hand below:
//   kt_degradation j2: 3 of 4 detected, 2 of 3 isolated correctly, 1 alarm before onset;
//   torque_sensor_stuck j1: 2 of 2 detected, 1 of 2 isolated (the other "unknown");
//   healthy: 1 of 4 alarmed (as kt_degradation); one failed run that must count nowhere else.
std::vector<RunRecord> MixedRecords() {
  std::vector<RunRecord> v;
  RunRecord r1 = Detect(Faulty("kt/r1", kKt, 2, kKtGroup), kKt, 2, 0.1);
  r1.magnitude_name = "kt_factor";
  r1.magnitude_estimate = 0.85;
  v.push_back(r1);
  RunRecord r2 = Detect(Faulty("kt/r2", kKt, 2, kKtGroup), kKt, 2, 0.3);
  r2.magnitude_name = "kt_factor";
  r2.magnitude_estimate = 0.99;
  v.push_back(r2);
  RunRecord r3 = Detect(Faulty("kt/r3", kKt, 2, kKtGroup), kStuck, 2, 0.2);
  r3.magnitude_name = "kt_factor";
  r3.magnitude_estimate = 0.5;  // wrongly isolated: must not enter the magnitude error
  v.push_back(r3);
  RunRecord r4 = Faulty("kt/r4", kKt, 2, kKtGroup);
  r4.alarm_before_onset = true;
  v.push_back(r4);
  v.push_back(Detect(Faulty("stuck/r1", kStuck, 1, kStuckGroup), kStuck, 1, 0.5));
  v.push_back(Detect(Faulty("stuck/r2", kStuck, 1, kStuckGroup), "", 0, 0.4));
  v.push_back(Healthy("healthy/0", false));
  v.push_back(Healthy("healthy/1", true));
  v.push_back(Healthy("healthy/2", false));
  v.push_back(Healthy("healthy/3", false));
  RunRecord failed = Detect(Faulty("kt/r5", kKt, 2, kKtGroup), kKt, 2, 0.05);
  failed.ok = false;
  failed.failure_reason = "simulation diverged";
  v.push_back(failed);
  return v;
}

SummaryBuilder BuilderOf(const std::vector<RunRecord>& records) {
  SummaryBuilder b;
  for (const RunRecord& r : records) b.Add(r);
  return b;
}

void ExpectRate(const nlohmann::json& j, long successes, long trials) {
  EXPECT_EQ(j.at("successes").get<long>(), successes) << j.dump();
  EXPECT_EQ(j.at("trials").get<long>(), trials) << j.dump();
  const RateInterval w = Wilson(successes, trials);
  EXPECT_EQ(j.at("rate").get<double>(), w.rate) << j.dump();
  EXPECT_EQ(j.at("low").get<double>(), w.low) << j.dump();
  EXPECT_EQ(j.at("high").get<double>(), w.high) << j.dump();
}

TEST(CampaignSummaryWilsonTest, MatchesTheClosedFormForEightOfTen) {
  const RateInterval w = Wilson(8, 10);
  EXPECT_DOUBLE_EQ(w.rate, 0.8);
  // High-precision evaluation of the Wilson formula with z = 1.959963984540054.
  EXPECT_NEAR(w.low, 0.490162471536641740, 1e-9);
  EXPECT_NEAR(w.high, 0.943317848545624737, 1e-9);
}

TEST(CampaignSummaryWilsonTest, MatchesNewcombe1998) {
  // Newcombe (1998), "Two-sided confidence intervals for the single proportion", the score
  // method (3) on its four examples, to the paper's 4 decimals; and to 1e-15 the same formula
  // at 40 digits (mpmath, z = sqrt(2) erfinv(0.95)).
  const struct {
    long s, n;
    double low4, high4, low, high;
  } cases[] = {{81, 263, 0.2553, 0.3662, 0.25528851987827422577, 0.36620957698280007015},
               {15, 148, 0.0624, 0.1605, 0.062386399530736279792, 0.16048724172330803892},
               {0, 20, 0.0000, 0.1611, 0.0, 0.16112515805281938715},
               {1, 29, 0.0061, 0.1718, 0.0061132142927626605164, 0.17175521879320288131}};
  for (const auto& c : cases) {
    const RateInterval w = Wilson(c.s, c.n);
    EXPECT_NEAR(w.low, c.low4, 5e-5) << c.s << "/" << c.n;
    EXPECT_NEAR(w.high, c.high4, 5e-5) << c.s << "/" << c.n;
    EXPECT_NEAR(w.low, c.low, 1e-15) << c.s << "/" << c.n;
    EXPECT_NEAR(w.high, c.high, 1e-15) << c.s << "/" << c.n;
  }
  // A rate near 1, 130 of 136: mpmath as above.
  EXPECT_NEAR(Wilson(130, 136).low, 0.90709245549022264671, 1e-15);
  EXPECT_NEAR(Wilson(130, 136).high, 0.97962598298798162203, 1e-15);
}

TEST(CampaignSummaryWilsonTest, EdgesAreExact) {
  const RateInterval none = Wilson(0, 0);
  EXPECT_EQ(none.rate, 0.0);
  EXPECT_EQ(none.low, 0.0);
  EXPECT_EQ(none.high, 1.0);
  EXPECT_EQ(Wilson(0, 7).low, 0.0);
  EXPECT_GT(Wilson(0, 7).high, 0.0);
  EXPECT_EQ(Wilson(7, 7).high, 1.0);
  EXPECT_LT(Wilson(7, 7).low, 1.0);
  EXPECT_THROW(Wilson(3, 2), std::invalid_argument);
  EXPECT_THROW(Wilson(-1, 2), std::invalid_argument);
}

// Two runs whose fault could not act, one of them "missed": by default they are listed apart
// and change no rate; with include_not_excited they are scored like any other run.
TEST(CampaignSummaryTest, NotExcitedRunsAreListedApartAndLeftOutOfTheRates) {
  std::vector<RunRecord> records = MixedRecords();
  RunRecord still = Faulty("kt/still1", kKt, 2, kKtGroup);
  still.not_excited_reason = "joint 2 was asked to move 0 rad after the onset";
  RunRecord still2 = Detect(Faulty("kt/still0", kKt, 2, kKtGroup), kKt, 2, 0.4);
  still2.not_excited_reason = "the fault took no effect: x";
  records.push_back(still);
  records.push_back(still2);
  const nlohmann::json plain = BuilderOf(MixedRecords()).Build(Floors{}, nullptr, "v");
  const nlohmann::json left_out = BuilderOf(records).Build(Floors{}, nullptr, "v");
  EXPECT_EQ(left_out.at("overall").at("detection"), plain.at("overall").at("detection"));
  EXPECT_EQ(left_out.at("per_family").at(kKt).at("isolation"), plain.at("per_family").at(kKt).at("isolation"));
  EXPECT_EQ(left_out.at("runs").at("faulty"), 6);
  EXPECT_EQ(left_out.at("runs").at("not_excited"), 2);
  EXPECT_EQ(left_out.at("overall").at("not_excited"), 2);
  EXPECT_EQ(left_out.at("per_family").at(kKt).at("not_excited"), 2);
  const nlohmann::json& listed = left_out.at("not_excited_runs");
  EXPECT_EQ(listed.at("count"), 2);
  EXPECT_EQ(listed.at("included"), false);
  ASSERT_EQ(listed.at("runs").size(), 2u);
  EXPECT_EQ(listed.at("runs")[0].at("run_id"), "kt/still0");  // sorted by run_id
  EXPECT_EQ(listed.at("runs")[1].at("reason"), still.not_excited_reason);

  SummaryBuilder included(true);
  for (const RunRecord& r : records) included.Add(r);
  const nlohmann::json in = included.Build(Floors{}, nullptr, "v");
  ExpectRate(in.at("overall").at("detection"), 6, 8);  // 5 of 6, plus one of the two
  EXPECT_EQ(in.at("not_excited_runs").at("included"), true);
  EXPECT_EQ(in.at("runs").at("faulty"), 8);
}

TEST(CampaignSummaryTest, JUnitSkipsACaseWhoseRunsWereAllNotExcited) {
  SummaryBuilder b;
  RunRecord still = Faulty("exp1/kt/still", kKt, 2, kKtGroup);
  still.trajectory = "exp1";
  still.not_excited_reason = "joint 2 was asked to move 0 rad after the onset";
  b.Add(still);
  RunRecord seen = Detect(Faulty("p2p/kt/seen", kKt, 2, kKtGroup), kKt, 2, 0.2);
  seen.trajectory = "p2p";
  b.Add(seen);
  Floors floors;
  floors.overall.detection_rate = 0.9;
  const std::string xml = JUnitXml("c", b, floors, "campaign.json");
  EXPECT_THAT(xml, HasSubstr("<skipped message=\"not excited: joint 2 was asked to move 0 rad after the onset\"/>"));
  EXPECT_THAT(xml, HasSubstr("skipped=\"1\""));
  EXPECT_THAT(xml, HasSubstr("1 not excited (left out), e.g. joint 2"));
  EXPECT_THAT(xml, ::testing::Not(HasSubstr("<failure")));
}

TEST(CampaignSummaryTest, CountsRunsAndExcludesFailedOnes) {
  const SummaryBuilder b = BuilderOf(MixedRecords());
  EXPECT_EQ(b.runs(), 11);
  EXPECT_EQ(b.failed_runs(), 1);
  const nlohmann::json s = b.Build(Floors{}, nlohmann::json{{"name", "mixed"}}, "9.9.9");
  EXPECT_EQ(s.at("armfault_version"), "9.9.9");
  EXPECT_EQ(s.at("campaign"), (nlohmann::json{{"name", "mixed"}}));
  EXPECT_EQ(s.at("runs"), (nlohmann::json{{"total", 11}, {"ok", 10}, {"failed", 1}, {"faulty", 6}, {"healthy", 4}, {"not_excited", 0}}));
  EXPECT_EQ(s.at("failed_runs").at("count"), 1);
  EXPECT_EQ(s.at("failed_runs").at("truncated"), false);
  EXPECT_EQ(s.at("failed_runs").at("runs"),
            (nlohmann::json::array({{{"run_id", "kt/r5"}, {"reason", "simulation diverged"}}})));
}

// The healthy runs' false alarms per hour: 4 healthy runs of 15 min, one alarmed, the failed
// one left out; the bound is the exact Poisson one (k = 1: 4.743864518 alarms).
TEST(CampaignSummaryTest, FalseAlarmsPerHourOfHealthyOperation) {
  const SummaryBuilder b = BuilderOf(MixedRecords());
  EXPECT_EQ(b.healthy_runs(), 4);
  EXPECT_EQ(b.healthy_alarms(), 1);
  const HealthyOperation h = HealthyOperationOf(b, 900.0);
  EXPECT_EQ(h.hours, 1.0);
  const nlohmann::json j = h.ToJson();
  EXPECT_EQ(j.at("healthy_runs"), 4);
  EXPECT_EQ(j.at("false_alarms"), 1);
  EXPECT_EQ(j.at("per_hour").get<double>(), 1.0);
  EXPECT_NEAR(j.at("per_hour_upper_95").get<double>(), 4.743864518, 1e-8);
  EXPECT_EQ(h.Line(), "healthy operation: 4 runs, 1 h, 1 false alarm: 1 per hour (95 % upper bound 4.74)");
  // The confounder bench's target: 0 alarms in 120 runs of 10 min support at most 0.150 per hour.
  SummaryBuilder quiet;
  for (int k = 0; k < 120; ++k) quiet.Add(Healthy("h/" + std::to_string(k), false));
  const nlohmann::json q = HealthyOperationOf(quiet, 600.0).ToJson();
  EXPECT_EQ(q.at("hours").get<double>(), 20.0);
  EXPECT_EQ(q.at("per_hour").get<double>(), 0.0);
  EXPECT_NEAR(q.at("per_hour_upper_95").get<double>(), 2.995732273553991 / 20.0, 1e-12);
  EXPECT_EQ(HealthyOperationOf(quiet, 600.0).Line(),
            "healthy operation: 120 runs, 20 h, 0 false alarms: 0 per hour (95 % upper bound 0.15)");
  EXPECT_FALSE(q.contains("set_for_per_hour"));
  // A monitor that states its rate (the sequential decision) has it written beside the measured one.
  EXPECT_EQ(HealthyOperationOf(quiet, 600.0, 0.5).ToJson().at("set_for_per_hour"), 0.5);
  EXPECT_EQ(HealthyOperationOf(quiet, 600.0, 0.5).Line(),
            "healthy operation: 120 runs, 20 h, 0 false alarms: 0 per hour (95 % upper bound 0.15), set for 0.5 per hour");
  // No healthy run: no rate.
  const nlohmann::json none = HealthyOperationOf(SummaryBuilder(), 600.0).ToJson();
  EXPECT_TRUE(none.at("per_hour").is_null());
  EXPECT_TRUE(none.at("per_hour_upper_95").is_null());
}

TEST(CampaignSummaryTest, OverallRatesOnMixedSet) {
  const nlohmann::json o = BuilderOf(MixedRecords()).Build(Floors{}, nullptr, "v").at("overall");
  EXPECT_EQ(o.at("runs"), 10);
  EXPECT_EQ(o.at("faulty_runs"), 6);
  EXPECT_EQ(o.at("healthy_runs"), 4);
  ExpectRate(o.at("detection"), 5, 6);
  ExpectRate(o.at("isolation"), 3, 5);
  ExpectRate(o.at("false_alarm"), 1, 4);
  ExpectRate(o.at("alarm_before_onset_rate"), 1, 6);
  EXPECT_EQ(o.at("detection").at("rate").get<double>(), 5.0 / 6.0);
  EXPECT_EQ(o.at("false_alarm").at("rate").get<double>(), 0.25);
  const nlohmann::json& lat = o.at("latency");
  EXPECT_EQ(lat.at("count"), 5);
  EXPECT_EQ(lat.at("median_s").get<double>(), 0.3);
  EXPECT_EQ(lat.at("p95_s").get<double>(), 0.5);
  EXPECT_EQ(lat.at("misses"), 1);
  const double e1 = std::abs(0.85 - 0.9) / 0.9, e2 = std::abs(0.99 - 0.9) / 0.9;
  const nlohmann::json& mag = o.at("magnitude_error");
  EXPECT_EQ(mag.at("count"), 2);
  EXPECT_DOUBLE_EQ(mag.at("mean").get<double>(), (e1 + e2) / 2);
  EXPECT_DOUBLE_EQ(mag.at("max").get<double>(), e2);
}

TEST(CampaignSummaryTest, PerFamilyAndGroups) {
  const nlohmann::json s = BuilderOf(MixedRecords()).Build(Floors{}, nullptr, "v");
  const nlohmann::json& kt = s.at("per_family").at(kKt);
  ExpectRate(kt.at("detection"), 3, 4);
  ExpectRate(kt.at("isolation"), 2, 3);
  ExpectRate(kt.at("alarm_before_onset_rate"), 1, 4);
  EXPECT_EQ(kt.at("latency").at("median_s").get<double>(), 0.2);
  EXPECT_FALSE(kt.contains("false_alarm"));
  const nlohmann::json& stuck = s.at("per_family").at(kStuck);
  ExpectRate(stuck.at("detection"), 2, 2);
  ExpectRate(stuck.at("isolation"), 1, 2);
  EXPECT_EQ(stuck.at("latency").at("median_s").get<double>(), 0.45);
  EXPECT_EQ(stuck.at("latency").at("misses"), 0);
  EXPECT_EQ(stuck.at("magnitude_error").at("count"), 0);
  EXPECT_TRUE(stuck.at("magnitude_error").at("mean").is_null());
  EXPECT_EQ(s.at("per_family").size(), 2u);

  const nlohmann::json& groups = s.at("groups");
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0].at("group"), "healthy");
  EXPECT_TRUE(groups[0].at("family").is_null());
  EXPECT_TRUE(groups[0].at("joint").is_null());
  ExpectRate(groups[0].at("false_alarm"), 1, 4);
  EXPECT_EQ(groups[1].at("group"), kKtGroup);
  EXPECT_EQ(groups[1].at("family"), kKt);
  EXPECT_EQ(groups[1].at("joint"), 2);
  EXPECT_EQ(groups[1].at("magnitude_key"), "kt_factor");
  EXPECT_EQ(groups[1].at("magnitude").get<double>(), 0.9);
  EXPECT_EQ(groups[1].at("runs"), 4);
  EXPECT_FALSE(groups[1].contains("false_alarm"));
  ExpectRate(groups[1].at("detection"), 3, 4);
  EXPECT_EQ(groups[2].at("group"), kStuckGroup);
  EXPECT_TRUE(groups[2].at("magnitude_key").is_null());
  EXPECT_TRUE(groups[2].at("magnitude").is_null());
}

TEST(CampaignSummaryTest, ConfusionMatrix) {
  const nlohmann::json c = BuilderOf(MixedRecords()).Build(Floors{}, nullptr, "v").at("confusion");
  EXPECT_EQ(c.at("labels"), (nlohmann::json{kKt, kStuck, "healthy", "unknown"}));
  EXPECT_EQ(c.at("counts"), (nlohmann::json{{2, 1, 1, 0},    // kt: r1 r2 | r3 as stuck | r4 missed
                                            {0, 1, 0, 1},    // stuck: one right, one unknown
                                            {1, 0, 3, 0},    // healthy: one alarm as kt
                                            {0, 0, 0, 0}}));  // nothing is truly "unknown"
}

// A fault named right but on the wrong joint: on the family confusion's diagonal, off the
// joint confusion's; per joint and per family x joint rates, false alarms by the joint named.
TEST(CampaignSummaryTest, PerJointRatesAndTheJointConfusionMatrix) {
  std::vector<RunRecord> records = MixedRecords();
  records.push_back(Detect(Faulty("kt/r6", kKt, 2, kKtGroup), kKt, 3, 0.4));  // kt named on joint 3
  const nlohmann::json s = BuilderOf(records).Build(Floors{}, nullptr, "v");
  EXPECT_EQ(s.at("confusion").at("counts").at(0), (nlohmann::json{3, 1, 1, 0}));  // r6 looks right here
  const nlohmann::json c = s.at("confusion_by_joint");
  auto label = [](const char* family, int joint) {
    return nlohmann::json{{"family", family}, {"joint", joint ? nlohmann::json(joint) : nlohmann::json(nullptr)}};
  };
  EXPECT_EQ(c.at("labels"), (nlohmann::json{label(kKt, 2), label(kKt, 3), label(kStuck, 1), label(kStuck, 2),
                                            label("healthy", 0), label("unknown", 0)}));
  EXPECT_EQ(c.at("counts"), (nlohmann::json{{2, 1, 0, 1, 1, 0},    // kt j2: r1 r2 | r6 on j3 | r3 as stuck | r4 missed
                                            {0, 0, 0, 0, 0, 0},    // nothing injected on kt j3
                                            {0, 0, 1, 0, 0, 1},    // stuck j1: right, unknown
                                            {0, 0, 0, 0, 0, 0},
                                            {0, 1, 0, 0, 3, 0},    // healthy: one alarm named kt j3
                                            {0, 0, 0, 0, 0, 0}}));
  const nlohmann::json& joints = s.at("per_joint");
  ASSERT_EQ(joints.size(), 3u);
  EXPECT_EQ(joints[0].at("joint"), 1);
  ExpectRate(joints[0].at("detection"), 2, 2);
  ExpectRate(joints[0].at("isolation"), 1, 2);
  ExpectRate(joints[0].at("false_alarm"), 0, 4);
  EXPECT_EQ(joints[1].at("joint"), 2);
  EXPECT_EQ(joints[1].at("runs"), 5);
  ExpectRate(joints[1].at("detection"), 4, 5);
  ExpectRate(joints[1].at("isolation"), 2, 4);
  EXPECT_EQ(joints[1].at("latency").at("count"), 4);
  EXPECT_EQ(joints[1].at("latency").at("misses"), 1);
  EXPECT_EQ(joints[2].at("joint"), 3);  // only a false alarm named it
  EXPECT_EQ(joints[2].at("faulty_runs"), 0);
  ExpectRate(joints[2].at("false_alarm"), 1, 4);
  const nlohmann::json& cells = s.at("per_family_joint");
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_EQ(cells[0].at("family"), kKt);
  EXPECT_EQ(cells[0].at("joint"), 2);
  ExpectRate(cells[0].at("detection"), 4, 5);
  EXPECT_EQ(cells[1].at("family"), kStuck);
  ExpectRate(cells[1].at("isolation"), 1, 2);
}

TEST(CampaignSummaryTest, ConfusionOfAnEmptyCampaignStillHasTheFixedLabels) {
  const nlohmann::json s = SummaryBuilder().Build(Floors{}, nullptr, "v");
  EXPECT_EQ(s.at("confusion").at("labels"), (nlohmann::json{"healthy", "unknown"}));
  EXPECT_EQ(s.at("confusion").at("counts"), (nlohmann::json{{0, 0}, {0, 0}}));
  EXPECT_TRUE(s.at("overall").at("latency").at("median_s").is_null());
  EXPECT_EQ(s.at("floors"), nlohmann::json::array());
  EXPECT_EQ(s.at("floors_met"), true);
}

TEST(CampaignSummaryTest, MedianAndNearestRankP95) {
  std::vector<RunRecord> v;
  for (int k = 1; k <= 20; ++k) {
    v.push_back(Detect(Faulty("s/" + std::to_string(k), kStuck, 1, kStuckGroup), kStuck, 1, 0.01 * k));
  }
  std::mt19937 rng(7);
  std::shuffle(v.begin(), v.end(), rng);
  nlohmann::json lat = BuilderOf(v).Build(Floors{}, nullptr, "v").at("overall").at("latency");
  EXPECT_EQ(lat.at("count"), 20);
  EXPECT_EQ(lat.at("median_s").get<double>(), (0.01 * 10 + 0.01 * 11) / 2);
  EXPECT_EQ(lat.at("p95_s").get<double>(), 0.01 * 19);  // index ceil(19) - 1 = 18

  v.push_back(Detect(Faulty("s/21", kStuck, 1, kStuckGroup), kStuck, 1, 0.01 * 21));
  lat = BuilderOf(v).Build(Floors{}, nullptr, "v").at("overall").at("latency");
  EXPECT_EQ(lat.at("median_s").get<double>(), 0.01 * 11);
  EXPECT_EQ(lat.at("p95_s").get<double>(), 0.01 * 20);  // index ceil(19.95) - 1 = 19

  lat = BuilderOf({v[0]}).Build(Floors{}, nullptr, "v").at("overall").at("latency");
  EXPECT_EQ(lat.at("median_s"), lat.at("p95_s"));
}

TEST(CampaignSummaryFloorsTest, MetAndMissedMessages) {
  Floors floors;
  floors.overall.detection_rate = 0.9;
  floors.overall.false_alarm_rate = 0.3;
  floors.overall.isolation_accuracy = 0.6;
  floors.per_family[kKt].false_alarm_rate = 0.2;
  floors.per_family[kKt].detection_rate = 0.75;
  floors.per_family["joint_friction"].detection_rate = 0.5;
  const SummaryBuilder b = BuilderOf(MixedRecords());
  const std::vector<FloorVerdict> v = b.Verdicts(floors);
  ASSERT_EQ(v.size(), 6u);

  EXPECT_EQ(v[0].name, "detection_rate");
  EXPECT_EQ(v[0].kind, "min");
  EXPECT_EQ(v[0].bound, 0.9);
  EXPECT_EQ(*v[0].measured, 5.0 / 6.0);
  EXPECT_FALSE(v[0].met);
  EXPECT_EQ(v[0].message, "detection_rate 0.833 < 0.900 (5 of 6 runs)");

  EXPECT_EQ(v[1].name, "false_alarm_rate");
  EXPECT_EQ(v[1].kind, "max");
  EXPECT_TRUE(v[1].met);
  EXPECT_EQ(v[1].message, "false_alarm_rate 0.250 <= 0.300 (1 of 4 healthy runs)");

  EXPECT_EQ(v[2].name, "isolation_accuracy");
  EXPECT_TRUE(v[2].met);  // 3 / 5 is exactly 0.6
  EXPECT_EQ(v[2].message, "isolation_accuracy 0.600 >= 0.600 (3 of 5 detected runs)");

  // Families in sorted order, metrics in the fixed order within each.
  EXPECT_EQ(v[3].name, "per_family/joint_friction/detection_rate");
  EXPECT_FALSE(v[3].met);
  EXPECT_FALSE(v[3].measured.has_value());
  EXPECT_THAT(v[3].message, HasSubstr("no runs of family joint_friction"));

  EXPECT_EQ(v[4].name, "per_family/kt_degradation/detection_rate");
  EXPECT_TRUE(v[4].met);
  EXPECT_EQ(v[4].message, "per_family/kt_degradation/detection_rate 0.750 >= 0.750 (3 of 4 runs)");

  EXPECT_EQ(v[5].name, "per_family/kt_degradation/false_alarm_rate");
  EXPECT_FALSE(v[5].met);
  EXPECT_EQ(*v[5].measured, 0.25);
  EXPECT_EQ(v[5].message,
            "per_family/kt_degradation/false_alarm_rate 0.250 > 0.200 (1 of 4 runs alarmed before onset)");

  const nlohmann::json s = b.Build(floors, nullptr, "v");
  EXPECT_EQ(s.at("floors_met"), false);
  ASSERT_EQ(s.at("floors").size(), 6u);
  EXPECT_EQ(s.at("floors")[0],
            (nlohmann::json{{"name", "detection_rate"},
                            {"kind", "min"},
                            {"bound", 0.9},
                            {"measured", 5.0 / 6.0},
                            {"met", false},
                            {"message", "detection_rate 0.833 < 0.900 (5 of 6 runs)"}}));
  EXPECT_TRUE(s.at("floors")[3].at("measured").is_null());
}

TEST(CampaignSummaryFloorsTest, AllMetGivesFloorsMet) {
  Floors floors;
  floors.overall.detection_rate = 0.8;
  floors.per_family[kStuck].detection_rate = 1.0;
  const nlohmann::json s = BuilderOf(MixedRecords()).Build(floors, nullptr, "v");
  EXPECT_EQ(s.at("floors_met"), true);
  EXPECT_EQ(s.at("floors").size(), 2u);
}

TEST(CampaignSummaryFloorsTest, FalseAlarmFloorWithoutHealthyRunsIsNotMet) {
  SummaryBuilder b;
  b.Add(Detect(Faulty("s/1", kStuck, 1, kStuckGroup), kStuck, 1, 0.1));
  RunRecord failed_healthy = Healthy("healthy/0", false);
  failed_healthy.ok = false;  // a failed healthy run is no healthy run to measure
  b.Add(failed_healthy);
  Floors floors;
  floors.overall.false_alarm_rate = 0.05;
  const std::vector<FloorVerdict> v = b.Verdicts(floors);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_FALSE(v[0].met);
  EXPECT_FALSE(v[0].measured.has_value());
  EXPECT_THAT(v[0].message, HasSubstr("no healthy runs"));
}

TEST(CampaignSummaryFloorsTest, IsolationFloorWithNothingDetectedIsNotMet) {
  SummaryBuilder b;
  b.Add(Faulty("s/1", kStuck, 1, kStuckGroup));
  Floors floors;
  floors.overall.isolation_accuracy = 0.0;
  const std::vector<FloorVerdict> v = b.Verdicts(floors);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_FALSE(v[0].met);
  EXPECT_THAT(v[0].message, HasSubstr("no detected runs"));
}

TEST(CampaignSummaryJUnitTest, FailureForMissedFloorAndEscaping) {
  FloorVerdict met{"detection_rate", "min", 0.9, 0.95, true, "detection_rate 0.950 >= 0.900 (19 of 20 runs)"};
  FloorVerdict missed{"false_alarm_rate", "max", 0.05, 0.1, false,
                      "false_alarm_rate 0.100 > 0.050 (2 of 20 healthy runs)"};
  const std::string xml = JUnitXml("arm <7> & \"friends\"", {met, missed});
  EXPECT_THAT(xml, HasSubstr("<testsuites tests=\"2\" failures=\"1\">"));
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"armfault floors: arm &lt;7&gt; &amp; &quot;friends&quot;\" "
                             "tests=\"2\" failures=\"1\">"));
  EXPECT_THAT(xml, HasSubstr("<testcase classname=\"floors\" name=\"detection_rate\"/>"));
  EXPECT_THAT(xml, HasSubstr("<testcase classname=\"floors\" name=\"false_alarm_rate\">\n"
                             "      <failure message=\"false_alarm_rate 0.100 &gt; 0.050 (2 of 20 healthy runs)\">"));
  EXPECT_EQ(std::count(xml.begin(), xml.end(), '<') - std::count(xml.begin(), xml.end(), '>'), 0);
  EXPECT_EQ(xml.find("<7>"), std::string::npos);
  EXPECT_EQ(xml.find("<failure"), xml.rfind("<failure"));  // exactly one failure

  FloorVerdict quoted = missed;
  quoted.message = "it's < 1";
  EXPECT_THAT(JUnitXml("c", {quoted}), HasSubstr("message=\"it&apos;s &lt; 1\""));
}

TEST(CampaignSummaryJUnitTest, OneSuitePerFamilyOneCasePerGroupAndTrajectoryWithTheReplayCommand) {
  SummaryBuilder b;
  auto on = [](RunRecord r, const std::string& trajectory, long case_index) {
    r.trajectory = trajectory;
    r.case_index = case_index;
    return r;
  };
  // exp1: 1 of 3 detected (cases 4 and 2 missed: the replay names case 2); p2p: 2 of 2.
  b.Add(on(Detect(Faulty("exp1/kt/a", kKt, 2, kKtGroup), kKt, 2, 0.5), "exp1", 1));
  b.Add(on(Faulty("exp1/kt/b", kKt, 2, kKtGroup), "exp1", 4));
  b.Add(on(Faulty("exp1/kt/c", kKt, 2, kKtGroup), "exp1", 2));
  b.Add(on(Detect(Faulty("p2p/kt/a", kKt, 2, kKtGroup), kKt, 2, 0.5), "p2p", 7));
  b.Add(on(Detect(Faulty("p2p/kt/b", kKt, 2, kKtGroup), kKt, 2, 0.5), "p2p", 8));
  b.Add(on(Healthy("exp1/healthy/0", true), "exp1", 5));
  b.Add(on(Healthy("exp1/healthy/1", false), "exp1", 6));
  Floors floors;
  floors.overall.detection_rate = 0.9;
  floors.overall.false_alarm_rate = 0.1;
  const std::string xml = JUnitXml("c", b, floors, "campaign.json");
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"kt_degradation\" tests=\"2\" failures=\"1\">"));
  EXPECT_THAT(xml, HasSubstr("name=\"exp1: kt_degradation kt_factor=0.9 joint=2\""));
  EXPECT_THAT(xml, HasSubstr("<failure message=\"detection_rate 0.333 &lt; 0.900 (1 of 3 runs)\">"));
  EXPECT_THAT(xml, HasSubstr("armfault trace campaign.json --run &apos;exp1/kt/c&apos;"));
  EXPECT_THAT(xml, HasSubstr("name=\"p2p: kt_degradation kt_factor=0.9 joint=2\">\n      <system-out>2 runs, 2 detected"));
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"healthy\" tests=\"1\" failures=\"1\">"));
  EXPECT_THAT(xml, HasSubstr("false_alarm_rate 0.500 &gt; 0.100 (1 of 2 healthy runs)"));
  EXPECT_THAT(xml, HasSubstr("--run &apos;exp1/healthy/0&apos;"));
  // Per joint: counts only, and the false alarm on the joint it named (Healthy names joint 3).
  EXPECT_THAT(xml, HasSubstr("<testsuite name=\"per joint\" tests=\"3\" failures=\"0\">"));
  EXPECT_THAT(xml, HasSubstr("name=\"joint 2\">\n      <system-out>5 runs, 3 detected, 3 isolated (family and joint), "
                             "latency median 0.500 s; false alarms naming joint 2: 0 of 2 healthy runs</system-out>"));
  EXPECT_THAT(xml, HasSubstr("name=\"joint 3\">\n      <system-out>no faulty runs; false alarms naming joint 3: 1 of 2"));
  EXPECT_THAT(xml, HasSubstr("name=\"kt_degradation: joint 2\">\n      <system-out>5 runs, 3 detected"));
  // The floors suite comes first, and the totals count every case: 2 floors + 3 group cases
  // + 3 per-joint cases.
  EXPECT_THAT(xml, HasSubstr("<testsuites name=\"armfault: c\" tests=\"8\" failures=\"4\">"));
}

// Failed runs are a failing JUnit case naming the first failure (lowest case number, whatever
// the order of the records) with its reason and the command that replays it.
TEST(CampaignSummaryJUnitTest, FailedRunsNameTheFirstFailureAndItsReason) {
  auto failed = [](const std::string& id, long case_index, const std::string& why) {
    RunRecord r = Healthy(id, false);
    r.case_index = case_index;
    r.ok = false;
    r.failure_reason = why;
    return r;
  };
  std::vector<RunRecord> v = {failed("b/late", 7, "timeout"), Healthy("ok/0", false),
                              failed("z/first", 2, "simulation diverged at t=0.5 s"), failed("a/mid", 5, "other")};
  for (int pass = 0; pass < 2; ++pass) {
    const SummaryBuilder b = BuilderOf(v);
    EXPECT_EQ(b.first_failure().run_id, "z/first");
    EXPECT_EQ(b.FirstFailureText(), "run z/first: simulation diverged at t=0.5 s");
    const std::string xml = JUnitXml("c", b, Floors{}, "campaign.json");
    EXPECT_THAT(xml, HasSubstr("<testsuite name=\"failed runs\" tests=\"1\" failures=\"1\">"));
    EXPECT_THAT(xml, HasSubstr("<testcase classname=\"failed runs\" name=\"every run completes\">"));
    EXPECT_THAT(xml, HasSubstr("<failure message=\"3 of 4 runs failed; first failed run z/first: simulation "
                               "diverged at t=0.5 s\">"));
    EXPECT_THAT(xml, HasSubstr("armfault trace campaign.json --run &apos;z/first&apos;"));
    // "no floors" and the failed runs, one failure.
    EXPECT_THAT(xml, HasSubstr("<testsuites name=\"armfault: c\" tests=\"3\" failures=\"1\">"));
    std::reverse(v.begin(), v.end());
  }
  // No failed run: no such suite (the junit.xml of a campaign without failures is unchanged).
  EXPECT_EQ(JUnitXml("c", BuilderOf({Healthy("ok/0", false)}), Floors{}, "campaign.json").find("failed runs"),
            std::string::npos);
  EXPECT_EQ(BuilderOf({Healthy("ok/0", false)}).FirstFailureText(), "");
}

// Every run failed: each floor says so (not "no faulty runs"), names the first failure, and is
// not met; a campaign with some runs left keeps the usual message.
TEST(CampaignSummaryTest, FloorsOfACampaignWhoseEveryRunFailedSaySo) {
  SummaryBuilder b;
  for (int k = 0; k < 4; ++k) {
    RunRecord r = k < 2 ? Faulty("kt/" + std::to_string(k), kKt, 2, kKtGroup) : Healthy("h/" + std::to_string(k), false);
    r.case_index = k;
    r.ok = false;
    r.failure_reason = "monitor plugin failed: lib.so: step returned error: boom";
    b.Add(r);
  }
  Floors floors;
  floors.overall.detection_rate = 0.9;
  floors.overall.false_alarm_rate = 0.1;
  floors.per_family[kKt].isolation_accuracy = 0.5;
  const std::vector<FloorVerdict> verdicts = b.Verdicts(floors);
  ASSERT_EQ(verdicts.size(), 3u);
  for (const FloorVerdict& v : verdicts) {
    EXPECT_FALSE(v.met) << v.name;
    EXPECT_FALSE(v.measured) << v.name;
    EXPECT_THAT(v.message, HasSubstr(v.name + ": all 4 runs failed, nothing to measure (floor "));
    EXPECT_THAT(v.message, HasSubstr("; first failed run kt/0: monitor plugin failed: lib.so: step returned error: boom"));
    EXPECT_THAT(v.message, Not(HasSubstr("no faulty runs")));
  }
  EXPECT_THAT(verdicts[1].message, HasSubstr("(floor <= 0.100)"));
  EXPECT_THAT(JUnitXml("c", b, floors, "campaign.json"), HasSubstr("detection_rate: all 4 runs failed"));

  SummaryBuilder some;
  RunRecord f = Faulty("kt/0", kKt, 2, kKtGroup);
  f.ok = false;
  some.Add(f);
  some.Add(Healthy("h/1", false));
  EXPECT_THAT(some.Verdicts(floors)[0].message, HasSubstr("detection_rate: no faulty runs, nothing to measure"));
}

TEST(CampaignSummaryJUnitTest, NoFloorsIsOnePassingCase) {
  const std::string xml = JUnitXml("c", {});
  EXPECT_THAT(xml, HasSubstr("tests=\"1\" failures=\"0\""));
  EXPECT_THAT(xml, HasSubstr("<testcase classname=\"floors\" name=\"no floors\"/>"));
  EXPECT_EQ(xml.find("<failure"), std::string::npos);
}

TEST(CampaignSummaryTest, BuildDoesNotDependOnTheOrderOfRecords) {
  std::vector<RunRecord> v = MixedRecords();
  // Enough failed runs to truncate the listing, and latencies whose sum depends on order.
  for (int k = 0; k < 130; ++k) {
    RunRecord f = Healthy("healthy/f" + std::to_string(1000 + k), false);
    f.ok = false;
    f.failure_reason = "timeout " + std::to_string(k);
    v.push_back(f);
  }
  for (int k = 0; k < 40; ++k) {
    RunRecord r = Detect(Faulty("kt/x" + std::to_string(k), kKt, 2, kKtGroup), kKt, 2, 0.1 / (k + 1));
    r.magnitude_name = "kt_factor";
    r.magnitude_estimate = 0.9 + 1e-3 * std::sin(k);
    v.push_back(r);
  }
  Floors floors;
  floors.overall.detection_rate = 0.5;
  floors.per_family[kKt].isolation_accuracy = 0.9;
  const std::string forward = BuilderOf(v).Build(floors, nullptr, "v").dump();
  std::reverse(v.begin(), v.end());
  EXPECT_EQ(BuilderOf(v).Build(floors, nullptr, "v").dump(), forward);
  std::mt19937 rng(42);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(v.begin(), v.end(), rng);
    EXPECT_EQ(BuilderOf(v).Build(floors, nullptr, "v").dump(), forward);
  }

  const nlohmann::json failed = nlohmann::json::parse(forward).at("failed_runs");
  EXPECT_EQ(failed.at("count"), 131);
  EXPECT_EQ(failed.at("truncated"), true);
  ASSERT_EQ(failed.at("runs").size(), 100u);
  EXPECT_EQ(failed.at("runs")[0].at("run_id"), "healthy/f1000");
  EXPECT_EQ(failed.at("runs")[99].at("run_id"), "healthy/f1099");
}

}  // namespace
}  // namespace armfault
