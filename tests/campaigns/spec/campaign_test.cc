// Campaign files: strict parsing with pointers to the offending value, case expansion, and a
// runner whose results do not depend on threads, shards or an interruption.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <fstream>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/runner.h"
#include "tests/campaigns/campaign_fixtures.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;
using testing_support::ScratchDir;

json Small() { return testing_support::SmallCampaign(3); }

Campaign Parse(const json& j) { return CampaignFromJson(j, "c.json", "."); }

TEST(CampaignParse, CountsCasesAsTheProductOfSweeps) {
  const Campaign c = Parse(Small());
  // kt: 2 values x 2 joints x 2 reps = 8; friction: 3 x 1 x 2 = 6; healthy 2.
  EXPECT_EQ(CaseCount(c), 16);
  const std::vector<CaseSpec> cases = ExpandCases(c);
  ASSERT_EQ(cases.size(), 16u);
  EXPECT_EQ(cases[0].run_id, "exp1/kt_degradation#0/kt_factor=0.9/j2/r0");
  EXPECT_EQ(cases[1].run_id, "exp1/kt_degradation#0/kt_factor=0.9/j2/r1");
  EXPECT_EQ(cases[2].run_id, "exp1/kt_degradation#0/kt_factor=0.9/j3/r0");
  EXPECT_EQ(cases[8].run_id, "exp1/friction_increase#1/friction_factor=1.5,onset_s=U[0.5,1.5]/j3/r0");
  EXPECT_EQ(cases[15].run_id, "exp1/healthy/1");
  EXPECT_EQ(cases[10].fault["friction_factor"], 2.0);  // inclusive grid 1.5, 2, 2.5
  EXPECT_EQ(cases[0].group, "kt_degradation kt_factor=0.9 joint=2");
  for (const CaseSpec& cs : cases) {
    if (cs.fault.is_null()) continue;
    if (cs.fault["family"] == "friction_increase") {
      const double onset = cs.fault["onset_s"].get<double>();
      EXPECT_GE(onset, 0.5);
      EXPECT_LE(onset, 1.5);
    }
    EXPECT_GE(cs.extra_payload_kg, 0.0);
    EXPECT_LE(cs.extra_payload_kg, 0.5);
  }
  // Repetitions draw fresh values; the same case draws the same values every time.
  EXPECT_NE(cases[8].fault["onset_s"], cases[9].fault["onset_s"]);
  EXPECT_EQ(ExpandCases(c)[8].fault, cases[8].fault);
  EXPECT_EQ(ExpandCases(c)[8].seed, cases[8].seed);
}

TEST(CampaignParse, ErrorsPointAtTheOffendingValue) {
  struct Case {
    std::string patch, pointer, message;
  };
  const std::vector<Case> cases = {
      {R"([{"op": "replace", "path": "/faults/0/kt_factor/1", "value": 1.7}])", "/faults/0/kt_factor/1", "1.7"},
      {R"([{"op": "replace", "path": "/faults/0/kt_factor/0", "value": 1.7}])", "/faults/0/kt_factor/0", "1.7"},
      {R"([{"op": "replace", "path": "/faults/1/friction_factor/to", "value": 0.5}])", "/faults/1/friction_factor/from",
       "greater than"},
      {R"([{"op": "replace", "path": "/faults/1/friction_factor/from", "value": 0.5}])", "/faults/1/friction_factor/from",
       "0.5"},
      {R"([{"op": "add", "path": "/faults/0/kt_factr", "value": 0.5}])", "/faults/0/kt_factr", "unknown key"},
      {R"([{"op": "replace", "path": "/faults/0/joint/0", "value": 7}])", "/faults/0/joint/0", "joint 7"},
      {R"([{"op": "replace", "path": "/faults/0/kt_factor", "value": []}])", "/faults/0/kt_factor", "empty sweep"},
      {R"([{"op": "replace", "path": "/faults/1/friction_factor/from", "value": 3}])", "/faults/1/friction_factor/from",
       "greater than"},
      {R"([{"op": "replace", "path": "/faults/0/family", "value": "gremlins"}])", "/faults/0/family", "unknown fault family"},
      {R"([{"op": "replace", "path": "/trajectories/0/joints/3/type", "value": "spiral"}])", "/trajectories/0/joints/3/type",
       "spiral"},
      {R"([{"op": "add", "path": "/healthy", "value": -1}])", "/healthy", "-1"},
      {R"([{"op": "add", "path": "/floors/detection_rate", "value": 1.5}])", "/floors/detection_rate", "1.5"},
      {R"([{"op": "add", "path": "/floors/per_family", "value": {"gremlins": {}}}])", "/floors/per_family/gremlins",
       "unknown fault family"},
      {R"([{"op": "add", "path": "/variation/friction_sprd", "value": 0.1}])", "/variation/friction_sprd", "unknown key"},
      {R"([{"op": "add", "path": "/monitor", "value": {"kt_factor": {"worn": 2}}}])", "/monitor/kt_factor/worn", "2"},
      {R"([{"op": "add", "path": "/variation/tolerances", "value": {"kt": -0.1}}])", "/variation/tolerances/kt", "-0.1"},
      {R"([{"op": "add", "path": "/variation/tolerances", "value": {"kt": 2}}])", "/variation/tolerances/kt", "2"},
      {R"([{"op": "add", "path": "/variation/tolerances", "value": {"kt_spread": 0.1}}])", "/variation/tolerances/kt_spread",
       "unknown key"},
      {R"([{"op": "add", "path": "/variation/tolerances", "value": "catalog"}])", "/variation/tolerances",
       "unknown tolerance preset"},
      {R"([{"op": "add", "path": "/variation/tolerances", "value": {"preset": "datasheet", "bus_voltage": 0.9}}])",
       "/variation/tolerances/bus_voltage", "0.9"},
      {R"([{"op": "add", "path": "/variation/ambient_C", "value": {"uniform": [40, 15]}}])", "/variation/ambient_C/uniform/0",
       "greater than"},
      {R"([{"op": "add", "path": "/variation/ambient_C", "value": 300}])", "/variation/ambient_C", "300"},
      {R"([{"op": "add", "path": "/variation/units", "value": 0}])", "/variation/units", "0"},
      {R"([{"op": "add", "path": "/variation/warm_start_fraction", "value": 1.5}])", "/variation/warm_start_fraction", "1.5"},
      {R"([{"op": "add", "path": "/variation/warm_start_fraction", "value": "half"}])", "/variation/warm_start_fraction",
       "expected a number"},
      {R"([{"op": "add", "path": "/commissioning", "value": "yes"}])", "/commissioning", "expected true, false or"},
      {R"([{"op": "add", "path": "/commissioning", "value": {"trajectory": "pick"}}])", "/commissioning/trajectory",
       "no trajectory named \"pick\" in this campaign (its trajectories: \"exp1\")"},
      {R"([{"op": "add", "path": "/commissioning", "value": {"duration_s": 4}}])", "/commissioning/duration_s", "4"},
      {R"([{"op": "add", "path": "/commissioning", "value": {"duraton_s": 2}}])", "/commissioning/duraton_s", "unknown key"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.patch);
    const json bad = Small().patch(json::parse(c.patch));
    const InputError e = ErrorOf([&] { Parse(bad); });
    EXPECT_EQ(e.count(), 1u);  // one mistake, one error: no echo from dependent checks
    EXPECT_EQ(e.source(), "c.json");
    EXPECT_EQ(e.pointer(), c.pointer);
    EXPECT_THAT(e.message(), HasSubstr(c.message));
  }
}

// Each error as the command line prints it (what() and any hint).
std::vector<std::string> Texts(const InputError& e) {
  std::vector<std::string> out;
  for (const InputError& one : e.errors()) out.push_back(one.text());
  return out;
}

TEST(CampaignParseAllErrors, ThreeIndependentErrorsAreExactlyThoseThree) {
  const json bad = Small().patch(json::parse(R"([
    {"op": "replace", "path": "/faults/0/kt_factor/1", "value": 1.7},
    {"op": "replace", "path": "/healthy", "value": -1},
    {"op": "add", "path": "/variation/friction_sprd", "value": 0.1}])"));
  const InputError e = ErrorOf([&] { Parse(bad); });
  EXPECT_THAT(Texts(e), testing::ElementsAre(
                            "c.json: /faults/0/kt_factor/1: kt_degradation: 1.7 is outside [0, 1]",
                            "c.json: /healthy: -1 is outside [0, 1000000]",
                            "c.json: /variation/friction_sprd: unknown key \"friction_sprd\"; did you mean \"friction_spread\"?"));
  // The first error reads exactly as it did when the loader stopped at it.
  const json first_only = Small().patch(json::parse(R"([{"op": "replace", "path": "/faults/0/kt_factor/1", "value": 1.7}])"));
  const InputError alone = ErrorOf([&] { Parse(first_only); });
  EXPECT_EQ(alone.count(), 1u);
  EXPECT_STREQ(e.what(), alone.what());
  EXPECT_STREQ(e.what(), "c.json: /faults/0/kt_factor/1: kt_degradation: 1.7 is outside [0, 1]");
  EXPECT_EQ(e.pointer(), "/faults/0/kt_factor/1");
}

TEST(CampaignParseAllErrors, ManyErrorsAreCutAtTheLimit) {
  json bad = Small();
  bad["faults"][0]["kt_factor"] = json::array();
  for (int i = 0; i < 25; ++i) bad["faults"][0]["kt_factor"].push_back(2 + i);
  const InputError e = ErrorOf([&] { Parse(bad); });
  ASSERT_EQ(e.count(), 25u);
  const std::vector<std::string> lines = ErrorReportLines(e);
  ASSERT_EQ(lines.size(), 21u);
  EXPECT_EQ(lines[0], "c.json: /faults/0/kt_factor/0: kt_degradation: 2 is outside [0, 1]");
  EXPECT_EQ(lines[19], "c.json: /faults/0/kt_factor/19: kt_degradation: 21 is outside [0, 1]");
  EXPECT_EQ(lines[20], "... and 5 more errors");
}

TEST(CampaignParseAllErrors, EveryUnknownKeyIsItsOwnError) {
  const json bad = Small().patch(json::parse(R"([
    {"op": "add", "path": "/durations", "value": 3},
    {"op": "add", "path": "/trajectories/0/joints/3/omga_rad_s", "value": 1},
    {"op": "add", "path": "/faults/0/kt_factr", "value": 0.5},
    {"op": "add", "path": "/faults/0/onset_sec", "value": 0.5},
    {"op": "add", "path": "/floors/detection_rte", "value": 0.5},
    {"op": "add", "path": "/monitor", "value": {"debounce": 1, "kt_factor": {"wron": 0.9}}}])"));
  EXPECT_THAT(Texts(ErrorOf([&] { Parse(bad); })),
              testing::ElementsAre(
                  "c.json: /durations: unknown key \"durations\"; did you mean \"duration_s\"?",
                  "c.json: /trajectories/0/joints/3/omga_rad_s: unknown key \"omga_rad_s\"; did you mean \"omega_rad_s\"?",
                  "c.json: /faults/0/kt_factr: kt_degradation: unknown key \"kt_factr\"; did you mean \"kt_factor\"?",
                  "c.json: /faults/0/onset_sec: kt_degradation: unknown key \"onset_sec\"; did you mean \"onset_s\"?",
                  "c.json: /monitor/debounce: unknown key \"debounce\"; did you mean \"debounce_s\"?",
                  "c.json: /monitor/kt_factor/wron: unknown key \"wron\"; did you mean \"worn\"?",
                  "c.json: /floors/detection_rte: unknown key \"detection_rte\"; did you mean \"detection_rate\"?"));
}

TEST(CampaignParseAllErrors, ValuesOfOneEntryAreCheckedPastABadNeighbour) {
  // onset_s is bad at its first value; kt_factor's own bad values still show, and so does
  // the bad joint.
  json bad = Small();
  bad["faults"][0] = json::parse(R"({"family": "kt_degradation", "joint": [3, 9], "kt_factor": [0.9, 1.5, 1.7],
                                     "onset_s": [-1, 2]})");
  EXPECT_THAT(Texts(ErrorOf([&] { Parse(bad); })),
              testing::ElementsAre("c.json: /faults/0/onset_s/0: kt_degradation: -1 is below the minimum 0",
                                   "c.json: /faults/0/joint/1: kt_degradation: joint 9 does not exist: robot mrr-config1 has joints 1..3",
                                   "c.json: /faults/0/kt_factor/1: kt_degradation: 1.5 is outside [0, 1]",
                                   "c.json: /faults/0/kt_factor/2: kt_degradation: 1.7 is outside [0, 1]"));
}

TEST(CampaignParseAllErrors, EveryBadKeyOfOneTrajectoryOrFaultEntryAtOnce) {
  // Within one trajectory or fault entry each key is checked on its own: a bad or unknown
  // key does not hide the next one until it is fixed.
  json bad = Small();
  bad["trajectories"] = json::parse(R"([
    {"name": "a", "joints": {"3": {"type": "sine_pair", "amplitude_deg": "x", "omega_rad_s": -1, "offset_deg": "y"}}},
    {"name": "b", "joints": {"3": {"type": "hold", "angle_deg": "z", "angel_deg": 1}}},
    {"name": "c", "joints": {"3": {"type": "cosine_ramp", "amplitde_deg": 20, "period_s": 0}}},
    {"name": "d", "joints": {"3": {"type": "min_jerk", "waypoints": [[0, 0], [1]], "foo": 1}}}])");
  bad["faults"] = json::parse(R"([
    {"family": "inverter_short", "joint": 3, "kind": "phase_phse", "resistance_ohm": -1},
    {"family": "brake_lock", "joint": 3, "drag_fraction": 2, "onset_s": -1, "profile": "bogus", "ramp_s": -2},
    {"family": "kt_degradation", "joint": 3, "kt_factr": 0.5, "onset_s": 1, "profile": "abrupt", "ramp_s": 1}])");
  EXPECT_THAT(Texts(ErrorOf([&] { Parse(bad); })),
              testing::ElementsAre(
                  "c.json: /trajectories/0/joints/3/amplitude_deg: expected a number, got string \"x\"",
                  "c.json: /trajectories/0/joints/3/omega_rad_s: -1 must be greater than 0",
                  "c.json: /trajectories/0/joints/3/offset_deg: expected a number, got string \"y\"",
                  "c.json: /trajectories/1/joints/3/angel_deg: unknown key \"angel_deg\"; did you mean \"angle_deg\"?",
                  "c.json: /trajectories/1/joints/3/angle_deg: expected a number, got string \"z\"",
                  // A key missing beside an unknown one is that one misspelt: not reported twice.
                  "c.json: /trajectories/2/joints/3/amplitde_deg: unknown key \"amplitde_deg\"; did you mean \"amplitude_deg\"?",
                  "c.json: /trajectories/2/joints/3/period_s: 0 must be greater than 0",
                  "c.json: /trajectories/3/joints/3/foo: unknown key \"foo\"",
                  "c.json: /trajectories/3/joints/3/waypoints/1: expected a [time_s, angle_deg] pair, got [1]",
                  "c.json: /faults/0/kind: inverter_short: unknown kind \"phase_phse\" (known: phase_phase, phase_ground, switch)",
                  "c.json: /faults/0/resistance_ohm: inverter_short: -1 is outside [0.001, 1000]",
                  "c.json: /faults/1/onset_s: brake_lock: -1 is below the minimum 0",
                  "c.json: /faults/1/profile: brake_lock: unknown profile \"bogus\" (known: abrupt, incipient, intermittent)",
                  "c.json: /faults/1/ramp_s: brake_lock: -2 must be greater than 0",
                  "c.json: /faults/1/drag_fraction: brake_lock: 2 is outside [0, 1]",
                  "c.json: /faults/2/kt_factr: kt_degradation: unknown key \"kt_factr\"; did you mean \"kt_factor\"?",
                  "c.json: /faults/2/ramp_s: kt_degradation: ramp_s does not apply to the abrupt profile"));
}

TEST(CampaignParseAllErrors, DependentChecksAreSkipped) {
  // A bad robot: trajectories are not checked against its joints and fault values not
  // through the family (both need it), but their own shape still is.
  json bad = Small();
  bad["robot"] = "mrr-config9";
  bad["trajectories"][0]["joints"]["7"] = {{"type", "hold"}};            // needs the robot: skipped
  bad["trajectories"][0]["joints"]["3"]["omega_rad_s"] = "fast";         // its own shape: reported
  bad["faults"][1]["family"] = "friction_increse";                        // reported
  bad["faults"][0]["kt_factor"] = {0.9, 1.7};                             // needs the robot: skipped
  EXPECT_THAT(Texts(ErrorOf([&] { Parse(bad); })),
              testing::ElementsAre(
                  "c.json: /robot: unknown robot preset \"mrr-config9\" (known: mrr-config1, pendulum, ur-class)",
                  "c.json: /trajectories/0/joints/3/omega_rad_s: expected a number, got string \"fast\"",
                  "c.json: /faults/1/family: unknown fault family \"friction_increse\" (known: kt_degradation, "
                  "friction_increase, brake_lock, torque_sensor_stuck, inverter_short, winding_resistance, "
                  "torque_sensor_drift); did you mean \"friction_increase\"?"));
  // A grid with a bad end: the points between are not reported as well.
  json grid = Small();
  grid["faults"][1]["friction_factor"] = {{"from", 0.5}, {"to", 200}, {"steps", 50}};
  EXPECT_THAT(Texts(ErrorOf([&] { Parse(grid); })),
              testing::ElementsAre("c.json: /faults/1/friction_factor/from: friction_increase: 0.5 is outside [1, 100]",
                                   "c.json: /faults/1/friction_factor/to: friction_increase: 200 is outside [1, 100]"));
  // The run count needs every part: not checked while another error stands.
  json empty = Small();
  empty.erase("faults");
  empty["healthy"] = 0;
  empty["repetitions"] = 0;
  EXPECT_THAT(Texts(ErrorOf([&] { Parse(empty); })),
              testing::ElementsAre("c.json: /repetitions: 0 is outside [1, 1000000]"));
}

TEST(CampaignParse, AHealthyOnlyCampaignIsValidAnEmptyOneIsNot) {
  json healthy_only = Small();
  healthy_only.erase("faults");
  EXPECT_EQ(CaseCount(Parse(healthy_only)), 2);
  healthy_only["healthy"] = 0;
  EXPECT_THAT(ErrorOf([&] { Parse(healthy_only); }).message(), HasSubstr("no runs"));
}

TEST(CampaignParse, SchemaKeyIsForEditorsOnly) {
  // "$schema" lets an editor find campaigns/spec/campaign.schema.json: accepted, checked to be a
  // string, and left out of the resolved campaign (so of its hash).
  json with_schema = Small();
  with_schema["$schema"] = "../campaigns/spec/campaign.schema.json";
  EXPECT_EQ(Parse(with_schema).resolved, Parse(Small()).resolved);
  EXPECT_FALSE(Parse(with_schema).resolved.contains("$schema"));
  with_schema["$schema"] = 3;
  const InputError e = ErrorOf([&] { Parse(with_schema); });
  EXPECT_EQ(e.pointer(), "/$schema");
  EXPECT_THAT(e.message(), HasSubstr("expected a string"));
}

TEST(CampaignParse, ShippedCampaignsAreValid) {
  for (const char* name : {"thesis-sweep.json", "five-families.json", "ci.json"}) {
    const Campaign c = ReadCampaignFile(std::string(ARMFAULT_SOURCE_DIR) + "/campaigns/files/" + name);
    EXPECT_GT(CaseCount(c), 0) << name;
  }
  EXPECT_EQ(DefaultCampaign().name, "thesis-sweep");
}

// A short campaign for the runner tests: 1.5 s runs.
Campaign Quick() {
  json j = Small();
  j["duration_s"] = 1.5;
  return Parse(j);
}

// Runs `c` with 1 and with 2 threads into DIR/j1 and DIR/j2; returns both results.jsonl texts.
std::pair<std::string, std::string> RunOnOneAndTwoThreads(const Campaign& c, const ScratchDir& dir) {
  RunnerOptions one;
  one.output_dir = (dir.path() / "j1").string();
  one.threads = 1;
  RunnerOptions two = one;
  two.output_dir = (dir.path() / "j2").string();
  two.threads = 2;
  RunCampaign(c, one);
  RunCampaign(c, two);
  return {ReadAll(dir.path() / "j1" / "results.jsonl"), ReadAll(dir.path() / "j2" / "results.jsonl")};
}

TEST(CampaignRunner, ResultsAreIdenticalForAnyThreadCount) {
  ScratchDir dir("runner");
  const auto [a, b] = RunOnOneAndTwoThreads(Quick(), dir);
  EXPECT_EQ(a, b);
  EXPECT_EQ(std::count(a.begin(), a.end(), '\n'), 16);
  EXPECT_EQ(ReadAll(dir.path() / "j1" / "decisions.jsonl"), ReadAll(dir.path() / "j2" / "decisions.jsonl"));
}

TEST(CampaignRunner, DecisionsGoToTheirOwnFileInTheOrderOfTheResults) {
  ScratchDir dir("decisions");
  const Campaign c = Quick();
  RunnerOptions o;
  o.output_dir = dir.path().string();
  o.threads = 2;
  RunCampaign(c, o);
  const std::vector<std::string> results = Lines(ReadAll(dir.path() / "results.jsonl"));
  const std::vector<std::string> decisions = Lines(ReadAll(dir.path() / "decisions.jsonl"));
  ASSERT_EQ(results.size(), 16u);
  ASSERT_EQ(decisions.size(), results.size());
  const std::vector<CaseSpec> cases = ExpandCases(c);
  for (size_t k = 0; k < results.size(); ++k) {
    const json r = json::parse(results[k]);
    // results.jsonl stays small: no decision statistics, about 1 kB a run.
    EXPECT_FALSE(r.contains("decision")) << k;
    EXPECT_LT(results[k].size(), 1500u) << r["run_id"];
    const json d = json::parse(decisions[k]);
    EXPECT_EQ(d.size(), 3u) << decisions[k].substr(0, 200);
    EXPECT_EQ(d["case_index"], r["case"]);
    EXPECT_EQ(d["run_id"], r["run_id"]);
    EXPECT_EQ(d["run_id"], cases[k].run_id);
    ASSERT_TRUE(d["decision"].is_object()) << k;
    EXPECT_TRUE(d["decision"].contains("traces")) << k;
    // The decision line is the record's, as RunCase makes it (trace --run relies on RunCase).
    if (k == 0) {
      EXPECT_EQ(DecisionLineJson(RunCase(c, cases[k])).dump(), decisions[k]);
    }
  }
  // An older line with the decision inline still reads, keeping it.
  json old = json::parse(results[0]);
  old["decision"] = json::parse(decisions[0])["decision"];
  const RunRecord from_old = RunRecordFromJson(old);
  EXPECT_EQ(from_old.decision, old["decision"]);
  EXPECT_EQ(ToJson(from_old).dump(), results[0]);  // and writes it back without
}

// The message of the std::runtime_error `f` throws.
template <class F>
std::string ErrorMessageOf(F&& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

TEST(CampaignRunner, ADecisionLineMustHaveItsKeys) {
  EXPECT_THAT(ErrorMessageOf([] { DecisionLineFromJson(json::parse(R"({"case_index": 1, "decision": {}})")); }),
              HasSubstr("\"run_id\""));
  EXPECT_THAT(ErrorMessageOf([] { DecisionLineFromJson(json::parse(R"({"case_index": 1, "run_id": "a", "decision": 3})")); }),
              HasSubstr("\"decision\" has the wrong type"));
  const DecisionLine d = DecisionLineFromJson(json::parse(R"({"case_index": 4, "run_id": "a", "decision": null})"));
  EXPECT_EQ(d.case_index, 4);
  EXPECT_TRUE(d.decision.is_null());
}

// A fleet: datasheet tolerances, 4 units, 15-40 °C, commissioning.
json Fleet() {
  json j = Small();
  j["variation"] = json::parse(R"({"tolerances": "datasheet", "ambient_C": {"uniform": [15, 40]}, "units": 4,
                                   "friction_spread": 0.15})");
  j["duration_s"] = 2;
  return j;
}

// Commissioning on one of the campaign's trajectories: by name, for the given seconds; the
// resolved campaign writes the object with its defaults, and reads back the same.
TEST(CampaignFleet, CommissioningOnATrajectoryIsReadAndWrittenBack) {
  json j = Fleet();
  j["commissioning"] = {{"duration_s", 1.5}};
  const Campaign c = Parse(j);
  EXPECT_TRUE(c.commissioning);
  EXPECT_EQ(c.commissioning_trajectory, 0);  // the first, by default
  EXPECT_EQ(c.commissioning_duration_s, 1.5);
  EXPECT_EQ(c.resolved["commissioning"], json::parse(R"({"trajectory": "exp1", "duration_s": 1.5})"));
  const Campaign again = Parse(c.resolved);
  EXPECT_EQ(again.commissioning_trajectory, 0);
  EXPECT_EQ(again.commissioning_duration_s, 1.5);
  // A boolean keeps the sine motion.
  j["commissioning"] = true;
  EXPECT_EQ(Parse(j).commissioning_trajectory, -1);
}

TEST(CampaignFleet, RunsOfOneUnitShareItsDrawsAndUnitsDiffer) {
  const Campaign c = Parse(Fleet());
  EXPECT_TRUE(c.commissioning);  // on by default with tolerances
  std::map<int, json> by_unit;
  std::set<double> ambients;
  for (const CaseSpec& cs : ExpandCases(c)) {
    ASSERT_GE(cs.unit, 0);
    ASSERT_LT(cs.unit, 4);
    ASSERT_EQ(cs.tolerance_draws.size(), 3u);
    const json drawn = {{"tolerances", cs.VariationJson()["tolerances"]}, {"friction", cs.friction_factors}};
    auto [it, inserted] = by_unit.emplace(cs.unit, drawn);
    if (!inserted) {
      EXPECT_EQ(it->second, drawn) << "unit " << cs.unit;  // one unit, one draw
    }
    ambients.insert(cs.ambient_C);  // ambient is the run's
  }
  EXPECT_GE(by_unit.size(), 2u);
  EXPECT_NE(by_unit.begin()->second, by_unit.rbegin()->second);
  EXPECT_GT(ambients.size(), 4u);
  for (double a : ambients) EXPECT_TRUE(a >= 15 && a < 40) << a;
  // Each draw within its stated half-width about the datasheet value.
  for (const CaseSpec& cs : ExpandCases(c)) {
    for (const auto& joint : cs.tolerance_draws) {
      for (size_t k = 0; k < ToleranceKeys().size(); ++k) {
        const double s = DatasheetTolerances().*ToleranceKeys()[k].member;
        EXPECT_LE(std::fabs(joint[k] - (ToleranceKeys()[k].absolute ? 0.0 : 1.0)), s + 1e-12) << ToleranceKeys()[k].name;
      }
    }
  }
}

// Warm starts drawn per run; only a campaign that asks draws (older streams kept).
TEST(CampaignFleet, WarmStartFractionDrawsWarmRunsAndRecordsThem) {
  json j = Fleet();
  const std::vector<CaseSpec> before = ExpandCases(Parse(j));
  j["variation"]["warm_start_fraction"] = 0.5;
  const std::vector<CaseSpec> cases = ExpandCases(Parse(j));
  ASSERT_EQ(cases.size(), before.size());
  int warm = 0;
  for (size_t i = 0; i < cases.size(); ++i) {
    EXPECT_FALSE(before[i].warm_start);
    EXPECT_FALSE(before[i].VariationJson().contains("start"));
    EXPECT_EQ(cases[i].ambient_C, before[i].ambient_C);  // drawn after the older draws
    EXPECT_EQ(cases[i].VariationJson().contains("start"), cases[i].warm_start);
    warm += cases[i].warm_start;
  }
  EXPECT_GT(warm, 0);
  EXPECT_LT(warm, static_cast<int>(cases.size()));
  j["variation"]["warm_start_fraction"] = 1;
  for (const CaseSpec& cs : ExpandCases(Parse(j))) EXPECT_TRUE(cs.warm_start);
}

TEST(CampaignFleet, ResultsAreIdenticalForAnyThreadCountAndRecordTheUnit) {
  ScratchDir dir("fleet");
  json j = Fleet();
  j["healthy"] = 2;
  j["faults"] = json::array({j["faults"][0]});
  j["repetitions"] = 1;
  const Campaign c = Parse(j);
  const auto [a, b] = RunOnOneAndTwoThreads(c, dir);
  EXPECT_EQ(a, b);
  std::istringstream lines(a);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    const json r = json::parse(line);
    EXPECT_EQ(r["status"], "ok") << r["reason"];
    EXPECT_TRUE(r["variation"].contains("unit"));
    EXPECT_TRUE(r["variation"].contains("ambient_C"));
    EXPECT_EQ(r["variation"]["tolerances"]["kt"].size(), 3u);
    ++n;
  }
  EXPECT_EQ(n, 6);
  // A run alone gives its line again: the unit is commissioned the same way.
  const std::vector<CaseSpec> cases = ExpandCases(c);
  std::getline(std::istringstream(a), line);
  EXPECT_EQ(ToJson(RunCase(c, cases[0])).dump(), line);
}

TEST(CampaignFleet, WithoutCommissioningTheLimitsWidenFromTheStatedTolerances) {
  json j = Fleet();
  j["commissioning"] = false;
  const Campaign c = Parse(j);
  const Campaign plain = Parse(Small());
  auto config = [](const Campaign& k) { return dynamic_cast<const PowerEfficiencyModel&>(*k.monitor_model).model().config; };
  EXPECT_LT(config(c).kt_factor.worn, config(plain).kt_factor.worn - 0.05);
  EXPECT_GT(config(c).friction_factor.worn, config(plain).friction_factor.worn + 0.1);
  // campaign.json keeps the limits as given: reading it again widens them the same way.
  EXPECT_EQ(c.resolved["monitor"], plain.resolved["monitor"]);
  EXPECT_EQ(config(Parse(c.resolved)).kt_factor.worn, config(c).kt_factor.worn);
}

TEST(CampaignRunner, ShardsPartitionTheCases) {
  ScratchDir dir("shards");
  const Campaign c = Quick();
  long total = 0;
  for (int k = 0; k < 3; ++k) {
    RunnerOptions o;
    o.output_dir = (dir.path() / std::to_string(k)).string();
    o.shard = {k, 3};
    total += RunCampaign(c, o).ran;
    std::ifstream in(dir.path() / std::to_string(k) / "results.jsonl");
    std::string line;
    while (std::getline(in, line)) EXPECT_EQ(json::parse(line)["case"].get<long>() % 3, k);
  }
  EXPECT_EQ(total, 16);
}

// The first `lines` lines of `text`, then `extra` bytes of the next one.
std::string Head(const std::string& text, int lines, size_t extra = 0) {
  size_t pos = 0;
  for (int k = 0; k < lines; ++k) pos = text.find('\n', pos) + 1;
  return text.substr(0, pos) + text.substr(pos, extra);
}

TEST(CampaignRunner, ResumeAfterACutCompletesWithTheSameBytes) {
  ScratchDir dir("resume");
  const Campaign c = Quick();
  RunnerOptions o;
  o.output_dir = (dir.path() / "full").string();
  RunCampaign(c, o);
  const std::string full = ReadAll(dir.path() / "full" / "results.jsonl");
  const std::string full_decisions = ReadAll(dir.path() / "full" / "decisions.jsonl");

  // As if killed mid-write: 5 complete lines and half of the sixth, in each file.
  o.output_dir = (dir.path() / "cut").string();
  RunCampaign(c, o);
  std::ofstream(dir.path() / "cut" / "results.jsonl", std::ios::binary | std::ios::trunc) << Head(full, 5, 40);
  std::ofstream(dir.path() / "cut" / "decisions.jsonl", std::ios::binary | std::ios::trunc) << Head(full_decisions, 5, 300);
  o.resume = true;
  const RunnerResult r = RunCampaign(c, o);
  EXPECT_EQ(r.resumed, 5);
  EXPECT_EQ(r.ran, 11);
  EXPECT_EQ(ReadAll(dir.path() / "cut" / "results.jsonl"), full);
  EXPECT_EQ(ReadAll(dir.path() / "cut" / "decisions.jsonl"), full_decisions);

  // Each way a kill can leave the two files (the decision line is written first): the
  // longest prefix both hold is kept, and the rest run again, to the same bytes.
  struct Cut {
    int results, decisions;                  // complete lines kept
    size_t results_extra, decisions_extra;   // bytes of the cut line after them
    long resumed;
  };
  for (const Cut& cut : {Cut{7, 8, 0, 0, 7},       // killed between the two writes
                         Cut{7, 7, 0, 120, 7},     // killed in the decision line
                         Cut{7, 8, 25, 0, 7},      // killed in the results line
                         Cut{9, 4, 0, 10, 4},      // decisions behind (edited by hand): their prefix
                         Cut{16, 16, 0, 0, 16}}) {  // complete: nothing runs again
    std::ofstream(dir.path() / "cut" / "results.jsonl", std::ios::binary | std::ios::trunc)
        << Head(full, cut.results, cut.results_extra);
    std::ofstream(dir.path() / "cut" / "decisions.jsonl", std::ios::binary | std::ios::trunc)
        << Head(full_decisions, cut.decisions, cut.decisions_extra);
    const RunnerResult again = RunCampaign(c, o);
    EXPECT_EQ(again.resumed, cut.resumed) << cut.results << "/" << cut.decisions;
    EXPECT_EQ(again.ran, 16 - cut.resumed);
    EXPECT_EQ(ReadAll(dir.path() / "cut" / "results.jsonl"), full) << cut.results << "/" << cut.decisions;
    EXPECT_EQ(ReadAll(dir.path() / "cut" / "decisions.jsonl"), full_decisions) << cut.results << "/" << cut.decisions;
  }
  // No decisions.jsonl beside a results.jsonl (removed, or an older armfault's directory):
  // nothing is kept, and everything runs again.
  std::filesystem::remove(dir.path() / "cut" / "decisions.jsonl");
  const RunnerResult rerun = RunCampaign(c, o);
  EXPECT_EQ(rerun.resumed, 0);
  EXPECT_EQ(rerun.ran, 16);
  EXPECT_EQ(ReadAll(dir.path() / "cut" / "results.jsonl"), full);
  EXPECT_EQ(ReadAll(dir.path() / "cut" / "decisions.jsonl"), full_decisions);

  // Resuming a directory of another campaign is refused.
  json other = Small();
  other["seed"] = 4;
  other["duration_s"] = 1.5;
  EXPECT_THAT(ErrorOf([&] { RunCampaign(Parse(other), o); }).message(), HasSubstr("another campaign"));
}

TEST(CampaignRunner, AFailingRunIsRecordedAndTheCampaignGoesOn) {
  // A case that cannot even be set up (a fault value the family rejects) becomes a failed
  // record with the reason, not an exception that stops the campaign.
  const Campaign c = Quick();
  CaseSpec bad = ExpandCases(c)[0];
  bad.fault["kt_factor"] = -1;  // rejected when the run is set up
  const RunRecord r = RunCase(c, bad);
  EXPECT_FALSE(r.ok);
  EXPECT_THAT(r.failure_reason, HasSubstr("kt_factor"));
}

TEST(CampaignWarnings, AFaultOnAJointATrajectoryLeavesStillIsNamed) {
  const std::vector<std::string> w = CampaignWarnings(Parse(Small()));
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0], "/faults/0 (kt_degradation) targets joint 2, which trajectory \"exp1\" leaves still: its runs there "
                  "will be not excited (kt_degradation shows only in motion) and left out of the rates");
  json moving = Small();
  moving["trajectories"][0]["joints"]["2"] = {{"type", "sine_pair"}, {"amplitude_deg", 10}, {"omega_rad_s", 1.0}};
  EXPECT_TRUE(CampaignWarnings(Parse(moving)).empty());
}

TEST(CampaignErrors, AnOnsetAtOrAfterTheEndOfTheRunIsAnError) {
  // Small() runs 3 s; its second entry's onset is uniform on [0.5, 1.5].
  json late = Small();
  late["trajectories"][0]["joints"]["2"] = {{"type", "sine_pair"}, {"amplitude_deg", 10}, {"omega_rad_s", 1.0}};
  late["faults"][0]["onset_s"] = {1, 3};
  late["faults"][1]["onset_s"] = {{"uniform", {2, 4}}};
  try {
    CampaignFromJson(late, "c.json", ".");
    FAIL() << "no error";
  } catch (const InputError& e) {
    ASSERT_EQ(e.count(), 2u);
    EXPECT_STREQ(e.errors()[0].what(), "c.json: /faults/0/onset_s: onset_s 3 s is at or after the end of the run "
                                       "(duration_s 3): the fault would never act");
    EXPECT_THAT(e.errors()[1].what(), testing::StartsWith("c.json: /faults/1/onset_s: onset_s up to 4 s is at or after"));
  }
  late["faults"][0]["onset_s"] = {1, 2.999};
  late["faults"][1]["onset_s"] = {{"uniform", {2, 2.9}}};
  EXPECT_NO_THROW(CampaignFromJson(late, "c.json", "."));
  EXPECT_TRUE(CampaignWarnings(Parse(late)).empty());
}

TEST(CampaignRunner, RecordsSayWhetherTheFaultCouldActAndWhyARunWasWrong) {
  const Campaign c = Parse(Small());
  bool saw_still = false, saw_moving = false;
  for (const CaseSpec& cs : ExpandCases(c)) {
    if (cs.fault.is_null() || cs.fault["family"] != "kt_degradation" || cs.repetition != 0 || cs.fault["kt_factor"] != 0.6) continue;
    const RunRecord r = RunCase(c, cs);
    ASSERT_TRUE(r.ok) << r.failure_reason;
    if (r.joint == 2) {
      saw_still = true;
      EXPECT_FALSE(r.excited());
      EXPECT_THAT(r.not_excited_reason, HasSubstr("joint 2 was asked to move 0 rad"));
      EXPECT_EQ(ToJson(r).at("excited"), false);
    } else {
      saw_moving = true;
      EXPECT_TRUE(r.excited());
      EXPECT_EQ(ToJson(r).at("not_excited_reason"), nullptr);
      // Scored right, so nothing to explain; a wrong run always says why.
      EXPECT_EQ(r.miss_reason.empty(), r.detected && r.isolated_family == r.family && r.isolated_joint == r.joint);
    }
    EXPECT_EQ(RunRecordFromJson(ToJson(r)).not_excited_reason, r.not_excited_reason);
  }
  EXPECT_TRUE(saw_still && saw_moving);
}

}  // namespace
}  // namespace armfault
