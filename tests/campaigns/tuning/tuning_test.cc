// Threshold tuning: the decision rule on stored statistics, the hit/miss fit, the sweep
// spec, and the end-to-end promise: a campaign re-run with the tuned monitor gives the rates
// the tuner predicted.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "campaigns/spec/campaign.h"
#include "campaigns/scoring/campaign_summary.h"
#include "campaigns/scoring/run_record.h"
#include "campaigns/running/runner.h"
#include "campaigns/tuning/tuning.h"
#include "core/monitors/detector_statistics.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;
using testing_support::Lines;
using testing_support::ReadAll;
using testing_support::ScratchDir;

TEST(SlidingMin, IsTheMinimumOfTheLastSpanValues) {
  SlidingMin m(3);
  const std::vector<double> in = {5, 3, 4, 6, 7, 1, 2, 2, 9};
  for (size_t i = 0; i < in.size(); ++i) {
    const size_t lo = i >= 2 ? i - 2 : 0;
    const double expected = *std::min_element(in.begin() + lo, in.begin() + i + 1);
    EXPECT_EQ(m.Push(in[i]), expected) << i;
  }
}

TEST(SlidingMin, NoStatisticHoldsTheMinimumDown) {
  SlidingMin m(2);
  EXPECT_EQ(m.Push(kNoStatistic), kNoStatistic);
  EXPECT_EQ(m.Push(10), kNoStatistic);
  EXPECT_EQ(m.Push(12), 10);
}

DecisionStats Stats() {
  DecisionStats s;
  s.onset_s = 2.0;
  s.first_tick_s = 2.0;
  DecisionStats::Trace kt;
  kt.joint = 3;
  kt.detector = Detector::kKtFactor;
  kt.pre = {{20, 500}, {5, 900}};  // 0.020 at 5 standard errors, 0.005 at 9, before the onset
  kt.rise = {{2.0, {10, 500}, ""}, {2.5, {50, 500}, ""}, {3.0, {200, 350}, ""}, {3.2, {150, 600}, ""}};
  DecisionStats::Trace friction;
  friction.joint = 2;
  friction.detector = Detector::kFrictionFactor;
  friction.rise = {{2.5, {400, 500}, ""}, {4.0, {3500, 500}, "brake_lock"}};
  s.traces = {kt, friction};
  return s;
}

DetectorThresholds Thresholds(double kt, double friction) { return {kt, 10.0, friction, 10.0}; }

TEST(Decide, TheFirstRecordPastBothTheThresholdAndTheSignificanceAlarms) {
  DecisionOutcome d = Decide(Stats(), Thresholds(0.07, 10.0), 3.0);
  EXPECT_TRUE(d.detected);
  EXPECT_DOUBLE_EQ(d.detection_time_s, 3.0);  // 0.200 > 0.07 at 3.5 standard errors; 0.050 is not
  EXPECT_EQ(d.family, "kt_degradation");
  EXPECT_EQ(d.joint, 3);
  EXPECT_FALSE(d.alarm_before_onset);
  d = Decide(Stats(), Thresholds(0.07, 10.0), 4.0);  // 3.5 is not significant enough: 6.0 at 3.2 s
  EXPECT_DOUBLE_EQ(d.detection_time_s, 3.2);
  EXPECT_TRUE(Decide(Stats(), Thresholds(0.07, 10.0), 6.0).detected);  // >= z
  EXPECT_FALSE(Decide(Stats(), Thresholds(0.07, 10.0), 6.01).detected);
}

TEST(Decide, PreOnsetPairsAreFalseAlarms) {
  EXPECT_TRUE(Decide(Stats(), Thresholds(0.019, 10.0), 3.0).alarm_before_onset);
  EXPECT_FALSE(Decide(Stats(), Thresholds(0.020, 10.0), 3.0).alarm_before_onset);  // strictly above
  EXPECT_TRUE(Decide(Stats(), Thresholds(0.004, 10.0), 8.0).alarm_before_onset);   // the second pair
  EXPECT_FALSE(Decide(Stats(), Thresholds(0.019, 10.0), 5.5).alarm_before_onset);
}

TEST(DecisionRecorder, KeepsOnlyPairsNoEarlierPairDominates) {
  DecisionRecorder rec(1, 1.0);
  auto record = [&](double t, double b, double z) {
    DetectorReadings r;
    r[0] = {b, z, "kt_degradation"};
    rec.Record(t, 0, r, "");
  };
  record(0.5, 10, 100);
  record(0.6, 20, 50);
  record(0.7, 5, 50);  // dominated by both
  record(0.8, 30, 200);  // dominates both: they go
  record(1.0, 1, 1);
  record(1.1, 1, 1);  // a repeat
  record(1.2, 2, 0);
  record(1.3, 0, 2);
  record(1.4, 2, 2);
  record(1.5, 1, 2);  // dominated
  const DecisionStats& s = rec.stats();
  ASSERT_EQ(s.traces.size(), 1u);
  ASSERT_EQ(s.traces[0].pre.size(), 1u);
  EXPECT_EQ(s.traces[0].pre[0].quanta, 30);
  std::vector<double> times;
  for (const auto& r : s.traces[0].rise) times.push_back(r.t_s);
  EXPECT_THAT(times, testing::ElementsAre(1.0, 1.2, 1.3, 1.4));
  EXPECT_DOUBLE_EQ(s.first_tick_s, 1.0);
}

TEST(Decide, TiesGoToTheEarlierDetectorAndLabelsComeFromTheRise) {
  // Both detectors pass at 2.5 s: K_T comes first in the detector order.
  DecisionOutcome d = Decide(Stats(), Thresholds(0.04, 0.3), 3.0);
  EXPECT_DOUBLE_EQ(d.detection_time_s, 2.5);
  EXPECT_EQ(d.family, "kt_degradation");
  d = Decide(Stats(), Thresholds(1.0, 3.0), 3.0);
  EXPECT_DOUBLE_EQ(d.detection_time_s, 4.0);
  EXPECT_EQ(d.family, "brake_lock");
  EXPECT_EQ(d.joint, 2);
  EXPECT_FALSE(Decide(Stats(), Thresholds(1.0, 3.5), 3.0).detected);
}

TEST(Decide, ALatchedEventBeforeTheOnsetAlarmsAtTheFirstTickAfterIt) {
  DecisionStats s = Stats();
  s.first_tick_s = 2.001;
  s.events = {{1, "inverter_short", 1.0}};
  const DecisionOutcome d = Decide(s, Thresholds(1.0, 10.0), 3.0);
  EXPECT_TRUE(d.alarm_before_onset);
  EXPECT_DOUBLE_EQ(d.detection_time_s, 2.001);
  EXPECT_EQ(d.family, "inverter_short");
}

TEST(DecisionStats, JsonRoundTripIsExact) {
  const DecisionStats s = Stats();
  const DecisionStats back = DecisionStatsFromJson(json::parse(ToJson(s).dump()));
  EXPECT_EQ(ToJson(back), ToJson(s));
  json bad = ToJson(s);
  bad["traces"][0]["detector"] = "kt_factr";
  try {
    DecisionStatsFromJson(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("kt_factr"));
  }
}

TEST(FitPod, RecoversAKnownLogisticCurve) {
  // True POD: logit p = 4 + 2 log(s).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> s;
  std::vector<bool> hit;
  for (double sev : {0.02, 0.05, 0.1, 0.2, 0.4}) {
    for (int i = 0; i < 400; ++i) {
      s.push_back(sev);
      hit.push_back(u(rng) < 1 / (1 + std::exp(-(4 + 2 * std::log(sev)))));
    }
  }
  const PodFit f = FitPod(s, hit);
  ASSERT_TRUE(f.ok) << f.reason;
  EXPECT_NEAR(f.intercept, 4, 0.4);
  EXPECT_NEAR(f.slope, 2, 0.2);
  EXPECT_LT(f.Bound(0.1, -1.96), f.Probability(0.1));
  EXPECT_GT(f.Bound(0.1, 1.96), f.Probability(0.1));
}

TEST(FitPod, CompleteSeparationStillGivesAFiniteCurve) {
  // All small faults missed, all large caught: plain maximum likelihood diverges.
  const PodFit f = FitPod({0.1, 0.1, 0.1, 0.2, 0.2, 0.2, 0.4, 0.4}, {false, false, false, true, true, true, true, true});
  ASSERT_TRUE(f.ok) << f.reason;
  EXPECT_GT(f.slope, 0);
  EXPECT_LT(f.Probability(0.1), 0.5);
  EXPECT_GT(f.Probability(0.4), 0.5);
  EXPECT_FALSE(FitPod({0.1, 0.1, 0.1, 0.1}, {true, true, false, true}).ok);  // one magnitude
}

TEST(SweepGrid, SpecsEditAxesAndTheMonitorsLimitsAreAlwaysIncluded) {
  const MonitorConfig base;
  const SweepGrid g = MakeSweepGrid(base, "kt_factor.worn=0.9:0.98:5,friction_factor.worn=1.5,significance=4:5:2");
  EXPECT_THAT(g.axes[0].worn_values, testing::ElementsAre(0.9, 0.92, 0.94, 0.95, 0.96, 0.98));
  EXPECT_THAT(g.axes[2].worn_values, testing::ElementsAre(1.3, 1.5));
  EXPECT_THAT(g.significance, testing::ElementsAre(3, 4, 5));
  EXPECT_EQ(SettingCount(g), 6L * 6 * 2 * 7 * 3);
  // kt 0.900..0.995 by 0.005 (20, 0.95 among them); resistance 1.0..3.0 by 0.5 plus 1.4;
  // friction 1.0..1.9 by 0.1 (1.3 among them); drift 0.1..3.1 by 0.6 plus 1.0;
  // significance 1..5 by 0.5 (3 among them).
  EXPECT_EQ(SettingCount(MakeSweepGrid(base, "")), 20L * 6 * 10 * 7 * 9);
  auto error = [&](const std::string& spec) {
    try {
      MakeSweepGrid(base, spec);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error("kt_factr.worn=0.9"), HasSubstr("unknown detector parameter \"kt_factr\""));
  EXPECT_THAT(error("kt_factor=0.9"), HasSubstr("NAME.worn"));
  EXPECT_THAT(error("kt_factor.worn=0.9:0.8"), HasSubstr("FROM:TO:STEPS"));
  EXPECT_THAT(error("kt_factor.worn=1.2"), HasSubstr("not a worn limit"));
  EXPECT_THAT(error("friction_factor.worn=1:2:0"), HasSubstr("STEPS"));
  EXPECT_THAT(error("friction_factor.worn=abc"), HasSubstr("expected a number, got \"abc\""));
  EXPECT_THAT(error("significance=0"), HasSubstr("significance: 0.000000 is not in (0, 100]"));
}

// A small campaign the default K_T limit (0.95) partly misses: K_T 0.95 and 0.9 faults.
json KtCampaign(const json& monitor) {
  json j = json::parse(R"({
    "name": "kt-tune", "seed": 11, "duration_s": 6,
    "trajectories": [{"name": "exp1", "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}],
    "faults": [{"family": "kt_degradation", "joint": 3, "kt_factor": [0.96, 0.95, 0.9], "onset_s": 1.5}],
    "healthy": 3, "repetitions": 2,
    "variation": {"payload_kg": {"uniform": [0, 0.5]}, "friction_spread": 0.1}
  })");
  j["monitor"] = monitor;
  return j;
}

std::vector<DecisionLine> ReadDecisions(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<DecisionLine> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(DecisionLineFromJson(json::parse(line)));
  return out;
}

std::vector<RunRecord> ReadRecords(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<RunRecord> out;
  std::string line;
  while (std::getline(in, line)) out.push_back(RunRecordFromJson(json::parse(line)));
  return out;
}

TEST(Tune, RocAucCoversTheMeasuredPointsOnlyAndUnsweptCurvesHaveNone) {
  ScratchDir dir("tune_roc");
  json file = KtCampaign(json::object());
  file["faults"].push_back({{"family", "torque_sensor_stuck"}, {"joint", 3}, {"lead", "supply"}, {"onset_s", 2.0}});
  const Campaign campaign = CampaignFromJson(file, "kt.json", dir.path().string());
  RunnerOptions o;
  o.output_dir = (dir.path() / "out").string();
  RunCampaign(campaign, o);
  TuneOptions options;
  options.sweep = "kt_factor.worn=0.9:0.995:20,significance=1:5:9";
  const json roc = TuneCampaignDir(o.output_dir, options).report["roc"];
  // The stuck sensor has no swept threshold of its own: not swept, no AUC, whatever its points.
  EXPECT_TRUE(roc["torque_sensor_stuck"]["parameter"].is_null());
  EXPECT_FALSE(roc["torque_sensor_stuck"]["swept"].get<bool>());
  EXPECT_TRUE(roc["torque_sensor_stuck"]["auc"].is_null());
  EXPECT_EQ(roc["kt_degradation"]["parameter"], "kt_factor.worn");
  for (const auto& [name, curve] : roc.items()) {
    std::vector<std::pair<double, double>> pts;
    for (const json& p : curve["points"]) pts.emplace_back(p["false_alarm_rate"].get<double>(), p["detection_rate"].get<double>());
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    const bool own = name == "overall" || !curve["parameter"].is_null();
    EXPECT_EQ(curve["swept"].get<bool>(), own && pts.size() >= 2) << name;
    if (!curve["swept"].get<bool>() || pts.back().first == pts.front().first) {
      EXPECT_TRUE(curve["auc"].is_null()) << name;
      EXPECT_TRUE(curve["auc_false_alarm_range"].is_null()) << name;
      continue;
    }
    // Trapezoids between the measured points only: nothing added at (0, 0) or (1, 1).
    double area = 0;
    for (size_t i = 1; i < pts.size(); ++i) area += (pts[i].first - pts[i - 1].first) * (pts[i].second + pts[i - 1].second) / 2;
    EXPECT_DOUBLE_EQ(curve["auc"].get<double>(), area) << name;
    EXPECT_EQ(curve["auc_false_alarm_range"], json::array({pts.front().first, pts.back().first})) << name;
  }
  // This campaign's swept K_T limit does move its rates.
  EXPECT_TRUE(roc["kt_degradation"]["swept"].get<bool>()) << roc["kt_degradation"].dump();
}

// One denominator: at the thresholds it ran with, tune's rates are run's (summary.json), with
// the runs whose fault could not act left out of both (or, when the campaign includes them,
// in both).
TEST(Tune, AsRunRatesAreTheSummarysWithTheSameRunsLeftOut) {
  for (const bool include : {false, true}) {
    ScratchDir dir(include ? "tune_denominator_in" : "tune_denominator");
    json file = KtCampaign(json::object());
    file["duration_s"] = 4;
    // Joint 2 holds still: a K_T loss there cannot act, so its runs are not excited.
    file["faults"].push_back({{"family", "kt_degradation"}, {"joint", 2}, {"kt_factor", 0.9}, {"onset_s", 1.5}});
    if (include) file["include_not_excited"] = true;
    const Campaign campaign = CampaignFromJson(file, "kt.json", dir.path().string());
    RunnerOptions o;
    o.output_dir = (dir.path() / "out").string();
    RunCampaign(campaign, o);
    SummaryBuilder summary(include);
    for (const RunRecord& r : ReadRecords(dir.path() / "out" / "results.jsonl")) summary.Add(r);
    const json overall = summary.Build(Floors{}, nullptr, "v")["overall"];
    ASSERT_EQ(summary.not_excited_runs(), 2);  // kt_factor 0.9 on joint 2, two repetitions
    TuneOptions options;
    options.sweep = "kt_factor.worn=0.9:0.99:4";
    const TuningResult t = TuneCampaignDir(o.output_dir, options);
    const json& as_run = t.report["default_point"];
    for (const auto& [tuned, run] : {std::pair{"detection_rate", "detection"}, std::pair{"false_alarm_rate", "false_alarm"},
                                     std::pair{"isolation_accuracy", "isolation"}}) {
      EXPECT_EQ(as_run[tuned]["count"], overall[run]["successes"]) << tuned << " include " << include;
      EXPECT_EQ(as_run[tuned]["runs"], overall[run]["trials"]) << tuned << " include " << include;
    }
    EXPECT_EQ(t.report["runs"]["faulty"], overall["faulty_runs"]);
    EXPECT_EQ(t.report["runs"]["not_excited"], 2);
    EXPECT_EQ(t.report["runs"]["not_excited_included"], include);
    EXPECT_EQ(t.not_excited, include ? 0 : 2);
  }
}

TEST(Tune, ARunDirectoryWhoseCsvTrajectoryIsNotBesideItIsTuned) {
  // campaign.json names the csv trajectory relative to the campaign file, which is not beside
  // the run directory: tune reads only the spec (campaigns/spec/campaign_spec.h) and loads nothing.
  ScratchDir dir("tune_csv");
  std::filesystem::create_directories(dir.path() / "campaign");
  dir.Write("campaign/swing.csv", "time_s,angle_deg\n0,0\n1,20\n2,0\n3,-20\n4,0\n");
  json file = KtCampaign(json::object());
  file["duration_s"] = 4;
  file["repetitions"] = 1;
  file["trajectories"] = json::parse(R"([{"name": "swing", "joints": {"3": {"type": "csv", "path": "swing.csv"}}}])");
  const Campaign campaign = CampaignFromJson(file, "kt.json", (dir.path() / "campaign").string());
  RunnerOptions o;
  o.output_dir = (dir.path() / "out").string();
  RunCampaign(campaign, o);
  std::filesystem::remove(dir.path() / "campaign" / "swing.csv");
  TuneOptions options;
  options.sweep = "kt_factor.worn=0.9:0.99:4";
  const TuningResult t = TuneCampaignDir(o.output_dir, options);
  EXPECT_EQ(t.report["campaign"], "kt-tune");
  // The spec alone reads it too, without the file; the campaign for running still needs it.
  const json resolved = ReadJsonFile((dir.path() / "out" / "campaign.json").string())["campaign"];
  EXPECT_EQ(CampaignSpecFromJson(resolved, "campaign.json", o.output_dir).trajectories[0].name, "swing");
  EXPECT_THROW(CampaignFromJson(resolved, "campaign.json", o.output_dir), InputError);
}

TEST(Tune, ChoosesOnEvenSeedsReportsOnOddSeedsAndWarnsAtTheGridsEdge) {
  ScratchDir dir("tune_split");
  json file = KtCampaign(json::object());
  file["healthy"] = 8;  // both halves need healthy runs
  const Campaign campaign = CampaignFromJson(file, "kt.json", dir.path().string());
  RunnerOptions o;
  o.output_dir = (dir.path() / "out").string();
  RunCampaign(campaign, o);
  long even_faulty = 0, odd_faulty = 0;
  for (const RunRecord& r : ReadRecords(dir.path() / "out" / "results.jsonl")) {
    if (!r.family.empty()) (r.seed % 2 == 0 ? even_faulty : odd_faulty) += 1;
  }
  TuneOptions options;
  options.sweep = "kt_factor.worn=0.9:0.99:10";
  options.rule.false_alarm_ceiling = 0.0;
  const TuningResult t = TuneCampaignDir(o.output_dir, options);
  const json& sel = t.report["selection"];
  ASSERT_TRUE(sel.contains("held_out")) << sel.dump();
  EXPECT_EQ(sel["chosen_on"]["detection_rate"]["runs"].get<long>(), even_faulty);
  EXPECT_EQ(sel["held_out"]["detection_rate"]["runs"].get<long>(), odd_faulty);
  EXPECT_EQ(sel["chosen_on"]["setting"], t.report["operating_point"]["setting"]);
  // Resistance and drift never alarm here, so the tie-break takes their largest limits: the
  // grid's edge, which the report must point out.
  bool resistance_edge = false;
  for (const json& w : t.report["warnings"]) {
    EXPECT_THAT(w.get<std::string>(), HasSubstr("edge of the swept range"));
    resistance_edge = resistance_edge || w.get<std::string>().rfind("resistance_factor.worn", 0) == 0;
  }
  EXPECT_TRUE(resistance_edge) << t.report["warnings"].dump();
}

TEST(Tune, ARerunWithTheTunedMonitorGivesThePredictedRates) {
  ScratchDir dir("tune");
  const Campaign first = CampaignFromJson(KtCampaign(json::object()), "kt.json", dir.path().string());
  RunnerOptions o;
  o.output_dir = (dir.path() / "first").string();
  RunCampaign(first, o);

  TuneOptions options;
  options.sweep = "kt_factor.worn=0.9:0.99:10";
  options.rule.false_alarm_ceiling = 0.0;
  const TuningResult t = TuneCampaignDir(o.output_dir, options);
  const json& op = t.report["operating_point"];
  const json& as_run = t.report["default_point"];
  // The tuner found a more sensitive K_T limit than the default, without false alarms.
  EXPECT_GT(op["setting"]["kt_factor.worn"].get<double>(), 0.93);
  EXPECT_GT(op["detection_rate"]["count"].get<long>(), as_run["detection_rate"]["count"].get<long>());
  EXPECT_EQ(op["false_alarm_rate"]["count"].get<long>(), 0);
  EXPECT_DOUBLE_EQ(t.tuned.kt_factor.worn, op["setting"]["kt_factor.worn"].get<double>());

  // Run the campaign again with the tuned monitor, and score it from its own records.
  const Campaign second = CampaignFromJson(KtCampaign(MonitorConfigToJson(t.tuned)), "kt.json", dir.path().string());
  RunnerOptions o2 = o;
  o2.output_dir = (dir.path() / "second").string();
  RunCampaign(second, o2);
  long faulty = 0, detected = 0, healthy = 0, false_alarms = 0, isolated = 0;
  for (const RunRecord& r : ReadRecords(dir.path() / "second" / "results.jsonl")) {
    if (r.family.empty()) {
      ++healthy;
      false_alarms += r.detected;
    } else {
      ++faulty;
      detected += r.detected;
      isolated += r.detected && r.isolated_family == r.family && r.isolated_joint == r.joint;
    }
  }
  EXPECT_EQ(detected, op["detection_rate"]["count"].get<long>());
  EXPECT_EQ(faulty, op["detection_rate"]["runs"].get<long>());
  EXPECT_EQ(false_alarms, op["false_alarm_rate"]["count"].get<long>());
  EXPECT_EQ(healthy, op["false_alarm_rate"]["runs"].get<long>());
  EXPECT_EQ(isolated, op["isolation_accuracy"]["count"].get<long>());

  // The statistics do not depend on the thresholds: both runs stored the same ones.
  const auto a = ReadDecisions(dir.path() / "first" / "decisions.jsonl");
  const auto b = ReadDecisions(dir.path() / "second" / "decisions.jsonl");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), ReadRecords(dir.path() / "first" / "results.jsonl").size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].decision.is_object()) << a[i].run_id;
    EXPECT_EQ(a[i].decision, b[i].decision) << a[i].run_id;
  }
}

// The sequential decision: tune sweeps the target rate, reports the rate measured beside each
// target, and a rerun at the chosen target gives the rates it predicted.
TEST(Tune, TheSequentialDecisionSweepsItsTargetRateAndARerunGivesThePrediction) {
  ScratchDir dir("tune_sequential");
  auto campaign = [](const json& monitor) {
    json j = KtCampaign(monitor);
    j["duration_s"] = 40;
    j["faults"][0]["kt_factor"] = {0.9, 0.7};
    j["faults"][0]["onset_s"] = 10;
    return j;
  };
  const json monitor = {{"decision", "sequential"}};
  RunnerOptions o;
  o.output_dir = (dir.path() / "first").string();
  const Campaign first = CampaignFromJson(campaign(monitor), "seq.json", dir.path().string());
  RunCampaign(first, o);
  // The summary states the rate the monitor was set for beside the one measured (none for the
  // threshold decision).
  EXPECT_EQ(StatedFalseAlarmsPerHour(first), 1.0);
  EXPECT_EQ(StatedFalseAlarmsPerHour(CampaignFromJson(campaign(json::object()), "t.json", dir.path().string())), 0.0);

  TuneOptions options;
  options.sweep = "target_false_alarms_per_hour=0.01,target_false_alarms_per_hour=100,target_false_alarms_per_hour=1e4";
  options.rule.false_alarm_ceiling = 1.0;
  const TuningResult t = TuneCampaignDir(o.output_dir, options);
  const json& cal = t.report["rate_calibration"];
  EXPECT_EQ(cal["parameter"], "target_false_alarms_per_hour");
  EXPECT_EQ(cal["as_run"], 1.0);
  ASSERT_EQ(cal["points"].size(), 4u);
  long previous_alarms = -1, previous_detected = -1;
  for (const json& p : cal["points"]) {
    // A higher target lowers every threshold: never fewer alarms, never fewer detections.
    EXPECT_GE(p["false_alarms"].get<long>(), previous_alarms);
    EXPECT_GE(p["detected"].get<long>(), previous_detected);
    previous_alarms = p["false_alarms"];
    previous_detected = p["detected"];
    EXPECT_GT(p["healthy_hours"].get<double>(), 0.0);
    EXPECT_LE(p["healthy_hours"].get<double>(), 3 * 40 / 3600.0 + 1e-9);
    const json& in = p["measured_interval_per_hour"];
    EXPECT_LE(in[0].get<double>(), p["measured_per_hour"].get<double>());
    EXPECT_GE(in[1].get<double>(), p["measured_per_hour"].get<double>());
    EXPECT_EQ(p["faulty_runs"], 4);
  }
  // 1e4 per hour: each of the 3 healthy runs alarms within seconds, and a run counts its first
  // alarm only, so 3 alarms in the hours to them is fewer than the 14 to 32 the target predicts
  // over those hours: reported as outside.
  EXPECT_EQ(cal["points"][3]["target_count_interval"], json::array({14, 32}));
  EXPECT_EQ(cal["points"][3]["false_alarms"], 3);
  EXPECT_FALSE(cal["points"][3]["consistent"].get<bool>());
  EXPECT_TRUE(cal["points"][1]["consistent"].get<bool>());
  // Never slower at a higher target (here the K_T faults cross every threshold at their first look).
  EXPECT_LE(cal["points"][3]["median_latency_s"].get<double>(), cal["points"][1]["median_latency_s"].get<double>());
  EXPECT_LE(cal["points"][1]["median_latency_s"].get<double>(), cal["points"][0]["median_latency_s"].get<double>());
  EXPECT_FALSE(t.report["parameters"].empty());
  EXPECT_TRUE(t.tuned_monitor.contains("target_false_alarms_per_hour"));
  EXPECT_EQ(t.tuned_monitor["decision"], "sequential");

  // Rerun with the tuned monitor: its own records give the operating point's rates.
  const json& op = t.report["operating_point"];
  RunnerOptions o2 = o;
  o2.output_dir = (dir.path() / "second").string();
  RunCampaign(CampaignFromJson(campaign(t.tuned_monitor), "seq.json", dir.path().string()), o2);
  long detected = 0, false_alarms = 0;
  for (const RunRecord& r : ReadRecords(dir.path() / "second" / "results.jsonl")) {
    (r.family.empty() ? false_alarms : detected) += r.detected;
  }
  EXPECT_EQ(detected, op["detection_rate"]["count"].get<long>());
  EXPECT_EQ(false_alarms, op["false_alarm_rate"]["count"].get<long>());
}

TEST(Tune, ASequentialSweepOfAnotherParameterIsRefused) {
  ScratchDir dir("tune_sequential_spec");
  json j = KtCampaign({{"decision", "sequential"}});
  j["healthy"] = 1;
  j["repetitions"] = 1;
  j["faults"][0]["kt_factor"] = 0.9;
  RunnerOptions o;
  o.output_dir = (dir.path() / "out").string();
  RunCampaign(CampaignFromJson(j, "seq.json", dir.path().string()), o);
  TuneOptions options;
  options.sweep = "kt_factor.worn=0.9";
  const InputError e = ErrorOf([&] { TuneCampaignDir(o.output_dir, options); });
  EXPECT_EQ(e.source(), "--sweep");
  EXPECT_THAT(e.message(), HasSubstr("target_false_alarms_per_hour="));
  options.sweep = "target_false_alarms_per_hour=0";
  EXPECT_THAT(ErrorOf([&] { TuneCampaignDir(o.output_dir, options); }).message(), HasSubstr("not a rate > 0"));
}

void WriteLines(const std::filesystem::path& path, const std::vector<std::string>& lines) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  for (const std::string& l : lines) out << l << "\n";
}

// The directory as an older armfault wrote it: each results line with its decision inline
// (keys sorted, as ToJson wrote them) and no decisions.jsonl.
void ReInline(const std::filesystem::path& dir) {
  const std::vector<std::string> results = Lines(ReadAll(dir / "results.jsonl"));
  const std::vector<std::string> decisions = Lines(ReadAll(dir / "decisions.jsonl"));
  ASSERT_EQ(results.size(), decisions.size());
  std::vector<std::string> old;
  for (size_t k = 0; k < results.size(); ++k) {
    json line = json::parse(results[k]);
    line["decision"] = json::parse(decisions[k])["decision"];
    old.push_back(line.dump());
  }
  WriteLines(dir / "results.jsonl", old);
  std::filesystem::remove(dir / "decisions.jsonl");
}

// The tuning of KtCampaign's runs in DIR/new and of the same runs in the older layout in
// DIR/old, run once for the tests below.
class TuneLayouts : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::filesystem::path(std::filesystem::temp_directory_path() / ("tune_layouts_" + std::to_string(getpid())));
    std::filesystem::create_directories(*dir_);
    json file = KtCampaign(json::object());
    file["healthy"] = 4;
    const Campaign c = CampaignFromJson(file, "kt.json", dir_->string());
    RunnerOptions o;
    o.output_dir = (*dir_ / "new").string();
    o.threads = 2;
    RunCampaign(c, o);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    std::filesystem::remove_all(*dir_, ec);
    delete dir_;
    dir_ = nullptr;
  }
  // A copy of the new layout to edit.
  static std::filesystem::path Copy(const std::string& name) {
    const std::filesystem::path to = *dir_ / name;
    std::filesystem::copy(*dir_ / "new", to, std::filesystem::copy_options::recursive);
    return to;
  }
  static TuneOptions Options() {
    TuneOptions options;
    options.sweep = "kt_factor.worn=0.9:0.99:10";
    options.rule.kind = OperatingRule::Kind::kYouden;
    options.threads = 2;
    return options;
  }
  static std::filesystem::path* dir_;
};
std::filesystem::path* TuneLayouts::dir_ = nullptr;

TEST_F(TuneLayouts, DecisionsJsonlTunesExactlyAsTheOlderInlineDecisions) {
  const TuningResult from_file = TuneCampaignDir((*dir_ / "new").string(), Options());
  const std::filesystem::path old = Copy("old");
  ReInline(old);
  ASSERT_FALSE(std::filesystem::exists(old / "decisions.jsonl"));
  const TuningResult from_inline = TuneCampaignDir(old.string(), Options());
  EXPECT_EQ(from_file.runs, 10);
  EXPECT_EQ(from_inline.runs, from_file.runs);
  EXPECT_EQ(from_inline.report.dump(2), from_file.report.dump(2));
  EXPECT_EQ(MonitorConfigToJson(from_inline.tuned), MonitorConfigToJson(from_file.tuned));
}

TEST_F(TuneLayouts, RefusesDecisionsThatDoNotGoWithTheResultsNamingTheLine) {
  const std::filesystem::path d = Copy("bad");
  const std::filesystem::path decisions = d / "decisions.jsonl", results = d / "results.jsonl";
  const std::vector<std::string> lines = Lines(ReadAll(decisions));
  auto error = [&] { return ErrorOf([&] { TuneCampaignDir(d.string(), Options()); }); };

  std::vector<std::string> swapped = lines;
  std::swap(swapped[1], swapped[2]);
  WriteLines(decisions, swapped);
  InputError e = error();
  EXPECT_EQ(e.source(), decisions.string());
  EXPECT_THAT(e.message(), HasSubstr("line 2: case 2 \"exp1/kt_degradation#0/kt_factor=0.95/j3/r0\", but line 2 of " +
                                     results.string() + " is case 1 \"exp1/kt_degradation#0/kt_factor=0.96/j3/r1\""));

  // Cut by a kill in its last line, or ending early.
  std::ofstream(decisions, std::ios::binary | std::ios::trunc) << lines[0] << "\n" << lines[1].substr(0, lines[1].size() / 2);
  e = error();
  EXPECT_EQ(e.source(), decisions.string());
  EXPECT_THAT(e.message(), HasSubstr("line 2: cut: the line has no newline"));
  WriteLines(decisions, std::vector<std::string>(lines.begin(), lines.begin() + 3));
  EXPECT_THAT(error().message(), HasSubstr("line 4: missing: the file ends after 3 lines"));
  // One line too many.
  std::vector<std::string> more = lines;
  more.push_back(lines.back());
  WriteLines(decisions, more);
  EXPECT_THAT(error().message(), HasSubstr("line 11: more lines than the 10 runs of " + results.string()));
  // Not a decisions line.
  std::vector<std::string> broken = lines;
  broken[4] = R"({"case_index": 4, "run_id": "exp1/kt_degradation#0/kt_factor=0.95/j3/r0"})";
  WriteLines(decisions, broken);
  EXPECT_THAT(error().message(), HasSubstr("line 5: missing key \"decision\""));

  // Neither decisions.jsonl nor inline decisions (--summary-only removed them).
  std::filesystem::remove(decisions);
  e = error();
  EXPECT_EQ(e.source(), results.string());
  EXPECT_THAT(e.message(), HasSubstr("line 1: no decision statistics: " + decisions.string() + " does not exist"));
}

TEST(Tune, RefusesResultsWhoseStatisticsDoNotReproduceThem) {
  ScratchDir dir("tune_tamper");
  json j = KtCampaign(json::object());
  j["faults"][0]["kt_factor"] = {0.7};
  j["healthy"] = 0;
  j["repetitions"] = 1;
  const Campaign c = CampaignFromJson(j, "kt.json", dir.path().string());
  RunnerOptions o;
  o.output_dir = dir.path().string();
  RunCampaign(c, o);
  std::string text;
  {
    std::ifstream in(dir.path() / "results.jsonl");
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  json line = json::parse(text.substr(0, text.find('\n')));
  ASSERT_TRUE(line["detected"].get<bool>());
  line["detected"] = false;
  line["detection_time_s"] = nullptr;
  dir.Write("results.jsonl", line.dump() + "\n");
  try {
    TuneCampaignDir(dir.path().string(), TuneOptions());
    FAIL() << "tampered results were accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("results.jsonl"));
    EXPECT_THAT(e.what(), HasSubstr("line 1"));
    EXPECT_THAT(e.what(), HasSubstr("do not reproduce"));
  }
}

}  // namespace
}  // namespace armfault
