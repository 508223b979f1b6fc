// The monitor registry, the scoring every monitor shares (verdicts against the onset), and the
// contract check that fails a run whose monitor emits garbage.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/monitors/registry.h"
#include "core/plant/robot/robot_config.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ScratchDir;

InputContext Context(const std::string& source = "c.json") {
  InputContext c;
  c.source = source;
  return c;
}

TEST(MonitorRegistry, TypeDefaultsToPowerEfficiencyAndKeepsTheOlderShape) {
  const MonitorSpec plain = MonitorSpecFromJson(json{{"debounce_s", 0.5}}, "/monitor", Context());
  EXPECT_EQ(plain.type, "power_efficiency");
  EXPECT_EQ(plain.settings["debounce_s"], 0.5);
  EXPECT_TRUE(plain.settings.contains("kt_factor"));  // resolved: every default filled in
  // Written back without "type", so an older campaign keeps its hash.
  EXPECT_FALSE(plain.ToJson().contains("type"));
  const MonitorSpec typed =
      MonitorSpecFromJson(json{{"type", "power_efficiency"}, {"debounce_s", 0.5}}, "/monitor", Context());
  EXPECT_EQ(typed.ToJson(), plain.ToJson());
}

TEST(MonitorRegistry, UnknownTypeNamesTheFieldTheValueAndTheNearestType) {
  const InputError e = ErrorOf([] { MonitorSpecFromJson(json{{"type", "power_eficiency"}}, "/monitor", Context()); });
  EXPECT_EQ(e.source(), "c.json");
  EXPECT_EQ(e.pointer(), "/monitor/type");
  EXPECT_THAT(e.message(), HasSubstr("unknown monitor type \"power_eficiency\""));
  EXPECT_THAT(e.hint(), HasSubstr("power_efficiency"));
  const InputError n = ErrorOf([] { MonitorSpecFromJson(json{{"type", 3}}, "/monitor", Context()); });
  EXPECT_EQ(n.pointer(), "/monitor/type");
  const InputError v = ErrorOf([] { MonitorSpecFromJson(json::array(), "/monitor", Context()); });
  EXPECT_EQ(v.pointer(), "/monitor");
  EXPECT_THAT(v.message(), HasSubstr("got []"));
}

TEST(MonitorRegistry, APythonMonitorIsReadAsAnyTypeButBuiltOnlyByThePythonPackage) {
  const MonitorSpec spec = MonitorSpecFromJson(json{{"type", "python"}, {"factory", "m.M"}}, "/monitor", Context());
  EXPECT_EQ(spec.type, "python");
  EXPECT_EQ(spec.ToJson(), (json{{"type", "python"}, {"factory", "m.M"}}));
  EXPECT_THAT(ErrorOf([] { MonitorSpecFromJson(json{{"type", "python"}}, "/monitor", Context()); }).what(),
              HasSubstr("c.json: /monitor/class: a Python monitor names its class by import path"));
  EXPECT_THAT(ErrorOf([] { MonitorSpecFromJson(json{{"type", "python"}, {"factory", "m.M"}, {"x", 1}}, "/monitor",
                                               Context()); })
                  .what(),
              HasSubstr("/monitor/x"));
  MonitorContext context;
  context.input = Context();
  context.robot = RobotPreset("mrr-config1");
  const InputError e = ErrorOf([&] { MakeMonitorModel(spec, context, "/monitor"); });
  EXPECT_THAT(e.what(), HasSubstr("c.json: /monitor/factory: a Python monitor passed to run_campaign (factory \"m.M\") "
                                  "cannot be rebuilt"));
}

TEST(MonitorRegistry, APythonMonitorNamedByClassIsCheckedAndRunsWherePythonIsHosted) {
  // The import path and settings, resolved with settings defaulting to {}.
  const MonitorSpec spec =
      MonitorSpecFromJson(json{{"type", "python"}, {"class", "pkg.mod:Outer.Mine"}}, "/monitor", Context());
  EXPECT_EQ(spec.ToJson(),
            (json{{"type", "python"}, {"class", "pkg.mod:Outer.Mine"}, {"settings", json::object()}}));
  EXPECT_EQ(MonitorSpecFromJson(json{{"type", "python"}, {"class", "m:M"}, {"settings", {{"k", 1}}}}, "/monitor",
                                Context())
                .settings["settings"],
            (json{{"k", 1}}));
  for (const char* bad : {"m.M", "m:", ":M", "m:M:N", "m/x.py:M", "1m:M", "m:M.", "m..n:M", "m:M()"}) {
    const InputError e = ErrorOf([&] { MonitorSpecFromJson(json{{"type", "python"}, {"class", bad}}, "/monitor", Context()); });
    EXPECT_EQ(e.pointer(), "/monitor/class") << bad;
    EXPECT_THAT(e.message(), HasSubstr(std::string("got \"") + bad + "\"")) << bad;
  }
  EXPECT_EQ(ErrorOf([] {
              MonitorSpecFromJson(json{{"type", "python"}, {"class", "m:M"}, {"settings", 3}}, "/monitor", Context());
            }).pointer(),
            "/monitor/settings");
  EXPECT_EQ(ErrorOf([] {
              MonitorSpecFromJson(json{{"type", "python"}, {"class", "m:M"}, {"factory", "m.M"}}, "/monitor", Context());
            }).pointer(),
            "/monitor/factory");
  // The armfault binary hosts no Python: the error names the value and the command that runs it.
  MonitorContext context;
  context.input = Context();
  context.robot = RobotPreset("mrr-config1");
  const InputError e = ErrorOf([&] { MakeMonitorModel(spec, context, "/monitor"); });
  EXPECT_EQ(e.pointer(), "/monitor/class");
  EXPECT_THAT(e.what(), HasSubstr("\"pkg.mod:Outer.Mine\" runs where Python is hosted"));
  EXPECT_THAT(e.what(), HasSubstr("python3 -m armfault"));
  EXPECT_TRUE(MonitorRunsUserCode("python"));
}

TEST(MonitorRegistry, SettingsErrorsKeepTheirPointersAndAFileNamesItself) {
  const InputError e =
      ErrorOf([] { MonitorSpecFromJson(json{{"type", "power_efficiency"}, {"debounce", "x"}}, "/monitor", Context()); });
  EXPECT_EQ(e.pointer(), "/monitor/debounce");
  ScratchDir dir("registry");
  dir.Write("m.json", R"({"type": "power_efficiency", "significance": -1})");
  InputContext context = Context((dir.path() / "c.json").string());
  context.base_dir = dir.path().string();
  const InputError f = ErrorOf([&] { MonitorSpecFromJson(json("m.json"), "/monitor", context); });
  EXPECT_EQ(f.source(), (dir.path() / "m.json").string());
  EXPECT_EQ(f.pointer(), "/significance");
}

TEST(MonitorRegistry, BuildsThePowerEfficiencyMonitorForTheNominalRobot) {
  MonitorContext context;
  context.robot = RobotPreset("mrr-config1");
  const auto model = MakeMonitorModel(MonitorSpecFromJson(json::object(), "/monitor", Context()), context);
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->type(), "power_efficiency");
  const std::unique_ptr<HealthMonitor> monitor = model->NewMonitor();
  EXPECT_NE(monitor->NewDecisionTap(1.0), nullptr);  // it publishes its statistics
  std::vector<std::string> types;
  for (const MonitorTypeInfo& t : MonitorTypes()) types.push_back(t.type);
  EXPECT_THAT(types, testing::Contains("power_efficiency"));
}

Verdict Alarm(double t_s, int joint, const std::string& family, double magnitude = 0.8) {
  Verdict v;
  v.t_s = t_s;
  v.joint = joint;
  v.state = HealthState::kWorn;
  v.alarm = true;
  v.family = family;
  v.magnitude_name = "kt_factor";
  v.magnitude = magnitude;
  v.confidence = 0.9;
  return v;
}

Verdict Healthy(double t_s, int joint) {
  Verdict v;
  v.t_s = t_s;
  v.joint = joint;
  return v;
}

TEST(ScoreVerdicts, AlarmsBeforeTheOnsetAreFalseAlarmsTheFirstAfterItDetects) {
  MonitorOutput out;
  out.verdicts = {Alarm(0.5, 1, "friction_increase"), Healthy(0.8, 1), Alarm(2.5, 3, "kt_degradation", 0.8),
                  Alarm(2.6, 2, "friction_increase"), Alarm(3.5, 3, "kt_degradation", 0.7)};
  const RunScore s = ScoreVerdicts(out, 2.0, 2.0);
  EXPECT_TRUE(s.alarm_before_onset);
  EXPECT_TRUE(s.detected);
  EXPECT_EQ(s.detection_time_s, 2.5);
  EXPECT_EQ(s.joint, 3);
  EXPECT_EQ(s.family, "kt_degradation");
  ASSERT_TRUE(s.magnitude.has_value());
  EXPECT_EQ(*s.magnitude, 0.7);  // the latest alarm verdict of that joint and family
}

TEST(ScoreVerdicts, AnAlarmStandingAtTheOnsetCountsAtTheFirstTick) {
  MonitorOutput out;
  out.verdicts = {Alarm(0.5, 2, "friction_increase"), Alarm(3.0, 1, "kt_degradation")};
  const RunScore s = ScoreVerdicts(out, 2.0, 2.002);
  EXPECT_TRUE(s.alarm_before_onset);
  EXPECT_TRUE(s.detected);
  EXPECT_EQ(s.detection_time_s, 2.002);
  EXPECT_EQ(s.joint, 2);
  // Cleared before the onset: nothing stands.
  out.verdicts = {Alarm(0.5, 2, "friction_increase"), Healthy(1.0, 2)};
  EXPECT_FALSE(ScoreVerdicts(out, 2.0, 2.002).detected);
  // A healthy run (onset 0): any alarm is the detection, which scoring counts as a false alarm.
  out.verdicts = {Alarm(0.5, 2, "friction_increase")};
  const RunScore h = ScoreVerdicts(out, 0.0, 0.0);
  EXPECT_TRUE(h.detected);
  EXPECT_FALSE(h.alarm_before_onset);
}

TEST(CheckOutput, GarbageVerdictsAreNamed) {
  const std::vector<std::string> families = {"kt_degradation", "friction_increase"};
  MonitorOutput out;
  out.verdicts = {Alarm(1.0, 1, "kt_degradation"), Healthy(1.5, 3)};
  EXPECT_EQ(CheckOutput(out, 3, 10.0, families), "");
  out.verdicts = {Alarm(1.0, 0, "kt_degradation")};
  EXPECT_THAT(CheckOutput(out, 3, 10.0, families), HasSubstr("verdict 1 (t_s 1, joint 0): joint 0 out of range, expected 1..3"));
  out.verdicts = {Alarm(1.0, 1, "kt_degradation", std::numeric_limits<double>::quiet_NaN())};
  EXPECT_THAT(CheckOutput(out, 3, 10.0, families), HasSubstr("magnitude is not a finite number"));
  out.verdicts = {Alarm(2.0, 1, "kt_degradation"), Alarm(1.0, 2, "kt_degradation")};
  EXPECT_THAT(CheckOutput(out, 3, 10.0, families), HasSubstr("verdict 2 (t_s 1, joint 2): time goes backwards"));
  out.verdicts = {Alarm(11.0, 1, "kt_degradation")};
  EXPECT_THAT(CheckOutput(out, 3, 10.0, families), HasSubstr("t_s 11 outside the run [0, 10] s"));
  out.verdicts = {Alarm(1.0, 1, "gremlins")};
  EXPECT_THAT(CheckOutput(out, 3, 10.0, families), HasSubstr("unknown fault family \"gremlins\""));
  out.verdicts = {Alarm(1.0, 1, "unknown")};
  EXPECT_EQ(CheckOutput(out, 3, 10.0, families), "");
  Verdict odd = Alarm(1.0, 1, "kt_degradation");
  odd.confidence = 2;
  out.verdicts = {odd};
  EXPECT_THAT(CheckOutput(out, 3, 10.0, families), HasSubstr("confidence 2 outside [0, 1]"));
}

TEST(ExplainFromVerdicts, SaysWhatWasNamedInstead) {
  RunScore s;
  EXPECT_THAT(ExplainFromVerdicts(s, "kt_degradation", 3), HasSubstr("no alarm"));
  s.detected = true;
  s.joint = 3;
  s.family = "friction_increase";
  s.detection_time_s = 2.5;
  EXPECT_EQ(ExplainFromVerdicts(s, "kt_degradation", 3), "named friction_increase on joint 3 at 2.5 s instead");
  EXPECT_EQ(ExplainFromVerdicts(s, "friction_increase", 3), "");
  EXPECT_THAT(ExplainFromVerdicts(s, "friction_increase", 2), HasSubstr("wrong joint"));
  EXPECT_THAT(ExplainFromVerdicts(s, "", 0), HasSubstr("false alarm"));
}

}  // namespace
}  // namespace armfault
