// The power monitor's swept detectors as threshold tests on scalar statistics, and the
// compact per-run record of those statistics that lets `armfault tune` re-score any
// threshold setting without simulating again.
//
// Each parametric detector d of a joint has, at every controller tick, a deviation statistic
// b_d >= 0 (how far the estimate lies from healthy, in the estimate's units) when the
// estimate is significant (its gate: enough excitation, |deviation| >= significance x std
// error), else none. The statistic is quantized down to kStatisticQuantum and held: the
// detector's held value at tick k is the minimum of the quantized statistic over ticks
// k-H..k, H = round(debounce_s / control period). The detector alarms while
//     held x kStatisticQuantum > threshold_d,   threshold_d = |worn limit - healthy value|.
// A run's alarm time under thresholds h is the first tick where any detector's held value
// passes its h (ties: Detector order, then joint), or a tick-level (structural) detector
// latches; the run's isolation is that detector's family and joint.
//
// Because held values do not depend on the thresholds, the running maximum of each held
// value (from the fault onset on) and its maximum before the onset are all a setting needs.
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
constexpr double kStatisticQuantum = 1e-3;  // of a factor, or N m for the drift
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
// The worn limit a threshold stands for (inverse of ThresholdsOf for one detector).
double WornLimitFor(const DetectorInfo& info, const MonitorConfig& config, double threshold);
double ThresholdFor(const DetectorInfo& info, double worn_limit);

// True when a held value (in quanta) alarms against a threshold; the one comparison the
// monitor and the re-scoring share.
inline bool Alarms(double held_quanta, double threshold) { return held_quanta * kStatisticQuantum > threshold; }

// Quantized statistic (in quanta, an integer-valued double), kNoStatistic when none.
double Quantize(double statistic);

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
  double held_quanta = kNoStatistic;
  const char* family = "";
};
using DetectorReadings = std::array<DetectorReading, kDetectorCount>;

// The compact record of one run, stored as "decision" in results.jsonl.
struct DecisionStats {
  struct Rise {
    double t_s = 0;
    long quanta = 0;
    std::string family;  // set when it differs from the detector's own family
  };
  struct Trace {
    int joint = 0;  // 1-based
    Detector detector = Detector::kKtFactor;
    double pre_max_quanta = kNoStatistic;  // max held value before the onset
    std::vector<Rise> rise;                // running maxima of the held value from the onset on
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
DecisionOutcome Decide(const DecisionStats& stats, const DetectorThresholds& thresholds);

}  // namespace armfault
