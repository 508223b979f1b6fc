// A run file (core/run_config.h): its defaults, values, limits and every error with its pointer.
#include "core/run_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/base/json_input.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::ElementsAre;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ErrorTexts;

// A two-joint robot JSON with default modules and links.
json TwoJoints() { return {{"modules", {json::object(), json::object()}}, {"links", {json::object(), json::object()}}}; }

InputContext RunContext() {
  InputContext ctx;
  ctx.source = "run.json";
  return ctx;
}

RunConfig ParseRun(const json& value) { return RunConfigFromJson(value, "", RunContext()); }
InputError RunError(const json& value) { return ErrorOf([&] { ParseRun(value); }); }

json SinePair(double amplitude_deg) {
  return {{"type", "sine_pair"}, {"amplitude_deg", amplitude_deg}, {"omega_rad_s", 1}};
}

TEST(RunConfigFromJson, DefaultsAndValues) {
  RunConfig run = ParseRun(json::object());
  EXPECT_EQ(run.robot.name, "mrr-config1");
  EXPECT_EQ(run.duration_s, 10.0);
  EXPECT_EQ(run.seed, 1u);
  EXPECT_TRUE(run.trajectories.empty());
  EXPECT_EQ(run.trajectories_json, json::object());

  run = ParseRun({{"robot", "pendulum"}, {"duration_s", 2.5}, {"seed", 42}, {"joints", {{"1", SinePair(10)}}}});
  EXPECT_EQ(run.robot.name, "pendulum");
  EXPECT_EQ(run.duration_s, 2.5);
  EXPECT_EQ(run.seed, 42u);
  ASSERT_EQ(run.trajectories.size(), 1u);
  EXPECT_STREQ(run.trajectories.at(1)->type(), "sine_pair");
  EXPECT_EQ(run.trajectories_json, json({{"1", SinePair(10)}}));
}

TEST(RunConfigFromJson, ThesisExperiment1) {
  const RunConfig run = ThesisExperiment1();
  EXPECT_EQ(run.robot.name, "mrr-config1");
  EXPECT_EQ(run.duration_s, 10.0);
  EXPECT_EQ(run.seed, 1u);
  ASSERT_EQ(run.trajectories.size(), 1u);
  EXPECT_STREQ(run.trajectories.at(3)->type(), "sine_pair");
  const RunSpec spec = MakeRunSpec(run);
  EXPECT_EQ(spec.duration_s, 10.0);
  EXPECT_EQ(spec.seed, 1u);
  ASSERT_EQ(spec.joints.size(), 3u);
  EXPECT_EQ(spec.joints[0].trajectory, nullptr);
  EXPECT_EQ(spec.joints[1].trajectory, nullptr);
  EXPECT_EQ(spec.joints[2].trajectory, run.trajectories.at(3));
}

TEST(RunConfigFromJson, SeedLimits) {
  EXPECT_EQ(ParseRun({{"seed", 0}}).seed, 0u);
  EXPECT_EQ(ParseRun({{"seed", 9007199254740991.0}}).seed, 9007199254740991u);
  for (const json& seed : {json(-1), json(1.5), json(9007199254740992.0), json("1")}) {
    const InputError e = RunError({{"seed", seed}});
    EXPECT_EQ(e.source(), "run.json") << seed;
    EXPECT_EQ(e.pointer(), "/seed") << seed;
  }
  EXPECT_EQ(RunError({{"seed", -1}}).message(), "expected a whole number >= 0, got -1");
}

TEST(RunConfigErrors, UnknownJointNumber) {
  for (const std::string key : {"7", "x", "0", "-1", "4", "3a", "", "99999999999999"}) {
    const InputError e = RunError({{"joints", {{key, SinePair(10)}}}});
    EXPECT_EQ(e.source(), "run.json") << key;
    EXPECT_EQ(e.pointer(), "/joints/" + key) << key;
    EXPECT_EQ(e.message(), "\"" + key + "\" is not a joint of robot mrr-config1 (joints 1..3)") << key;
  }
  EXPECT_STREQ(RunError({{"joints", {{"7", SinePair(10)}}}}).what(),
               "run.json: /joints/7: \"7\" is not a joint of robot mrr-config1 (joints 1..3)");
  EXPECT_EQ(RunError({{"robot", "pendulum"}, {"joints", {{"2", SinePair(10)}}}}).message(),
            "\"2\" is not a joint of robot pendulum (joints 1..1)");
  // The pointer of a key with a slash is escaped.
  EXPECT_EQ(RunError({{"joints", {{"1/2", SinePair(10)}}}}).pointer(), "/joints/1~12");
}

// A joint is named by exactly one key: "3", not " 3", "+3" or "03" (which would also let
// two entries for the same joint silently overwrite each other).
// DISABLED: fails, core/run_config.cc accepts anything std::stoi parses completely.
TEST(RunConfigErrors, JointNumbersAreCanonical) {
  for (const std::string key : {" 3", "+3", "03", "\t3"}) {
    const InputError e = RunError({{"joints", {{key, SinePair(10)}}}});
    EXPECT_EQ(e.pointer(), PointerJoin("/joints", key)) << "key \"" << key << "\"";
  }
}

TEST(RunConfigErrors, JointsMustBeAnObject) {
  const InputError e = RunError({{"joints", {SinePair(10)}}});
  EXPECT_EQ(e.pointer(), "/joints");
  EXPECT_THAT(e.message(), HasSubstr("expected an object mapping joint numbers to trajectories"));
}

TEST(RunConfigErrors, TrajectoryBeyondTheJointRangeNamesTheRange) {
  // sine_pair peaks at 1.299 x amplitude: 200 deg -> +-259.8 deg on a +-120 deg joint.
  InputError e = RunError({{"joints", {{"3", SinePair(200)}}}});
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/joints/3");
  EXPECT_EQ(e.message(), "the trajectory spans [-259.808, 259.808] deg, beyond joint 3's range [-120, 120] deg");
  // The MRR1 base joint has +-60 deg: 50 deg x 1.299 does not fit, 40 deg does.
  e = RunError({{"joints", {{"1", SinePair(50)}}}});
  EXPECT_EQ(e.pointer(), "/joints/1");
  EXPECT_THAT(e.message(), HasSubstr("beyond joint 1's range [-60, 60] deg"));
  EXPECT_NO_THROW(ParseRun({{"joints", {{"1", SinePair(40)}}}}));
  // A custom robot's range applies.
  json robot = TwoJoints();
  robot["modules"][1] = {{"min_angle_deg", -10}, {"max_angle_deg", 30}};
  e = RunError({{"robot", robot}, {"joints", {{"2", {{"type", "hold"}, {"angle_deg", -11}}}}}});
  EXPECT_EQ(e.pointer(), "/joints/2");
  EXPECT_EQ(e.message(), "the trajectory spans [-11, -11] deg, beyond joint 2's range [-10, 30] deg");
}

TEST(RunConfigErrors, RangeIsCheckedOverTheRunDurationOnly) {
  // Reaches 150 deg at t = 5 s: fine for a 1 s run, beyond +-120 deg for the default 10 s.
  const json ramp = {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {5, 150}}}};
  EXPECT_NO_THROW(ParseRun({{"duration_s", 1}, {"joints", {{"2", ramp}}}}));
  const InputError e = RunError({{"joints", {{"2", ramp}}}});
  EXPECT_EQ(e.pointer(), "/joints/2");
  EXPECT_THAT(e.message(), HasSubstr("the trajectory spans [0, 150] deg, beyond joint 2's range [-120, 120] deg"));
}

TEST(RunConfigErrors, TrajectoryErrorsKeepTheirPointerUnderJoints) {
  const InputError e = RunError({{"joints", {{"3", {{"type", "sine_pair"}, {"amplitude_deg", 25}}}}}});
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/joints/3/omega_rad_s");
}

TEST(RunConfigErrors, DurationOutOfRange) {
  for (const double d : {0.0, 0.001, -1.0, 3600.5, 1e9}) {
    const InputError e = RunError({{"duration_s", d}});
    EXPECT_EQ(e.source(), "run.json") << d;
    EXPECT_EQ(e.pointer(), "/duration_s") << d;
    EXPECT_THAT(e.message(), HasSubstr("is outside [0.002, 3600]")) << d;
  }
  EXPECT_EQ(RunError({{"duration_s", 0}}).message(), "0 is outside [0.002, 3600]");
  EXPECT_EQ(RunError({{"duration_s", "10"}}).message(), "expected a number, got string \"10\"");
  EXPECT_EQ(ParseRun({{"duration_s", 0.002}}).duration_s, 0.002);
  EXPECT_EQ(ParseRun({{"duration_s", 3600}}).duration_s, 3600);
}

TEST(RunConfigErrors, UnknownKeysAndRobotErrorsCarryTheSource) {
  InputError e = RunError({{"duraton_s", 1}});
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/duraton_s");
  EXPECT_EQ(e.message(), "unknown key \"duraton_s\"");
  EXPECT_STREQ(e.what(), "run.json: /duraton_s: unknown key \"duraton_s\"");

  json robot = TwoJoints();
  robot["modules"][1]["motor"] = {{"kt_Nm_per_A", -1}};
  e = RunError({{"robot", robot}});
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "/robot/modules/1/motor/kt_Nm_per_A");

  e = RunError({{"robot", "nope"}});
  EXPECT_EQ(e.pointer(), "/robot");
  EXPECT_THAT(e.message(), HasSubstr("unknown robot preset \"nope\""));

  e = RunError(json::array());
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_EQ(e.pointer(), "");
  EXPECT_THAT(e.message(), HasSubstr("expected an object"));
}

TEST(RunConfigErrors, EveryPartIsReportedAndJointsNeedTheRobotAndDuration) {
  const InputError e = RunError({{"duraton_s", 1},
                                 {"seed", -1},
                                 {"joints", {{"3", SinePair(10)}, {"7", SinePair(10)}, {"2", {{"type", "spiral"}}}}},
                                 {"monitor", {{"debounce_s", -2}, {"stuck_time_s", "x"}}}});
  EXPECT_EQ(e.source(), "run.json");
  EXPECT_THAT(ErrorTexts(e), ElementsAre("run.json: /duraton_s: unknown key \"duraton_s\"; did you mean \"duration_s\"?",
                                    "run.json: /seed: expected a whole number >= 0, got -1",
                                    "run.json: /joints/2/type: unknown trajectory type \"spiral\"; known types: "
                                    "sine_pair, cosine_ramp, min_jerk, hold, csv",
                                    "run.json: /joints/7: \"7\" is not a joint of robot mrr-config1 (joints 1..3)",
                                    "run.json: /monitor/stuck_time_s: expected a number, got string \"x\"",
                                    "run.json: /monitor/debounce_s: -2 is outside [0, 1000]"));
  // A bad duration: the joints' ranges cannot be checked, so they are not.
  EXPECT_THAT(ErrorTexts(RunError({{"duration_s", 0}, {"joints", {{"3", SinePair(500)}}}})),
              ElementsAre("run.json: /duration_s: 0 is outside [0.002, 3600]"));
}

TEST(RunConfigErrors, PointerPrefixIsKept) {
  const InputError e = ErrorOf([] {
    RunConfigFromJson({{"joints", {{"7", SinePair(10)}}}}, "/runs/2", RunContext());
  });
  EXPECT_EQ(e.pointer(), "/runs/2/joints/7");
}

}  // namespace
}  // namespace armfault
