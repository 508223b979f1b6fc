// Named scalar statistics that any monitor type (a C plugin, a Python monitor, a built-in
// one) may publish with their alarm thresholds, and the compact per-run record of them that
// lets `armfault tune` re-score other thresholds without simulating again (docs/monitor-api.md,
// "Statistics for tune").
//
// The contract a publishing monitor keeps: it declares statistics (name, the family its alarm
// names, threshold > 0) and after every tick gives each statistic's value for every joint (NaN:
// no value at this tick). At every tick, joint j alarms exactly while some statistic s has
//     value[j][s] > threshold[s],
// and its verdict names the family of the first such s in declaration order (a monitor whose
// alarm latches publishes the running maximum). Scoring reads the verdicts as for any monitor;
// tune checks that the stored statistics give each run's recorded outcome at the declared
// thresholds, and refuses the directory when they do not.
//
// What is stored, per joint and statistic: the maximum before the fault onset, and, from the
// onset on, the ticks whose value first exceeds one of the levels
//     threshold x 2^(k / kLevelsPerOctave),  k = -kLevelSteps .. kLevelSteps,
// (a factor 4 either way, 4.4 % apart). Under any threshold on a level the first alarm after
// the onset is one of those ticks, so re-scoring on the levels is exact; at most 2 kLevelSteps
// + 1 ticks a trace, whatever the run's length.
#pragma once

#include <nlohmann/json.hpp>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/monitors/monitor.h"

namespace armfault {

constexpr int kLevelsPerOctave = 16;
constexpr int kLevelSteps = 32;  // levels from threshold / 4 to threshold x 4

// A statistic as the monitor declares it.
struct StatisticInfo {
  std::string name;     // unique among the monitor's statistics, e.g. "kt_deficit"
  std::string family;   // a fault family, or "unknown": what its alarm names
  double threshold = 0;  // > 0; alarms while value > threshold
  // Where the threshold lives in the monitor's settings, as a JSON pointer ("/kt_worn"), so
  // tune can write the tuned monitor; "" when the settings do not hold it.
  std::string setting;
};
// "" or why the declarations are not usable (an empty or repeated name, threshold <= 0 ...).
std::string CheckStatistics(const std::vector<StatisticInfo>& statistics);

// The threshold of level k of a statistic declared with `threshold`.
double LevelThreshold(double threshold, int k);

// One run's record, stored as "decision" in its line of decisions.jsonl.
struct ThresholdStats {
  struct Rise {
    double t_s = 0;
    double value = 0;
  };
  struct Trace {
    int joint = 0;      // 1-based
    int statistic = 0;  // index into statistics
    double pre_max = -std::numeric_limits<double>::infinity();  // before the onset; -inf: none
    std::vector<Rise> rise;  // from the onset on, the ticks that passed a new level, in time order
  };
  std::vector<StatisticInfo> statistics;
  double onset_s = 0;
  double first_tick_s = -1;  // the first tick at or after the onset (-1: none)
  std::vector<Trace> traces;  // only (joint, statistic) pairs that ever had a value
};
nlohmann::json ToJson(const ThresholdStats& stats);
// Throws std::runtime_error naming the key on malformed input.
ThresholdStats ThresholdStatsFromJson(const nlohmann::json& j);

// Builds ThresholdStats tick by tick.
class ThresholdRecorder {
 public:
  ThresholdRecorder(std::vector<StatisticInfo> statistics, int joints, double onset_s);
  // values[j * statistics + s]: statistic s of joint j + 1 at tick t_s (NaN: none).
  void Record(double t_s, const double* values);
  const ThresholdStats& stats() const { return stats_; }
  int joints() const { return joints_; }
  // From now on every Record's values also go to `observer` (DecisionTap::ShowStatistics).
  void Show(StatisticsObserver* observer);

 private:
  ThresholdStats stats_;
  int joints_;
  StatisticsObserver* observer_ = nullptr;
  std::vector<int> trace_index_;  // [j * statistics + s], -1: no trace yet
  std::vector<int> next_level_;   // the lowest level not passed yet since the onset
};

// The outcome of one run under thresholds (one per statistic, each a level of it):
// what ScoreVerdicts gives for a monitor keeping the contract.
struct ThresholdOutcome {
  bool alarm_before_onset = false;
  bool detected = false;
  double detection_time_s = 0;
  int joint = 0;
  std::string family;
};
ThresholdOutcome DecideThresholds(const ThresholdStats& stats, const std::vector<double>& thresholds);
// The first alarm of one trace from the onset on under `threshold` (nullptr: none).
const ThresholdStats::Rise* FirstAlarm(const ThresholdStats::Trace& trace, double threshold);

// Why the run was scored as `score` ("" when right): for a miss, the faulted joint's statistic
// that came closest to its threshold; for a wrong name, what alarmed instead.
std::string ExplainThresholds(const ThresholdStats& stats, const RunScore& score, const std::string& family, int joint);

// The DecisionTap of a monitor that publishes statistics: the monitor records into recorder()
// as it computes them (a Python monitor in batches), so AfterObserve does nothing.
class ThresholdTap : public DecisionTap {
 public:
  ThresholdTap(std::vector<StatisticInfo> statistics, int joints, double onset_s)
      : recorder_(std::move(statistics), joints, onset_s) {}
  void AfterObserve(double) override {}
  nlohmann::json Statistics() const override { return ToJson(recorder_.stats()); }
  std::string Explain(const RunScore& score, const std::string& family, int joint) const override {
    return ExplainThresholds(recorder_.stats(), score, family, joint);
  }
  void ShowStatistics(StatisticsObserver* observer) override { recorder_.Show(observer); }
  ThresholdRecorder* recorder() { return &recorder_; }

 private:
  ThresholdRecorder recorder_;
};

}  // namespace armfault
