// Conditional onsets in campaigns: parse errors at the condition's own pointer, the run_id of
// swept conditions, records that hold the fire time and score from fire time + delay exactly
// as an ordinary onset_s there, runs whose condition never fired listed apart, the same bytes
// for any thread count, and ordinary campaigns unchanged (a golden written before the feature).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/running/runner.h"
#include "faults/onset_condition.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;
using testing_support::ScratchDir;

json Conditional() {
  return json::parse(R"({
    "name": "conditional", "seed": 5, "duration_s": 5,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [
      {"family": "kt_degradation", "joint": 3, "kt_factor": 0.5,
       "onset": [{"when": "joint_velocity_above", "joint": 3, "rad_s": 0.3, "delay_s": 0.2},
                 {"when": "after_reversals", "joint": 3, "count": 1},
                 {"when": "joint_velocity_above", "joint": 1, "rad_s": 0.3}]},
      {"family": "friction_increase", "joint": 3, "friction_factor": 3,
       "onset": {"when": "joint_position_crosses", "joint": 3, "deg": 10, "direction": "falling"}}
    ],
    "healthy": 1
  })");
}

Campaign Parse(const json& j) { return CampaignFromJson(j, "c.json", "."); }

TEST(ConditionalOnsetCampaign, ErrorsPointIntoTheCondition) {
  struct Case {
    std::string patch, pointer, message;
  };
  const std::vector<Case> cases = {
      {R"([{"op": "replace", "path": "/faults/1/onset/joint", "value": 4}])", "/faults/1/onset/joint",
       "friction_increase: joint 4 does not exist: robot mrr-config1 has joints 1..3"},
      {R"([{"op": "replace", "path": "/faults/0/onset/2/joint", "value": 9}])", "/faults/0/onset/2/joint",
       "kt_degradation: joint 9 does not exist: robot mrr-config1 has joints 1..3"},
      {R"([{"op": "replace", "path": "/faults/1/onset/when", "value": "joint_jerk_above"}])", "/faults/1/onset/when",
       "unknown condition \"joint_jerk_above\""},
      {R"([{"op": "add", "path": "/faults/1/onset/rad_s", "value": 1}])", "/faults/1/onset/rad_s",
       "friction_increase: joint_position_crosses: unknown key \"rad_s\""},
      {R"([{"op": "remove", "path": "/faults/0/onset/1/count"}])", "/faults/0/onset/1/count", "missing"},
      {R"([{"op": "add", "path": "/faults/0/onset/0/delay_s", "value": -0.5}])", "/faults/0/onset/0/delay_s", "-0.5"},
      {R"([{"op": "add", "path": "/faults/1/onset_s", "value": 2}])", "/faults/1/onset",
       "friction_increase: give either onset_s (a time) or onset (a condition), not both (/faults/1/onset_s is given too)"},
      {R"([{"op": "replace", "path": "/faults/0/onset", "value": []}])", "/faults/0/onset", "non-empty list"},
      {R"([{"op": "replace", "path": "/faults/0/onset/1", "value": 3}])", "/faults/0/onset/1", "expected a condition"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.patch);
    const json bad = Conditional().patch(json::parse(c.patch));
    const InputError e = ErrorOf([&] { Parse(bad); });
    EXPECT_EQ(e.count(), 1u);
    EXPECT_EQ(e.source(), "c.json");
    EXPECT_EQ(e.pointer(), c.pointer);
    EXPECT_THAT(e.message(), HasSubstr(c.message));
  }
}

TEST(ConditionalOnsetCampaign, SweptConditionsArePartOfTheRunIdNotTheGroup) {
  const std::vector<CaseSpec> cases = ExpandCases(Parse(Conditional()));
  ASSERT_EQ(cases.size(), 5u);
  EXPECT_EQ(cases[0].run_id, "exp1/kt_degradation#0/onset=joint_velocity_above:delay_s=0.2:joint=3:rad_s=0.3/j3/r0");
  EXPECT_EQ(cases[1].run_id, "exp1/kt_degradation#0/onset=after_reversals:count=1:joint=3/j3/r0");
  EXPECT_EQ(cases[3].run_id, "exp1/friction_increase#1/-/j3/r0");  // one condition: not in the run_id
  EXPECT_EQ(cases[0].group, "kt_degradation kt_factor=0.5 joint=3");
  EXPECT_EQ(cases[1].group, cases[0].group);
  EXPECT_EQ(cases[0].fault["onset"], Conditional()["faults"][0]["onset"][0]);
}

TEST(ConditionalOnsetCampaign, TheRecordHoldsTheFireTimeAndScoresFromFireTimePlusDelay) {
  const Campaign c = Parse(Conditional());
  const CaseSpec cs = CaseAt(c, 0);  // |velocity| of joint 3 above 0.3 rad/s, + 0.2 s
  const RunRecord r = RunCase(c, cs);
  ASSERT_TRUE(r.ok) << r.failure_reason;
  ASSERT_TRUE(r.onset_fired_s.has_value());
  EXPECT_TRUE(r.injected());
  EXPECT_NEAR(r.onset_s, *r.onset_fired_s + 0.2, 1e-12);
  const json j = ToJson(r);
  EXPECT_EQ(j["onset_fired_s"], RoundToMicroseconds(*r.onset_fired_s));
  EXPECT_TRUE(j["not_injected_reason"].is_null());
  EXPECT_EQ(j["fault"]["onset"]["when"], "joint_velocity_above");
  ASSERT_TRUE(r.detected);
  EXPECT_DOUBLE_EQ(*r.latency_s, *r.detection_time_s - r.onset_s);

  // The very run with onset_s = fire time + delay instead: everything scored the same.
  CaseSpec plain = cs;
  plain.fault.erase("onset");
  plain.fault["onset_s"] = r.onset_s;
  const RunRecord p = RunCase(c, plain);
  EXPECT_EQ(p.onset_s, r.onset_s);
  EXPECT_EQ(p.detected, r.detected);
  EXPECT_EQ(p.detection_time_s, r.detection_time_s);
  EXPECT_EQ(p.latency_s, r.latency_s);
  EXPECT_EQ(p.alarm_before_onset, r.alarm_before_onset);
  EXPECT_EQ(p.isolated_family, r.isolated_family);
  EXPECT_EQ(p.effect, r.effect);
  EXPECT_EQ(p.decision, r.decision);  // the decision statistics split at the same onset
  EXPECT_FALSE(ToJson(p).contains("onset_fired_s"));

  // The real run meets the condition at the very tick the probe found.
  double seen = -1;
  const OnsetCondition condition = ReadOnsetCondition(cs.fault["onset"], "", c.robot);
  OnsetWatcher w(condition);
  RunCase(c, cs, [&](const Tick& tick) {
    if (w.Observe(tick.t_s, (*tick.joints)[2])) seen = tick.t_s;
  });
  EXPECT_EQ(seen, *r.onset_fired_s);
}

TEST(ConditionalOnsetCampaign, AConditionThatNeverFiresIsNotInjectedAndListedApart) {
  const Campaign c = Parse(Conditional());
  const RunRecord r = RunCase(c, CaseAt(c, 2));  // joint 1 never moves
  ASSERT_TRUE(r.ok) << r.failure_reason;
  EXPECT_FALSE(r.injected());
  EXPECT_EQ(r.not_injected_reason, "the onset condition never fired: joint 1's |velocity| above 0.3 rad/s");
  EXPECT_FALSE(r.onset_fired_s.has_value());
  EXPECT_FALSE(r.detected);
  EXPECT_EQ(r.miss_reason, "");
  EXPECT_EQ(r.not_excited_reason, "");
  const json j = ToJson(r);
  EXPECT_TRUE(j["onset_s"].is_null());
  EXPECT_TRUE(j["onset_fired_s"].is_null());
  EXPECT_EQ(j["not_injected_reason"], r.not_injected_reason);
  // Read back as written.
  const RunRecord back = RunRecordFromJson(j);
  EXPECT_TRUE(back.conditional_onset);
  EXPECT_EQ(back.not_injected_reason, r.not_injected_reason);
  EXPECT_EQ(ToJson(back), j);

  SummaryBuilder builder;
  RunRecord healthy = RunCase(c, CaseAt(c, 4));
  builder.Add(r);
  builder.Add(healthy);
  EXPECT_EQ(builder.not_injected_runs(), 1);
  const json s = builder.Build(Floors{}, json::object(), "test");
  EXPECT_EQ(s["runs"]["not_injected"], 1);
  EXPECT_EQ(s["runs"]["faulty"], 0);  // neither a detection nor a miss
  EXPECT_EQ(s["overall"]["latency"]["misses"], 0);
  EXPECT_EQ(s["not_injected_runs"]["count"], 1);
  EXPECT_EQ(s["not_injected_runs"]["runs"][0]["run_id"], r.run_id);
  EXPECT_EQ(s["not_injected_runs"]["runs"][0]["reason"], r.not_injected_reason);
}

TEST(ConditionalOnsetCampaign, ResultsAreIdenticalForAnyThreadCount) {
  ScratchDir dir("conditional");
  const Campaign c = Parse(Conditional());
  RunnerOptions one;
  one.output_dir = (dir.path() / "j1").string();
  one.threads = 1;
  RunnerOptions two = one;
  two.output_dir = (dir.path() / "j2").string();
  two.threads = 2;
  RunCampaign(c, one);
  RunCampaign(c, two);
  for (const char* file : {"results.jsonl", "decisions.jsonl"}) {
    SCOPED_TRACE(file);
    const std::string a = ReadAll(dir.path() / "j1" / file);
    EXPECT_EQ(a, ReadAll(dir.path() / "j2" / file));
    EXPECT_EQ(Lines(a).size(), 5u);
  }
}

// A campaign of ordinary onsets (fixed, uniform, an incipient ramp) gives the records the
// a campaign without conditional onsets scores (tests/campaigns/spec/golden/; its friction run's
// detection and magnitude follow the monitor as it is, rewritten when the monitor moves them):
// every key of the golden line with the same value, and no conditional key.
TEST(ConditionalOnsetCampaign, OrdinaryOnsetsScoreExactlyAsBefore) {
  const std::string golden_dir = std::string(ARMFAULT_SOURCE_DIR) + "/tests/campaigns/spec/golden/";
  const Campaign c = ReadCampaignFile(golden_dir + "ordinary_onsets.json");
  const std::vector<std::string> golden = Lines(ReadAll(golden_dir + "ordinary_onsets_results.jsonl"));
  ASSERT_EQ(static_cast<long>(golden.size()), CaseCount(c));
  for (size_t k = 0; k < golden.size(); ++k) {
    const json want = json::parse(golden[k]);
    const json got = ToJson(RunCase(c, CaseAt(c, static_cast<long>(k))));
    SCOPED_TRACE(want["run_id"].dump());
    for (auto it = want.begin(); it != want.end(); ++it) EXPECT_EQ(got[it.key()].dump(), it.value().dump()) << it.key();
    EXPECT_FALSE(got.contains("onset_fired_s"));
    EXPECT_FALSE(got.contains("not_injected_reason"));
  }
}

}  // namespace
}  // namespace armfault
