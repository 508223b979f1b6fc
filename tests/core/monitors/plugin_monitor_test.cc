// The "plugin" monitor type: a C plugin (include/armfault/monitor_plugin.h) loaded from a campaign,
// scored like any monitor; a library that does not load is an InputError naming the file, the
// pointer and the library; a plugin that returns errors or garbage fails its run with the reason
// while the campaign goes on. The plugins are built by tests/CMakeLists.txt (paths below).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <fstream>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/running/run_pipeline.h"
#include "campaigns/running/runner.h"
#include "campaigns/tuning/tuning.h"
#include "core/monitors/plugin_monitor.h"
#include "core/monitors/threshold_statistics.h"
#include "core/monitors/registry.h"
#include "core/plant/simulation.h"
#include "armfault/monitor_settings.h"  // C++ includes the C helper too
#include "tests/core/test_support.h"

namespace armfault {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::ScratchDir;

const char* const kExample = ARMFAULT_EXAMPLE_PLUGIN;
const char* const kTest = ARMFAULT_TEST_PLUGIN;
const char* const kTestAbi2 = ARMFAULT_TEST_PLUGIN_ABI2;
const char* const kTestNoFinish = ARMFAULT_TEST_PLUGIN_NOFINISH;
const char* const kTestV2 = ARMFAULT_TEST_PLUGIN_V2;
const char* const kTestV2Only = ARMFAULT_TEST_PLUGIN_V2ONLY;
const char* const kTestNoCreate = ARMFAULT_TEST_PLUGIN_NOCREATE;

// Two trajectories, as the runner's own monitor tests: joint 3 moves in exp1 (where the test
// plugin acts), joint 2 in j2; one fault and one healthy run each.
json TwoRuns(const json& monitor, double duration_s = 2) {
  json c = json::parse(R"({
    "name": "plugin", "seed": 5,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}},
                     {"name": "j2", "joints": {"2": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1.0}}}],
    "faults": [{"family": "friction_increase", "joint": 3, "friction_factor": 2.0, "onset_s": 0.5}],
    "healthy": 1
  })");
  c["monitor"] = monitor;
  c["duration_s"] = duration_s;
  return c;
}

json TestPlugin(const std::string& mode, const char* library = kTest) {
  return {{"type", "plugin"}, {"library", library}, {"settings", {{"mode", mode}}}};
}

std::string ReadText(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(PluginMonitor, IsARegisteredType) {
  std::vector<std::string> types;
  for (const MonitorTypeInfo& t : MonitorTypes()) types.push_back(t.type);
  EXPECT_THAT(types, testing::Contains("plugin"));
}

TEST(PluginMonitor, LibraryResolvesAgainstTheCampaignsDirectoryAndIsRecordedAbsolute) {
  ScratchDir dir("plugin_relative");
  fs::create_directories(dir.path() / "lib");
  fs::copy_file(kTest, dir.path() / "lib" / "libtest.so");
  const std::string path = dir.Write("c.json", TwoRuns({{"type", "plugin"}, {"library", "lib/libtest.so"}}).dump());
  const Campaign c = ReadCampaignFile(path);
  ASSERT_NE(c.monitor_model, nullptr);
  EXPECT_EQ(c.monitor_model->type(), "plugin");
  const std::string absolute = (dir.path() / "lib" / "libtest.so").string();
  EXPECT_EQ(c.resolved["monitor"], (json{{"type", "plugin"}, {"library", absolute}, {"settings", json::object()}}));
  // campaign.json read again from elsewhere (merge, tune, report) loads the same library.
  const Campaign again = CampaignFromJson(c.resolved, "out/campaign.json", "out");
  EXPECT_EQ(again.resolved["monitor"], c.resolved["monitor"]);
  // A monitor file names the library relative to itself.
  fs::create_directories(dir.path() / "monitors");
  dir.Write("monitors/m.json", json{{"type", "plugin"}, {"library", "../lib/libtest.so"}}.dump());
  const Campaign via_file = ReadCampaignFile(dir.Write("d.json", TwoRuns("monitors/m.json").dump()));
  EXPECT_EQ(via_file.resolved["monitor"]["library"], absolute);
}

TEST(PluginMonitor, SettingsErrorsNameTheFileThePointerAndTheValue) {
  ScratchDir dir("plugin_settings");
  const std::string campaign = (dir.path() / "c.json").string();
  auto load = [&](const json& monitor) { return ReadCampaignFile(dir.Write("c.json", TwoRuns(monitor).dump())); };

  const InputError missing = ErrorOf([&] { load({{"type", "plugin"}, {"library", "nowhere/libx.so"}}); });
  EXPECT_EQ(missing.source(), campaign);
  EXPECT_EQ(missing.pointer(), "/monitor/library");
  EXPECT_THAT(missing.message(), HasSubstr("plugin library \"" + (dir.path() / "nowhere/libx.so").string() +
                                           "\" (resolved from \"nowhere/libx.so\") does not exist"));
  const InputError unknown = ErrorOf([&] { load({{"type", "plugin"}, {"library", kTest}, {"setings", json::object()}}); });
  EXPECT_EQ(unknown.pointer(), "/monitor/setings");
  EXPECT_THAT(unknown.hint(), HasSubstr("settings"));
  const InputError no_library = ErrorOf([&] { load({{"type", "plugin"}}); });
  EXPECT_EQ(no_library.pointer(), "/monitor/library");
  const InputError not_object = ErrorOf([&] { load({{"type", "plugin"}, {"library", kTest}, {"settings", 3}}); });
  EXPECT_EQ(not_object.pointer(), "/monitor/settings");
  EXPECT_THAT(not_object.message(), HasSubstr("got 3"));
  const InputError directory = ErrorOf([&] { load({{"type", "plugin"}, {"library", "."}}); });
  EXPECT_THAT(directory.message(), HasSubstr("is a directory"));
}

TEST(PluginMonitor, ALibraryThatDoesNotLoadIsAnInputErrorNamingIt) {
  ScratchDir dir("plugin_load");
  const std::string campaign = (dir.path() / "c.json").string();
  auto error_of = [&](const json& monitor) {
    return ErrorOf([&] { ReadCampaignFile(dir.Write("c.json", TwoRuns(monitor).dump())); });
  };
  const std::string text = dir.Write("libtext.so", "not a library\n");
  const InputError not_elf = error_of({{"type", "plugin"}, {"library", "libtext.so"}});
  EXPECT_EQ(not_elf.source(), campaign);
  EXPECT_EQ(not_elf.pointer(), "/monitor/library");
  EXPECT_THAT(not_elf.message(), HasSubstr("plugin library \"" + text + "\" cannot be loaded: "));

  const InputError symbol = error_of(TestPlugin("quiet", kTestNoFinish));
  EXPECT_EQ(symbol.source(), campaign);
  EXPECT_EQ(symbol.pointer(), "/monitor/library");
  EXPECT_THAT(symbol.message(), HasSubstr(std::string("plugin library \"") + kTestNoFinish + "\""));
  EXPECT_THAT(symbol.message(), HasSubstr("does not export armfault_monitor_finish"));

  const InputError abi = error_of(TestPlugin("quiet", kTestAbi2));
  EXPECT_EQ(abi.pointer(), "/monitor/library");
  EXPECT_THAT(abi.message(), HasSubstr(kTestAbi2));
  EXPECT_THAT(abi.message(), HasSubstr("built for monitor plugin ABI version 2, this armfault loads version 1"));

  const InputError create = error_of(TestPlugin("create_error"));
  EXPECT_EQ(create.pointer(), "/monitor/library");
  EXPECT_THAT(create.message(), HasSubstr(kTest));
  EXPECT_THAT(create.message(), HasSubstr("armfault_monitor_create returned NULL for the settings {\"mode\":\"create_error\"}: "
                                          "settings rejected: mode create_error"));
  // The example checks its own settings.
  const InputError example = error_of({{"type", "plugin"}, {"library", kExample}, {"settings", {{"kt_wron", 0.8}}}});
  EXPECT_THAT(example.message(), HasSubstr("unknown setting \"kt_wron\""));
}

TEST(PluginMonitor, ScoredFromItsVerdictsLikeAnyMonitor) {
  const Campaign c = CampaignFromJson(TwoRuns(TestPlugin("alarm")), "c.json", ".");
  const std::vector<CaseSpec> cases = ExpandCases(c);
  const RunRecord faulty = RunCase(c, cases[0]);
  ASSERT_TRUE(faulty.ok) << faulty.failure_reason;
  EXPECT_TRUE(faulty.detected);
  EXPECT_EQ(faulty.isolated_family, "friction_increase");
  EXPECT_EQ(faulty.isolated_joint, 3);
  EXPECT_EQ(faulty.magnitude_name, "friction_factor");
  EXPECT_EQ(*faulty.magnitude_estimate, 2.0);
  EXPECT_NEAR(*faulty.latency_s, 0.5, 1e-9);
  EXPECT_TRUE(faulty.decision.is_null());  // a plugin publishes no statistics
  const RunRecord quiet_joint = RunCase(c, cases[3]);  // j2, healthy: joint 3 never moves
  ASSERT_TRUE(quiet_joint.ok) << quiet_joint.failure_reason;
  EXPECT_FALSE(quiet_joint.detected);
}

TEST(PluginMonitor, ErrorsAndGarbageFailTheRunWithTheReasonAndTheCampaignGoesOn) {
  const std::vector<std::pair<std::string, std::string>> garbage = {
      {"joint0", std::string("monitor plugin ") + kTest +
                     " emitted a bad verdict: verdict 1 (t_s 1, joint 0): joint 0 out of range, expected 1..3"},
      {"nan", "magnitude is not a finite number"},
      {"backwards", "time goes backwards"},
      {"bad_state", ": verdict 1: state 7, expected 0 (healthy), 1 (worn) or 2 (defective)"},
      {"unterminated", ": verdict 1: family is not NUL-terminated"},
      {"step_error", std::string("monitor plugin failed: ") + kTest + ": step returned error: sensor model diverged at t = 1 s"},
      {"finish_error", std::string("monitor plugin failed: ") + kTest + ": finish returned error: cannot finish at 2 s"}};
  for (const auto& [mode, message] : garbage) {
    const Campaign c = CampaignFromJson(TwoRuns(TestPlugin(mode)), "c.json", ".");
    ScratchDir dir("plugin_garbage_" + mode);
    RunnerOptions o;
    o.output_dir = dir.path().string();
    o.threads = 2;
    const RunnerResult r = RunCampaign(c, o);
    EXPECT_EQ(r.ran, 4) << mode;
    // finish fails on every run; the others only where joint 3 moves (exp1).
    EXPECT_EQ(r.failed, mode == "finish_error" ? 4 : 2) << mode;
    std::istringstream lines(ReadText(dir.path() / "results.jsonl"));
    std::string line;
    int failed = 0;
    while (std::getline(lines, line)) {
      const json record = json::parse(line);
      if (record["status"] != "failed") continue;
      ++failed;
      EXPECT_THAT(record["reason"].get<std::string>(), HasSubstr(message)) << mode;
      // Every monitor error names its source: the library.
      EXPECT_THAT(record["reason"].get<std::string>(), HasSubstr(kTest)) << mode;
    }
    EXPECT_EQ(failed, r.failed) << mode;
  }
}

TEST(PluginMonitor, TheExampleDetectsKtAndFrictionOnTheMovingJointAndIsQuietWhenHealthy) {
  json campaign = json::parse(R"({
    "name": "example", "seed": 11, "duration_s": 7,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": 0.5, "onset_s": 2.0},
               {"family": "friction_increase", "joint": 3, "friction_factor": 3.0, "onset_s": 2.0}],
    "healthy": 2
  })");
  campaign["monitor"] = {{"type", "plugin"}, {"library", kExample}};
  const Campaign c = CampaignFromJson(campaign, "c.json", ".");
  std::vector<std::string> lines[2];
  for (int threads : {1, 2}) {
    ScratchDir dir("plugin_example_" + std::to_string(threads));
    RunnerOptions o;
    o.output_dir = dir.path().string();
    o.threads = threads;
    const RunnerResult r = RunCampaign(c, o);
    EXPECT_EQ(r.failed, 0);
    std::istringstream text(ReadText(dir.path() / "results.jsonl"));
    for (std::string line; std::getline(text, line);) lines[threads - 1].push_back(line);
  }
  EXPECT_EQ(lines[0], lines[1]);  // the same bytes for any thread count
  ASSERT_EQ(lines[0].size(), 4u);
  const json kt = json::parse(lines[0][0]), friction = json::parse(lines[0][1]);
  EXPECT_EQ(kt["isolated_family"], "kt_degradation");
  EXPECT_EQ(kt["isolated_joint"], 3);
  EXPECT_NEAR(kt["magnitude_estimate"].get<double>(), 0.5, 0.1);
  EXPECT_EQ(friction["isolated_family"], "friction_increase");
  EXPECT_EQ(friction["isolated_joint"], 3);
  EXPECT_NEAR(friction["magnitude_estimate"].get<double>(), 3.0, 0.6);
  for (int k : {2, 3}) EXPECT_EQ(json::parse(lines[0][k])["detected"], false) << lines[0][k];
}

// Statistics for tune (docs/monitor-api.md): a plugin that publishes them and keeps the threshold
// contract is swept by tune, which writes the tuned threshold into its settings; one whose
// statistics do not give its alarms is refused with the run named; bad declarations are load
// errors; a plugin that publishes none cannot be swept, and tune says so.
TEST(PluginMonitor, PublishedStatisticsAreSweptByTune) {
  ScratchDir dir("plugin_statistics");
  RunnerOptions o;
  o.output_dir = dir.path().string();
  o.threads = 2;
  RunCampaign(CampaignFromJson(TwoRuns(TestPlugin("stats_true")), "c.json", "."), o);
  const std::string decisions = ReadText(dir.path() / "decisions.jsonl");
  EXPECT_THAT(decisions, HasSubstr(R"("kind":"threshold_statistics")"));
  TuneOptions tune;
  tune.sweep = "alarmed=0.26:1.9:2";
  const TuningResult t = TuneCampaignDir(o.output_dir, tune);
  EXPECT_EQ(t.report["parameters"][0]["name"], "alarmed");
  // The values asked for, each moved to the nearest stored level, and the threshold as run.
  std::vector<double> values;
  for (int k : {-15, 0, 31}) values.push_back(LevelThreshold(0.5, k));
  EXPECT_EQ(t.report["parameters"][0]["values"], json(values));
  // As run: the fault on joint 3 found at 1 s where joint 3 moves (exp1, not j2); the healthy
  // exp1 run alarms as well.
  EXPECT_EQ(t.report["default_point"]["detection_rate"]["count"], 1);
  EXPECT_EQ(t.report["default_point"]["false_alarm_rate"]["count"], 1);
  // Above 1 nothing alarms: the rule's operating point (false alarms <= 1 %).
  EXPECT_EQ(t.report["operating_point"]["setting"]["alarmed"], LevelThreshold(0.5, 31));
  EXPECT_EQ(t.report["operating_point"]["false_alarm_rate"]["count"], 0);
  EXPECT_EQ(t.tuned_monitor["type"], "plugin");
  EXPECT_EQ(t.tuned_monitor["settings"]["mode"], "stats_true");
  // The statistic names no setting: tune says so instead of writing it.
  EXPECT_THAT(t.report["warnings"][0].get<std::string>(), HasSubstr("statistic alarmed names no setting"));

  tune.sweep = "alarmed=9";
  EXPECT_THAT(ErrorOf([&] { TuneCampaignDir(o.output_dir, tune); }).what(),
              HasSubstr("alarmed: 9 is outside the range the runs stored, 0.125 to 2"));
  tune.sweep = "nope=1";
  EXPECT_THAT(ErrorOf([&] { TuneCampaignDir(o.output_dir, tune); }).what(),
              HasSubstr("with NAME a statistic the monitor publishes (alarmed)"));
}

TEST(PluginMonitor, TuneRefusesStatisticsThatDoNotGiveTheAlarms) {
  ScratchDir dir("plugin_statistics_lie");
  RunnerOptions o;
  o.output_dir = dir.path().string();
  RunCampaign(CampaignFromJson(TwoRuns(TestPlugin("stats_lie")), "c.json", "."), o);
  EXPECT_THAT(ErrorOf([&] { TuneCampaignDir(o.output_dir, TuneOptions()); }).what(),
              HasSubstr("results.jsonl: line 1: run exp1/friction_increase#0/-/j3/r0: its decision statistics do not "
                        "reproduce its result (the monitor's alarms are not the threshold test"));

  ScratchDir quiet("plugin_statistics_none");
  o.output_dir = quiet.path().string();
  RunCampaign(CampaignFromJson(TwoRuns(TestPlugin("alarm")), "c.json", "."), o);
  const InputError e = ErrorOf([&] { TuneCampaignDir(o.output_dir, TuneOptions()); });
  EXPECT_EQ(e.pointer(), "/campaign/monitor/type");
  EXPECT_THAT(e.what(), HasSubstr("monitor type \"plugin\" publishes no statistics tune can re-score"));

  EXPECT_THAT(ErrorOf([&] { CampaignFromJson(TwoRuns(TestPlugin("stats_zero")), "c.json", "."); }).what(),
              HasSubstr("c.json: /monitor/library: plugin library \"" + std::string(kTest) +
                        "\": statistic 1 (\"alarmed\"): threshold 0 is not a number > 0"));
}

// ABI minor 1: a plugin exporting armfault_monitor_create_v2 is told the control period and the
// joint count (and armfault prefers it to create); one exporting only it loads; an old plugin
// (create alone) loads and runs unchanged; one with neither create is refused naming both.
TEST(PluginMonitor, CreateV2GetsTheControlPeriodAndTheJointCount) {
  // The verdict "context" emits at its first tick: joint = joint count, magnitude = dt_s.
  auto context_of = [](const char* library) {
    const Campaign c = CampaignFromJson(TwoRuns(TestPlugin("context", library)), "c.json", ".");
    std::unique_ptr<HealthMonitor> monitor = c.monitor_model->NewMonitor();
    std::vector<JointSignals> ticks(3);
    monitor->Observe(0.0, ticks);
    monitor->Finish(0.0);
    EXPECT_EQ(monitor->output().verdicts.size(), 1u) << library;
    return monitor->output().verdicts.empty() ? Verdict{} : monitor->output().verdicts[0];
  };
  const double dt_s = ArmModel(CampaignFromJson(TwoRuns(json::object()), "c.json", ".").robot).control_dt_s();
  ASSERT_GT(dt_s, 0);
  for (const char* library : {kTestV2, kTestV2Only}) {
    const Verdict v = context_of(library);
    EXPECT_EQ(v.magnitude_name, "dt_s") << library;
    EXPECT_EQ(v.magnitude, dt_s) << library;  // exactly: the ticks are k * dt_s
    EXPECT_EQ(v.joint, 3) << library;
  }
  const Verdict old = context_of(kTest);  // create alone: as before minor 1
  EXPECT_EQ(old.magnitude, -1);
  EXPECT_EQ(old.joint, 0);

  // A whole run of a create_v2-only plugin, scored as any other.
  const Campaign c = CampaignFromJson(TwoRuns(TestPlugin("alarm", kTestV2Only)), "c.json", ".");
  const RunRecord faulty = RunCase(c, ExpandCases(c)[0]);
  ASSERT_TRUE(faulty.ok) << faulty.failure_reason;
  EXPECT_EQ(faulty.isolated_family, "friction_increase");

  ScratchDir dir("plugin_v2");
  const std::string campaign = (dir.path() / "c.json").string();
  auto error_of = [&](const json& monitor) {
    return ErrorOf([&] { ReadCampaignFile(dir.Write("c.json", TwoRuns(monitor).dump())); });
  };
  const InputError none = error_of(TestPlugin("quiet", kTestNoCreate));
  EXPECT_EQ(none.pointer(), "/monitor/library");
  EXPECT_THAT(none.message(), HasSubstr("does not export armfault_monitor_create (or armfault_monitor_create_v2) "
                                        "(include/armfault/monitor_plugin.h, ABI version 1.1)"));
  // create_v2's refusal is named as create_v2's (here: the settings helper's message).
  const InputError refused = error_of({{"type", "plugin"}, {"library", kTestV2Only}, {"settings", {{"mode", 3}}}});
  EXPECT_THAT(refused.message(), HasSubstr("armfault_monitor_create_v2 returned NULL for the settings {\"mode\":3}: "
                                           "setting \"mode\": expected a string, got a number"));
  const InputError unknown = error_of({{"type", "plugin"}, {"library", kTestV2Only}, {"settings", {{"mdoe", "x"}}}});
  EXPECT_THAT(unknown.message(), HasSubstr("unknown setting \"mdoe\" (known: mode)"));
}

// The settings helper is C++ too (a C++ plugin includes it); tests/core/monitors/
// settings_helper_test.c tests it in C.
TEST(PluginMonitor, TheSettingsHelperCompilesAsCpp) {
  char error[128] = "";
  double x = 0;
  EXPECT_EQ(armfault_setting_number(R"({"kt_worn":0.8})", "kt_worn", &x, error, sizeof error), ARMFAULT_SETTING_FOUND);
  EXPECT_EQ(x, 0.8);
}

// Commissioning (ABI minor 1): each unit's commissioning run is streamed to the plugin once; the
// blob its commission_end returns is kept per unit and every run of that unit gets it at
// create_v2; without commissioning no blob; a failing commission_tick fails the unit's runs
// naming the library and the message.
TEST(PluginMonitor, CommissioningStreamsEachUnitAndEveryRunOfItGetsItsBlob) {
  json campaign = TwoRuns(TestPlugin("commissioned", kTestV2Only));
  campaign["healthy"] = 3;
  campaign["variation"] = {{"tolerances", "datasheet"}, {"units", 2}};
  const Campaign c = CampaignFromJson(campaign, "c.json", ".");
  ASSERT_TRUE(c.commissioning);
  const double dt_s = ArmModel(c.robot).control_dt_s();
  const double ticks = static_cast<double>(std::lround(16.0 / dt_s) + 1);  // 16 s, both ends
  UnitMonitors units(c);
  std::map<int, double> mean_by_unit;
  for (const CaseSpec& spec : ExpandCases(c)) {
    MonitorOutput out;
    const RunRecord r = RunCase(c, spec, nullptr, &units, &out);
    ASSERT_TRUE(r.ok) << r.failure_reason;
    ASSERT_EQ(out.verdicts.size(), 2u);
    EXPECT_EQ(out.verdicts[0].magnitude, ticks);
    const double mean = out.verdicts[1].magnitude;
    EXPECT_GT(mean, 0);
    const auto [it, first] = mean_by_unit.emplace(spec.unit, mean);
    if (!first) {
      EXPECT_EQ(it->second, mean) << "unit " << spec.unit;  // the unit's one blob
    }
  }
  ASSERT_EQ(mean_by_unit.size(), 2u);
  EXPECT_NE(mean_by_unit.begin()->second, mean_by_unit.rbegin()->second);  // each unit its own run

  // A monitor that learns from commissioning is not warned about; one that does not is, once.
  auto commissioning_warnings = [](const Campaign& c) {
    int n = 0;
    for (const std::string& w : CampaignWarnings(c)) n += w.find("learns nothing from commissioning") != std::string::npos;
    return n;
  };
  EXPECT_EQ(commissioning_warnings(c), 0);
  json old_plugin = campaign;
  old_plugin["monitor"] = TestPlugin("quiet", kTest);
  const Campaign ignores = CampaignFromJson(old_plugin, "c.json", ".");
  EXPECT_EQ(commissioning_warnings(ignores), 1);
  EXPECT_THAT(CampaignWarnings(ignores).front(),
              HasSubstr("/commissioning: monitor plugin (" + std::string(kTest) + ") learns nothing from commissioning"));

  campaign["commissioning"] = false;
  const Campaign off = CampaignFromJson(campaign, "c.json", ".");
  EXPECT_EQ(commissioning_warnings(off), 0);
  MonitorOutput out;
  ASSERT_TRUE(RunCase(off, ExpandCases(off)[0], nullptr, nullptr, &out).ok);
  ASSERT_EQ(out.verdicts.size(), 2u);
  EXPECT_EQ(out.verdicts[0].magnitude, -1);

  campaign["commissioning"] = true;
  campaign["monitor"] = TestPlugin("commission_error", kTestV2Only);
  const Campaign failing = CampaignFromJson(campaign, "c.json", ".");
  const RunRecord r = RunCase(failing, ExpandCases(failing)[0]);
  EXPECT_FALSE(r.ok);
  EXPECT_THAT(r.failure_reason, HasSubstr(std::string(kTestV2Only) +
                                          ": commission_tick returned error at t_s 1: commissioning diverged at t = 1 s"));
}

// The example plugin learns each unit: its blob holds, per joint, the unit's own 1/a and c/a
// near the datasheet's 1 for the moving joint, and the scatter of its healthy windowed fit;
// a run of the commissioned unit with a strong friction fault still detects and names it.
TEST(PluginMonitor, TheExampleLearnsItsUnitByCommissioning) {
  json campaign = TwoRuns({{"type", "plugin"}, {"library", kExample}}, 6);
  campaign["variation"] = {{"tolerances", "datasheet"}, {"units", 1}};
  const Campaign c = CampaignFromJson(campaign, "c.json", ".");
  ASSERT_TRUE(c.commissioning);
  EXPECT_TRUE(c.monitor_model->LearnsFromCommissioning());
  const std::vector<CaseSpec> cases = ExpandCases(c);
  const UnitMonitor unit = CommissionUnit(c, cases[0]);
  ASSERT_TRUE(unit.failure.empty()) << unit.failure;
  const auto& model = dynamic_cast<const PluginMonitorModel&>(*unit.model);
  ASSERT_NE(model.commissioning(), nullptr);
  ASSERT_EQ(model.commissioning()->size(), 4 * 3 * sizeof(double));
  double learned[12];
  std::memcpy(learned, model.commissioning()->data(), sizeof learned);
  EXPECT_NEAR(learned[8], 1.0, 0.25);   // joint 3: 1/a, the unit's K_T against the datasheet's
  EXPECT_NEAR(learned[9], 1.0, 0.6);    // c/a, its friction
  EXPECT_LE(learned[10], 1.0 + 1e-12);  // the lowest windowed 1/a, relative
  EXPECT_GE(learned[11], 1.0 - 1e-12);  // the highest windowed c/a, relative
  UnitMonitors units(c);
  const RunRecord faulty = RunCase(c, cases[0], nullptr, &units);  // friction x2 on joint 3
  ASSERT_TRUE(faulty.ok) << faulty.failure_reason;
  EXPECT_TRUE(faulty.detected);
  EXPECT_EQ(faulty.isolated_family, "friction_increase");
  EXPECT_EQ(faulty.isolated_joint, 3);
}

}  // namespace
}  // namespace armfault
