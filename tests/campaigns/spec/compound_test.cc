// Compound faults (issue #16 item 3, docs/campaign-format.md "Compound faults"): parse errors
// at the element's own pointer, one case per trajectory x repetition in the usual order, the
// elements acting together on the plant, scoring from the earliest onset with per-element
// isolation, the summary's "compound" section, the same bytes for any thread count.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/running/runner.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;
using testing_support::ScratchDir;

json WithCompound() {
  return json::parse(R"({
    "name": "compound", "seed": 9, "duration_s": 4,
    "trajectories": [{"name": "exp1", "joints": {
       "2": {"type": "sine_pair", "amplitude_deg": 20, "omega_rad_s": 1.5},
       "3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [
      {"family": "kt_degradation", "joint": [2, 3], "kt_factor": [0.9, 0.6], "onset_s": 0.5},
      {"compound": [{"family": "friction_increase", "joint": 2, "friction_factor": 4, "onset_s": 1.5},
                    {"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 2, "onset_s": 0.8}],
       "name": "friction_j2+drift_j3"},
      {"compound": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.5, "onset_s": 1},
                    {"family": "winding_resistance", "joint": 2, "resistance_factor": 2}]}
    ],
    "healthy": 1, "repetitions": 2
  })");
}

Campaign Parse(const json& j) { return CampaignFromJson(j, "c.json", "."); }

TEST(CompoundCampaign, ErrorsPointIntoTheElement) {
  struct Case {
    std::string patch, pointer, message;
  };
  const std::vector<Case> cases = {
      {R"([{"op": "replace", "path": "/faults/1/compound/1/joint", "value": 7}])", "/faults/1/compound/1/joint",
       "joint 7 does not exist"},
      {R"([{"op": "replace", "path": "/faults/1/compound/1/joint", "value": [2, 3]}])", "/faults/1/compound/1/joint",
       "compound elements take single values"},
      {R"([{"op": "replace", "path": "/faults/1/compound/0/friction_factor", "value": {"uniform": [2, 3]}}])",
       "/faults/1/compound/0/friction_factor", "compound elements take single values"},
      {R"([{"op": "replace", "path": "/faults/1/compound/0/family", "value": "rust"}])", "/faults/1/compound/0/family",
       "rust"},
      {R"([{"op": "add", "path": "/faults/1/compound/0/lead", "value": 1}])", "/faults/1/compound/0/lead",
       "unknown key \"lead\""},
      {R"([{"op": "add", "path": "/faults/1/joint", "value": 2}])", "/faults/1/joint", "joint"},
      {R"([{"op": "remove", "path": "/faults/1/compound/1"}])", "/faults/1/compound", "at least 2"},
      {R"([{"op": "replace", "path": "/faults/1/name", "value": "a/b"}])", "/faults/1/name", "without '/'"},
      {R"([{"op": "replace", "path": "/faults/1/compound/1/onset_s", "value": -1}])", "/faults/1/compound/1/onset_s",
       "-1"},
      {R"([{"op": "replace", "path": "/faults/1/compound/0", "value": 3}])", "/faults/1/compound/0",
       "expected a fault object"},
      {R"([{"op": "add", "path": "/faults/1/compound/0/onset", "value": [{"when": "after_reversals", "joint": 3, "count": 1}]}])",
       "/faults/1/compound/0/onset", "compound elements take single values"},
      {R"([{"op": "add", "path": "/faults/2/compound/1/onset", "value": {"when": "after_reversals", "joint": 5, "count": 1}}])",
       "/faults/2/compound/1/onset/joint", "joint 5 does not exist"},
      {R"([{"op": "add", "path": "/search", "value": {}}])", "/search/faults/1", "compound"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.patch);
    const json bad = WithCompound().patch(json::parse(c.patch));
    const InputError e = ErrorOf([&] { Parse(bad); });
    ASSERT_GE(e.count(), 1u);
    EXPECT_EQ(e.source(), "c.json");
    bool found = false;
    for (const InputError& one : e.errors()) {
      if (c.pointer.rfind("/search", 0) == 0 ? one.pointer() == "/faults/1" && one.message().find("compound") != std::string::npos
                                             : one.pointer() == c.pointer && one.message().find(c.message) != std::string::npos) {
        found = true;
      }
    }
    EXPECT_TRUE(found) << e.what();
  }
}

TEST(CompoundCampaign, OneCasePerTrajectoryAndRepetitionInCaseOrder) {
  const Campaign c = Parse(WithCompound());
  ASSERT_EQ(c.faults.size(), 3u);
  EXPECT_TRUE(c.faults[1].compound);
  EXPECT_EQ(c.faults[2].name, "kt_degradation_j3+winding_resistance_j2");  // the default name
  // 2 x 2 x 2 ordinary, 2 + 2 compound, 1 healthy.
  EXPECT_EQ(CaseCount(c), 13);
  const std::vector<CaseSpec> cases = ExpandCases(c);
  ASSERT_EQ(cases.size(), 13u);
  EXPECT_EQ(cases[7].run_id, "exp1/kt_degradation#0/kt_factor=0.6/j3/r1");
  EXPECT_EQ(cases[8].run_id, "exp1/compound#1/friction_j2+drift_j3/r0");
  EXPECT_EQ(cases[9].run_id, "exp1/compound#1/friction_j2+drift_j3/r1");
  EXPECT_EQ(cases[10].run_id, "exp1/compound#2/kt_degradation_j3+winding_resistance_j2/r0");
  EXPECT_EQ(cases[12].run_id, "exp1/healthy/0");
  EXPECT_EQ(cases[8].group, "compound:friction_j2+drift_j3");
  EXPECT_EQ(cases[9].repetition, 1);
  EXPECT_EQ(cases[8].fault["family"], "compound");
  EXPECT_EQ(cases[8].fault["compound"], WithCompound()["faults"][1]["compound"]);
  EXPECT_NE(cases[8].seed, cases[9].seed);
  // The ordinary entry before it and the healthy run keep the run_ids and seeds they have
  // without the compound entries.
  json plain = WithCompound();
  plain["faults"].erase(1);
  plain["faults"].erase(1);
  const std::vector<CaseSpec> before = ExpandCases(Parse(plain));
  ASSERT_EQ(before.size(), 9u);
  for (size_t k = 0; k < 8; ++k) {
    EXPECT_EQ(cases[k].run_id, before[k].run_id);
    EXPECT_EQ(cases[k].seed, before[k].seed);
  }
  EXPECT_EQ(cases[12].seed, before[8].seed);
}

TEST(CompoundCampaign, TheElementsActTogetherAndTheOnsetIsTheEarliest) {
  const Campaign c = Parse(WithCompound());
  const RunRecord r = RunCase(c, CaseAt(c, 8));
  ASSERT_TRUE(r.ok) << r.failure_reason;
  EXPECT_EQ(r.family, "compound");
  EXPECT_EQ(r.joint, 0);
  EXPECT_DOUBLE_EQ(r.onset_s, 0.8);  // the drift's, before the friction's 1.5 s
  ASSERT_TRUE(r.is_compound());
  ASSERT_EQ(r.compound.size(), 2u);
  EXPECT_EQ(r.compound[0]["family"], "friction_increase");
  EXPECT_EQ(r.compound[0]["joint"], 2);
  EXPECT_EQ(r.compound[0]["onset_s"], 1.5);
  EXPECT_EQ(r.compound[0]["magnitude_key"], "friction_factor");
  EXPECT_EQ(r.compound[0]["magnitude"], 4);
  EXPECT_EQ(r.compound[1]["family"], "torque_sensor_drift");
  EXPECT_EQ(r.compound[1]["joint"], 3);
  EXPECT_EQ(r.compound[1]["onset_s"], 0.8);
  // Both took effect in the same run.
  EXPECT_TRUE(r.compound[0]["effect"]["took_effect"].get<bool>()) << r.compound[0]["effect"].dump();
  EXPECT_TRUE(r.compound[1]["effect"]["took_effect"].get<bool>()) << r.compound[1]["effect"].dump();
  EXPECT_TRUE(r.excited());
  const json j = ToJson(r);
  EXPECT_EQ(j["family"], "compound");
  EXPECT_TRUE(j["joint"].is_null());
  EXPECT_EQ(j["onset_s"], 0.8);
  EXPECT_EQ(j["compound"], r.compound);
  // A record reads back with its elements.
  EXPECT_EQ(RunRecordFromJson(j).compound, r.compound);
  if (r.detected) {
    EXPECT_DOUBLE_EQ(*r.latency_s, *r.detection_time_s - 0.8);
  }
}

// The test plugin in mode "alarm" names friction_increase on joint 3 at the first tick at or
// after 1 s: a verdict stream known in advance.
json WithPlugin() {
  json j = json::parse(R"({
    "name": "compound-plugin", "seed": 2, "duration_s": 3,
    "trajectories": [{"name": "exp1", "joints": {
       "2": {"type": "sine_pair", "amplitude_deg": 20, "omega_rad_s": 1.5},
       "3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [
      {"compound": [{"family": "friction_increase", "joint": 3, "friction_factor": 2, "onset_s": 0.6},
                    {"family": "torque_sensor_drift", "joint": 2, "drift_Nm_per_s": 1, "onset_s": 0.3}],
       "name": "named"},
      {"compound": [{"family": "friction_increase", "joint": 2, "friction_factor": 2, "onset_s": 0.5},
                    {"family": "kt_degradation", "joint": 3, "kt_factor": 0.6, "onset_s": 0.4}],
       "name": "other"},
      {"compound": [{"family": "friction_increase", "joint": 3, "friction_factor": 2, "onset_s": 2},
                    {"family": "kt_degradation", "joint": 2, "kt_factor": 0.6, "onset_s": 2.5}],
       "name": "late"}
    ],
    "healthy": 1
  })");
  j["monitor"] = {{"type", "plugin"}, {"library", ARMFAULT_TEST_PLUGIN}, {"settings", {{"mode", "alarm"}}}};
  return j;
}

TEST(CompoundCampaign, DetectionFromTheEarliestOnsetAndIsolationPerElement) {
  const Campaign c = Parse(WithPlugin());
  const RunRecord named = RunCase(c, CaseAt(c, 0));
  ASSERT_TRUE(named.ok) << named.failure_reason;
  ASSERT_TRUE(named.detected);
  EXPECT_GE(*named.detection_time_s, 1.0);
  EXPECT_LT(*named.detection_time_s, 1.1);
  EXPECT_DOUBLE_EQ(*named.latency_s, *named.detection_time_s - 0.3);
  EXPECT_EQ(named.isolated_family, "friction_increase");
  EXPECT_EQ(named.isolated_joint, 3);
  EXPECT_TRUE(IsolatedRight(named));
  EXPECT_TRUE(named.compound[0]["isolated"].get<bool>());
  EXPECT_EQ(named.compound[0]["detection_time_s"], RoundToMicroseconds(*named.detection_time_s));
  EXPECT_FALSE(named.compound[1]["isolated"].get<bool>());
  EXPECT_TRUE(named.compound[1]["detection_time_s"].is_null());
  EXPECT_TRUE(named.miss_reason.empty()) << named.miss_reason;

  const RunRecord other = RunCase(c, CaseAt(c, 1));  // the alarm names neither element
  ASSERT_TRUE(other.detected);
  EXPECT_FALSE(IsolatedRight(other));
  EXPECT_FALSE(other.compound[0]["isolated"].get<bool>());
  EXPECT_FALSE(other.compound[1]["isolated"].get<bool>());
  EXPECT_FALSE(other.miss_reason.empty());

  const RunRecord late = RunCase(c, CaseAt(c, 2));  // the alarm comes before either onset
  EXPECT_TRUE(late.alarm_before_onset);
  EXPECT_DOUBLE_EQ(late.onset_s, 2.0);
  EXPECT_FALSE(late.compound[0]["isolated"].get<bool>());

  SummaryBuilder b;
  for (const RunRecord& r : {named, other, late, RunCase(c, CaseAt(c, 3))}) b.Add(r);
  const json s = b.Build(Floors(), nullptr, "test");
  EXPECT_EQ(s["overall"]["faulty_runs"], 3);
  const long detected = 2 + (late.detected ? 1 : 0);  // an alarm standing at the onset detects
  const long named_first = 1 + (IsolatedRight(late) ? 1 : 0);
  EXPECT_EQ(s["overall"]["detection"]["successes"], detected);
  EXPECT_EQ(s["overall"]["isolation"]["successes"], named_first);
  EXPECT_EQ(s["overall"]["alarm_before_onset_rate"]["successes"], 1);
  EXPECT_FALSE(s["per_family"].contains("compound"));
  EXPECT_FALSE(s["per_family"].contains("friction_increase"));
  ASSERT_TRUE(s.contains("compound"));
  const json& cs = s["compound"];
  EXPECT_EQ(cs["runs"], 3);
  EXPECT_EQ(cs["detection"]["successes"], detected);
  EXPECT_EQ(cs["detection"]["trials"], 3);
  EXPECT_EQ(cs["detection"]["rate"], Wilson(detected, 3).rate);
  EXPECT_EQ(cs["detection"]["low"], Wilson(detected, 3).low);
  EXPECT_EQ(cs["detection"]["high"], Wilson(detected, 3).high);
  EXPECT_EQ(cs["first_alarm_named_a_fault"]["successes"], named_first);
  EXPECT_EQ(cs["first_alarm_named_a_fault"]["trials"], detected);
  // (position, family): 0 friction_increase in all three, isolated in "named" only.
  ASSERT_EQ(cs["elements"].size(), 3u);
  EXPECT_EQ(cs["elements"][0]["position"], 0);
  EXPECT_EQ(cs["elements"][0]["family"], "friction_increase");
  EXPECT_EQ(cs["elements"][0]["isolated"]["successes"], 1);
  EXPECT_EQ(cs["elements"][0]["isolated"]["trials"], 3);
  EXPECT_EQ(cs["elements"][1]["family"], "kt_degradation");
  EXPECT_EQ(cs["elements"][1]["isolated"]["trials"], 2);
  EXPECT_EQ(cs["elements"][2]["family"], "torque_sensor_drift");
  ASSERT_EQ(cs["per_name"].size(), 3u);
  EXPECT_EQ(cs["per_name"]["named"]["runs"], 1);
  EXPECT_EQ(cs["per_name"]["named"]["first_alarm_named_a_fault"]["successes"], 1);
  EXPECT_EQ(cs["per_name"]["other"]["first_alarm_named_a_fault"]["successes"], 0);
  // Groups: one row per compound name.
  bool group = false;
  for (const json& g : s["groups"]) group |= g["group"] == "compound:named" && g["family"] == "compound";
  EXPECT_TRUE(group);
  // A summary without compound runs has no section.
  SummaryBuilder plain;
  const RunRecord healthy = RunCase(c, CaseAt(c, 3));
  plain.Add(healthy);
  EXPECT_FALSE(plain.Build(Floors(), nullptr, "test").contains("compound"));
}

TEST(CompoundCampaign, ResultsAreIdenticalForAnyThreadCount) {
  ScratchDir dir("compound");
  json j = WithCompound();
  j["duration_s"] = 2.5;
  j["repetitions"] = 1;
  const Campaign c = Parse(j);
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
  }
  EXPECT_EQ(Lines(ReadAll(dir.path() / "j1" / "results.jsonl")).size(), 7u);
  SummaryBuilder b1, b2;
  for (const std::string& line : Lines(ReadAll(dir.path() / "j1" / "results.jsonl"))) b1.Add(RunRecordFromJson(json::parse(line)));
  for (const std::string& line : Lines(ReadAll(dir.path() / "j2" / "results.jsonl"))) b2.Add(RunRecordFromJson(json::parse(line)));
  const json summary = b1.Build(c.floors, c.resolved, "test");
  EXPECT_EQ(summary.dump(), b2.Build(c.floors, c.resolved, "test").dump());
  EXPECT_TRUE(summary.contains("compound"));
  EXPECT_FALSE(summary["per_family"].contains("compound"));
}

}  // namespace
}  // namespace armfault

namespace armfault {
namespace {

// --early-stop: a compound case is a faulty case for the overall floors, in no family's scope.
TEST(CompoundCampaign, EarlyStopScopesCountCompoundCasesAsFaulty) {
  nlohmann::json overall = WithCompound();
  overall["floors"] = {{"detection_rate", 0.5}};
  const Campaign c = Parse(overall);
  EXPECT_TRUE(EarlyStop(c, EarlyStopOptions()).Needed("compound"));
  nlohmann::json family = WithCompound();
  family["floors"] = nlohmann::json::parse(R"({"per_family": {"kt_degradation": {"detection_rate": 0.5}}})");
  const Campaign f = Parse(family);
  const EarlyStop per_family(f, EarlyStopOptions());
  EXPECT_FALSE(per_family.Needed("compound"));
  EXPECT_TRUE(per_family.Needed("kt_degradation"));
}

}  // namespace
}  // namespace armfault

namespace armfault {
namespace {

// An element may have a conditional onset: it acts from its fire time + delay; the run is not
// injected only when no element acted.
TEST(CompoundCampaign, ConditionalOnsetsPerElement) {
  nlohmann::json j = WithCompound();
  j["faults"] = nlohmann::json::parse(R"([
    {"compound": [{"family": "friction_increase", "joint": 2, "friction_factor": 4, "onset_s": 2.5},
                  {"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 2,
                   "onset": {"when": "joint_velocity_above", "joint": 3, "rad_s": 0.3, "delay_s": 0.2}}], "name": "fires"},
    {"compound": [{"family": "friction_increase", "joint": 2, "friction_factor": 4, "onset_s": 1},
                  {"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 2,
                   "onset": {"when": "joint_velocity_above", "joint": 1, "rad_s": 0.3}}], "name": "one_never"},
    {"compound": [{"family": "friction_increase", "joint": 2, "friction_factor": 4,
                   "onset": {"when": "joint_velocity_above", "joint": 1, "rad_s": 0.3}},
                  {"family": "torque_sensor_drift", "joint": 3, "drift_Nm_per_s": 2,
                   "onset": {"when": "joint_velocity_above", "joint": 1, "rad_s": 0.3}}], "name": "none"}
  ])");
  j["repetitions"] = 1;
  const Campaign c = Parse(j);
  const RunRecord fires = RunCase(c, CaseAt(c, 0));
  ASSERT_TRUE(fires.ok) << fires.failure_reason;
  EXPECT_TRUE(fires.injected());
  EXPECT_TRUE(fires.conditional_onset);
  ASSERT_TRUE(fires.compound[1]["onset_fired_s"].is_number());
  const double onset = fires.compound[1]["onset_s"].get<double>();
  EXPECT_NEAR(onset, fires.compound[1]["onset_fired_s"].get<double>() + 0.2, 1e-6);
  EXPECT_LT(onset, 2.5);
  EXPECT_NEAR(fires.onset_s, onset, 1e-6);  // the earliest onset is the fired one
  EXPECT_FALSE(fires.compound[0].contains("onset_fired_s"));  // a time: no condition keys

  const RunRecord one_never = RunCase(c, CaseAt(c, 1));
  ASSERT_TRUE(one_never.ok) << one_never.failure_reason;
  EXPECT_TRUE(one_never.injected());
  EXPECT_DOUBLE_EQ(one_never.onset_s, 1.0);
  EXPECT_TRUE(one_never.compound[1]["onset_s"].is_null());
  EXPECT_TRUE(one_never.compound[1]["onset_fired_s"].is_null());
  EXPECT_TRUE(one_never.compound[1]["not_injected_reason"].is_string());
  EXPECT_FALSE(one_never.compound[1]["isolated"].get<bool>());
  EXPECT_FALSE(one_never.compound[1]["excited"].get<bool>());

  const RunRecord none = RunCase(c, CaseAt(c, 2));
  ASSERT_TRUE(none.ok) << none.failure_reason;
  EXPECT_FALSE(none.injected());
  EXPECT_FALSE(none.detected);
  EXPECT_TRUE(none.excited());
  SummaryBuilder b;
  b.Add(none);
  EXPECT_EQ(b.not_injected_runs(), 1);
  EXPECT_EQ(b.Build(Floors(), nullptr, "test")["compound"]["runs"], 0);
}

}  // namespace
}  // namespace armfault
