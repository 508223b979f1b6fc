// The power monitor's swept detectors as threshold tests on scalar statistics, and the
// compact per-run record of those statistics that lets `armfault tune` re-score any
// threshold setting without simulating again.
//
// Each parametric detector d of a joint has, at every controller tick where its estimate is
// judged (enough excitation), two statistics: the deviation b_d (how far the estimate lies
// from healthy, in the estimate's units) and its significance s_d (deviation / standard
// error). Both are quantized down (kStatisticQuantum, kSignificanceQuantum) and held: the
// held value at tick k is the minimum over ticks k-H..k, H = round(debounce_s / control
// period). The detector alarms while
//     held b x kStatisticQuantum > threshold_d  and  held s x kSignificanceQuantum >= z,
// threshold_d = |worn limit - healthy value|, z = the monitor's significance. (For all ticks
// of the window, b > h and s >= z  <=>  min b > h and min s >= z.)
// A run's alarm time under (h, z) is the first tick where any detector alarms (ties:
// Detector order, then joint), or a tick-level (structural) detector latches; the run's
// isolation is that detector's family and joint.
//
// Held values do not depend on (h, z), so each detector stores, from the fault onset on, the
// ticks whose (held b, held s) no earlier tick dominates: the first alarm under any (h, z) is
// one of them. Before the onset, the non-dominated pairs tell whether any tick alarmed.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <deque>
#include <limits>
#include <string>
#include <vector>

namespace armfault {

struct MonitorConfig;

enum class Detector { kKtFactor = 0, kResistanceFactor, kFrictionFactor, kSensorDrift };
constexpr int kDetectorCount = 4;
constexpr double kStatisticQuantum = 1e-3;    // of a factor, or N m for the drift
constexpr double kSignificanceQuantum = 1e-2;  // standard errors
constexpr double kNoStatistic = -std::numeric_limits<double>::infinity();

struct DetectorInfo {
  Detector detector;
  const char* family;     // the fault family it names ("kt_degradation"...)
  const char* parameter;  // its MonitorConfig limit, "kt_factor" ("<parameter>.worn" in sweeps)
  double healthy;         // the parameter's healthy value (1 for factors, 0 for the drift)
};
const std::array<DetectorInfo, kDetectorCount>& Detectors();
// Throws std::out_of_range naming the known parameters.
const DetectorInfo& DetectorByParameter(const std::string& parameter);

// Thresholds on the deviation statistic, one per detector, in Detector order.
using DetectorThresholds = std::array<double, kDetectorCount>;
DetectorThresholds ThresholdsOf(const MonitorConfig& config);
double ThresholdFor(const DetectorInfo& info, double worn_limit);

// True when held values (in quanta) alarm against a threshold and a significance; the one
// comparison the monitor and the re-scoring share.
inline bool Alarms(double held_quanta, double held_significance_quanta, double threshold, double significance) {
  return held_quanta * kStatisticQuantum > threshold && held_significance_quanta * kSignificanceQuantum >= significance;
}

// Quantized statistic (in quanta, an integer-valued double), kNoStatistic when none.
double Quantize(double statistic, double quantum = kStatisticQuantum);

// Minimum of the last `span` pushed values (a monotone deque).
class SlidingMin {
 public:
  explicit SlidingMin(long span = 1) : span_(span) {}
  double Push(double value);  // returns the minimum including `value`
 private:
  long span_;
  long count_ = 0;
  std::deque<std::pair<long, double>> q_;
};

// One detector's held value at a tick, with the family it would name (a friction factor far
// beyond wear names brake_lock).
struct DetectorReading {
  double held_quanta = kNoStatistic;               // deviation
  double held_significance_quanta = kNoStatistic;  // deviation / standard error
  const char* family = "";
};
using DetectorReadings = std::array<DetectorReading, kDetectorCount>;

// The compact record of one run, stored as "decision" in its line of decisions.jsonl.
struct DecisionStats {
  struct Point {
    long quanta = 0;               // held deviation
    long significance_quanta = 0;  // held significance
  };
  struct Rise {
    double t_s = 0;
    Point held;
    std::string family;  // set when it differs from the detector's own family
  };
  struct Trace {
    int joint = 0;  // 1-based
    Detector detector = Detector::kKtFactor;
    std::vector<Point> pre;  // the non-dominated held pairs before the onset
    std::vector<Rise> rise;  // from the onset on, ticks whose held pair no earlier one dominates
  };
  struct Event {
    int joint = 0;
    std::string family;
    double t_s = 0;  // when the tick-level detector latched
  };
  double onset_s = 0;          // the fault's onset (0 for a healthy run)
  double first_tick_s = -1;    // the first monitored tick at or after the onset (-1: none)
  std::vector<Trace> traces;   // only detectors that ever had a statistic
  std::vector<Event> events;   // first latch per joint
  // "sequential" decision (sequential_test.h): the CUSUMs its rate is split over, from which
  // tune sets the thresholds of any target; 0 (not written) for the threshold decision.
  int sequential_tests = 0;
  double last_tick_s = -1;  // the run's last monitored tick (written with sequential_tests): its exposure
};
nlohmann::json ToJson(const DecisionStats& stats);
// Throws std::runtime_error naming the key on malformed input.
DecisionStats DecisionStatsFromJson(const nlohmann::json& j);

// Builds DecisionStats from the monitor's readings, tick by tick.
class DecisionRecorder {
 public:
  DecisionRecorder(int joints, double onset_s);
  // joint 0-based; `structural_family` non-empty once a tick-level detector has latched.
  void Record(double t_s, int joint, const DetectorReadings& readings, const std::string& structural_family);
  const DecisionStats& stats() const { return stats_; }
  void SetSequentialTests(int tests) { stats_.sequential_tests = tests; }

 private:
  DecisionStats stats_;
  std::vector<std::array<int, kDetectorCount>> trace_index_;  // -1: no trace yet
  std::vector<bool> latched_;
};

struct DecisionOutcome {
  bool alarm_before_onset = false;
  bool detected = false;  // an alarm at or after the onset
  double detection_time_s = 0;
  int joint = 0;
  std::string family;
};
DecisionOutcome Decide(const DecisionStats& stats, const DetectorThresholds& thresholds, double significance);

// Why a run was scored wrong, in one line for its record and the report ("" when it was
// scored right): for a missed fault, the statistic of the faulted joint that came closest to
// alarming and how far it stayed below its threshold, or the gate that never let a detector
// judge; for a wrong family or joint, what was named instead; for a healthy run that alarmed,
// what alarmed and when. `family` "" and `joint` 0 for a healthy run.
std::string ExplainOutcome(const DecisionStats& stats, const DetectorThresholds& thresholds, double significance,
                           const DecisionOutcome& outcome, const std::string& family, int joint,
                           const MonitorConfig& config);

// One detector trace against (h, z): whether it alarmed before the onset, and its first
// alarm from the onset on (nullptr if none).
bool AlarmedBefore(const DecisionStats::Trace& trace, double threshold, double significance);
const DecisionStats::Rise* FirstAlarm(const DecisionStats::Trace& trace, double threshold, double significance);

}  // namespace armfault
