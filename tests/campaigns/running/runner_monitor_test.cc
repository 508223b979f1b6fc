// The runner with a monitor other than the built-in one: scored from its verdicts alone, and a
// monitor that breaks the contract fails its run with a reason while the campaign goes on.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/runner.h"
#include "campaigns/scoring/run_record.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;

// Alarms "friction_increase" on joint 3 at a fixed time; or, when `garbage` says so and joint
// 3's reference moves, emits a verdict that breaks the contract in that way.
class ScriptedMonitor : public HealthMonitor {
 public:
  ScriptedMonitor(double alarm_at_s, std::string garbage) : alarm_at_s_(alarm_at_s), garbage_(std::move(garbage)) {}
  void Observe(double t_s, const std::vector<JointSignals>& joints) override {
    if (joints[2].qd_ref_rad_s != 0) moving_ = true;
    if (emitted_ || t_s < alarm_at_s_) return;
    if (!garbage_.empty() && !moving_) return;
    emitted_ = true;
    Verdict v;
    v.t_s = t_s;
    v.joint = 3;
    v.state = HealthState::kWorn;
    v.alarm = true;
    v.family = "friction_increase";
    if (garbage_ == "joint0") v.joint = 0;
    if (garbage_ == "nan") v.magnitude = std::numeric_limits<double>::quiet_NaN();
    if (garbage_ == "backwards") {
      Verdict early = v;
      early.t_s = t_s / 2;
      output_.verdicts.push_back(v);
      v = early;
    }
    if (garbage_ == "throw") throw MonitorFailure("step returned error -3: out of memory");
    output_.verdicts.push_back(v);
  }
  void Finish(double) override {}
  const MonitorOutput& output() const override { return output_; }

 private:
  double alarm_at_s_;
  std::string garbage_;
  bool emitted_ = false;
  bool moving_ = false;
  MonitorOutput output_;
};

class ScriptedModel : public MonitorModel {
 public:
  ScriptedModel(double alarm_at_s, std::string garbage) : alarm_at_s_(alarm_at_s), garbage_(std::move(garbage)) {}
  std::string type() const override { return "scripted"; }
  std::unique_ptr<HealthMonitor> NewMonitor() const override {
    return std::make_unique<ScriptedMonitor>(alarm_at_s_, garbage_);
  }

 private:
  double alarm_at_s_;
  std::string garbage_;
};

Campaign TwoRuns() {
  return CampaignFromJson(json::parse(R"({
    "name": "scripted", "seed": 5, "duration_s": 2,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}},
                     {"name": "j2", "joints": {"2": {"type": "sine_pair", "amplitude_deg": 10, "omega_rad_s": 1.0}}}],
    "faults": [{"family": "friction_increase", "joint": 3, "friction_factor": 2.0, "onset_s": 0.5}],
    "healthy": 1
  })"),
                          "c.json", ".");
}

TEST(RunnerWithAnyMonitor, ScoresItsVerdictsAlone) {
  Campaign c = TwoRuns();
  c.monitor_model = std::make_shared<ScriptedModel>(1.0, "");
  const std::vector<CaseSpec> cases = ExpandCases(c);
  const RunRecord faulty = RunCase(c, cases[0]);
  ASSERT_TRUE(faulty.ok) << faulty.failure_reason;
  EXPECT_TRUE(faulty.detected);
  EXPECT_EQ(faulty.isolated_family, "friction_increase");
  EXPECT_EQ(faulty.isolated_joint, 3);
  EXPECT_NEAR(*faulty.latency_s, 0.5, 1e-9);
  EXPECT_TRUE(faulty.decision.is_null());  // it publishes no statistics
  const RunRecord healthy = RunCase(c, cases[1]);
  EXPECT_TRUE(healthy.detected);  // a false alarm
  EXPECT_THAT(healthy.miss_reason, HasSubstr("false alarm"));
  // Alarming before the onset: a false alarm that stands at the onset, then detects there.
  c.monitor_model = std::make_shared<ScriptedModel>(0.2, "");
  const RunRecord early = RunCase(c, cases[0]);
  EXPECT_TRUE(early.alarm_before_onset);
  EXPECT_TRUE(early.detected);
  EXPECT_NEAR(*early.detection_time_s, 0.5, 1e-9);
}

TEST(RunnerWithAnyMonitor, GarbageVerdictsFailTheRunAndTheCampaignGoesOn) {
  const std::vector<std::pair<std::string, std::string>> garbage = {
      {"joint0", "joint 0 out of range, expected 1..3"},
      {"nan", "magnitude is not a finite number"},
      {"backwards", "time goes backwards"},
      {"throw", "monitor scripted failed: step returned error -3: out of memory"}};
  for (const auto& [kind, message] : garbage) {
    Campaign c = TwoRuns();
    c.monitor_model = std::make_shared<ScriptedModel>(1.0, kind);
    testing_support::ScratchDir dir("garbage_" + kind);
    RunnerOptions o;
    o.output_dir = dir.path().string();
    o.threads = 2;
    const RunnerResult r = RunCampaign(c, o);
    EXPECT_EQ(r.ran, 4) << kind;
    EXPECT_EQ(r.failed, 2) << kind;  // the two runs of exp1, where joint 3 moves
    std::ifstream in(dir.path() / "results.jsonl");
    std::string line;
    int lines = 0;
    while (std::getline(in, line)) {
      const RunRecord rec = RunRecordFromJson(json::parse(line));
      ++lines;
      EXPECT_EQ(rec.ok, rec.trajectory != "exp1") << kind << " " << rec.run_id;
      if (!rec.ok) {
        EXPECT_THAT(rec.failure_reason, HasSubstr(message)) << kind;
      }
    }
    EXPECT_EQ(lines, 4) << kind;
  }
}

}  // namespace
}  // namespace armfault

namespace armfault {
namespace {

TEST(OutputLock, ASecondWriterIsToldWhoHoldsTheDirectory) {
  testing_support::ScratchDir dir("lock");
  {
    const OutputLock first(dir.path(), "armfault run first.json");
    try {
      const OutputLock second(dir.path(), "armfault run second.json");
      ADD_FAILURE() << "a second writer got the lock";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), dir.path().string());
      EXPECT_THAT(e.message(), HasSubstr("another armfault is writing here (pid "));
      EXPECT_THAT(e.message(), HasSubstr(": armfault run first.json)"));
    }
  }
  // Released with its holder, and its file gone with it.
  EXPECT_FALSE(std::filesystem::exists(dir.path() / ".armfault.lock"));
  EXPECT_NO_THROW(OutputLock(dir.path(), "armfault run third.json"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / ".armfault.lock"));
}

TEST(OutputLock, AnOutputDirectoryThatIsASymbolicLinkIsRefused) {
  testing_support::ScratchDir dir("lock_link");
  std::filesystem::create_directories(dir.path() / "real");
  std::filesystem::create_directory_symlink(dir.path() / "real", dir.path() / "link");
  const InputError e = testing_support::ErrorOf([&] { OutputLock(dir.path() / "link", "armfault run"); });
  EXPECT_EQ(e.source(), (dir.path() / "link").string());
  EXPECT_THAT(e.message(), HasSubstr("symbolic link"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "real" / ".armfault.lock"));
}

TEST(OutputDirectory, AnotherCampaignsResultsAreKeptUnlessForced) {
  testing_support::ScratchDir dir("other_results");
  const nlohmann::json mine = {{"campaign", {{"name", "mine"}, {"seed", 1}}}, {"shard", {{"index", 0}, {"count", 1}}}};
  EXPECT_NO_THROW(RequireNoOtherResults(dir.path(), mine, false));  // nothing there
  nlohmann::json theirs = mine;
  theirs["campaign"]["name"] = "theirs";
  dir.Write("campaign.json", theirs.dump());
  dir.Write("results.jsonl", "{}\n");
  const InputError e = testing_support::ErrorOf([&] { RequireNoOtherResults(dir.path(), mine, false); });
  EXPECT_EQ(e.source(), dir.path().string());
  EXPECT_THAT(e.message(), HasSubstr("holds the results of campaign \"theirs\"; they are kept"));
  EXPECT_NO_THROW(RequireNoOtherResults(dir.path(), mine, true));
  dir.Write("campaign.json", mine.dump());  // this campaign again: a rerun
  EXPECT_NO_THROW(RequireNoOtherResults(dir.path(), mine, false));
  nlohmann::json other_shard = mine;
  other_shard["shard"]["count"] = 2;
  EXPECT_THAT(testing_support::ErrorOf([&] { RequireNoOtherResults(dir.path(), other_shard, false); }).message(),
              HasSubstr("(another shard)"));
  std::filesystem::remove(dir.path() / "campaign.json");  // results without their campaign
  EXPECT_THAT(testing_support::ErrorOf([&] { RequireNoOtherResults(dir.path(), mine, false); }).message(),
              HasSubstr("results.jsonl without its campaign.json"));
}

}  // namespace
}  // namespace armfault
