// The standard monitor interface: what any health monitor may read (the joint controller's
// signals, JointSignals in core/signals/joint_signals.h) and what it must produce (a stream of verdicts plus per-window efficiencies).
// Scoring and threshold tuning read only MonitorOutput, so any monitor that implements
// HealthMonitor is scored the same way as the power-efficiency monitor.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/signals/joint_signals.h"

namespace armfault {

enum class HealthState { kHealthy, kWorn, kDefective };
const char* HealthStateName(HealthState s);

// One timestamped verdict about one joint. Emitted when the monitor's view of the joint
// changes (state, family) and when a magnitude estimate is refined while alarmed.
struct Verdict {
  double t_s = 0;
  int joint = 0;  // 1-based
  HealthState state = HealthState::kHealthy;
  bool alarm = false;          // state != healthy, after debounce
  std::string family;          // candidate fault family, "unknown", or "" when healthy
  std::string magnitude_name;  // e.g. "kt_factor", "friction_factor"; "" if none
  double magnitude = 0;        // estimate in the family's own parameter
  double confidence = 0;       // 0..1
};

// Energies [J] and efficiencies of one window of one joint: a stretch of motion in one
// direction, bounded by zero (below the rest threshold) joint velocity. Efficiencies that
// are not defined for the window's power flow are NaN (null in JSON). See docs/monitor.md.
struct EfficiencyWindow {
  int joint = 0;  // 1-based
  double t_start_s = 0, t_end_s = 0;
  int direction = 0;        // sign of the joint velocity
  std::string flow;         // "forward" (motor drives the load), "reverse" (load drives), "mixed"
  bool used = false;        // long and energetic enough to judge
  double out_J = 0;         // integral tau_s dq (+ coupling correction)
  double rotor_J = 0;       // integral ratio K_T i_cmd dq: rotor power from the command
  double friction_J = 0;    // integral f_hat dq: modelled friction
  double mesh_in_J = 0;     // rotor_J - friction_J: power into the harmonic drive
  double mesh_loss_J = 0;   // expected mesh loss from the measured torque
  double supply_J = 0;      // integral U_d I_d dt
  double electrical_loss_J = 0;  // expected copper + inverter + quiescent
  double eta = 0, eta_m = 0, eta_e = 0;             // measured (eq 4-8, 4-21, 4-23)
  double eta_expected = 0, eta_m_expected = 0, eta_e_expected = 0;  // healthy, same motion
};

struct MonitorOutput {
  std::vector<Verdict> verdicts;          // time order
  std::vector<EfficiencyWindow> windows;  // time order of their end
};

// The run-level diagnosis scoring uses: the first alarm gives detection and its time; the
// last verdict of that joint (the most informed) gives family, joint and magnitude.
struct Diagnosis {
  bool detected = false;
  double detection_time_s = 0;
  int joint = 0;
  std::string family;
  std::string magnitude_name;
  double magnitude = 0;
  double confidence = 0;
  HealthState state = HealthState::kHealthy;
};
Diagnosis Diagnose(const MonitorOutput& output);

// How a run is scored, for every monitor alike, from its verdicts and the fault's onset (which
// scoring knows and the monitor never does): an alarm before the onset is a false alarm; the
// first alarm from the onset on is the detection (an alarm standing at the onset counts at
// first_tick_s, the first controller tick at or after it), and its joint and family are the
// isolation (ties at one instant: the lower joint); the size is that joint's latest alarm
// verdict of that family. A healthy run has onset 0: any alarm is a false alarm.
struct RunScore {
  bool alarm_before_onset = false;
  bool detected = false;
  double detection_time_s = 0;
  int joint = 0;
  std::string family;
  std::string magnitude_name;
  std::optional<double> magnitude;
  double confidence = 0;
};
RunScore ScoreVerdicts(const MonitorOutput& output, double onset_s, double first_tick_s);

// Why a run was scored wrong, from the verdicts alone (for a monitor without a DecisionTap):
// "no alarm", what was named instead, or what alarmed on a healthy run. "" when scored right.
std::string ExplainFromVerdicts(const RunScore& score, const std::string& family, int joint);

// One verdict against the contract, time order aside: "" or why not ("joint 0 out of range,
// expected 1..3"). What CheckOutput and `armfault score` check of every verdict.
std::string CheckVerdict(const Verdict& v, int joints, double t_end_s, const std::vector<std::string>& families);

// Checks what a monitor emitted against the contract (docs/monitor-api.md): verdict times
// finite, in [0, t_end_s] and in time order; joints 1..joints; an alarm names a family from
// `families` or "unknown"; magnitudes and confidences finite, confidence in [0, 1]. Returns ""
// or the first breach ("verdict 4: joint 0, expected 1..3"), which fails the run.
std::string CheckOutput(const MonitorOutput& output, int joints, double t_end_s,
                        const std::vector<std::string>& families);

nlohmann::json ToJson(const Verdict& v);
nlohmann::json ToJson(const EfficiencyWindow& w);
nlohmann::json ToJson(const Diagnosis& d);
// {"diagnosis", "verdicts", "windows"}: what `trace --monitor-out` writes.
nlohmann::json ToJson(const MonitorOutput& output);

// Thrown by a monitor (a plugin's error return, a Python exception) to fail the run it is in
// with a reason; the campaign goes on.
class MonitorFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One statistic behind a monitor's alarms as `trace --statistics` shows it: its name, the
// family its alarm names, its threshold and the test against it (`value > threshold`, or
// `value >= threshold` where `inclusive`: the built-in monitor's significance).
struct PublishedStatistic {
  std::string name;
  std::string family;
  double threshold = 0;
  bool inclusive = false;
};

// Receives every published statistic's value at every tick (`armfault trace --run RUN
// --statistics`): Declare once before the first tick, then Values after each tick's values are
// known, values[(joint - 1) * statistics.size() + s] (NaN: no value at this tick), in time order.
// Called on the run's thread; `values` is valid for the call only.
class StatisticsObserver {
 public:
  virtual ~StatisticsObserver() = default;
  virtual void Declare(const std::vector<PublishedStatistic>& statistics, int joints) = 0;
  virtual void Values(double t_s, const double* values) = 0;
};

// Scoring's tap on the statistics behind a monitor's alarms. The runner makes one per run and
// calls AfterObserve() after every Observe(); the tap, not the monitor, knows the fault onset,
// and keeps what `armfault tune` needs to re-score other thresholds without simulating again.
class DecisionTap {
 public:
  virtual ~DecisionTap() = default;
  virtual void AfterObserve(double t_s) = 0;
  // The run's "decision" statistics (decisions.jsonl), in the monitor type's own format.
  virtual nlohmann::json Statistics() const = 0;
  // Why the run was scored as `score` when the truth is (family, joint) ("" when scored right;
  // family "" and joint 0 for a healthy run): the closest statistic, the gate that never opened.
  virtual std::string Explain(const RunScore& score, const std::string& family, int joint) const = 0;
  // Shows every statistic's value at every tick to `observer` (not owned; outlives the run, or
  // nullptr to stop): it gets Declare at once and Values per tick from then on.
  virtual void ShowStatistics(StatisticsObserver* observer) = 0;
};

// A health monitor in the loop: Observe() is called at every controller tick with every
// joint's signals, in time order; Finish() once at the end of the run. One instance per run,
// used by one thread at a time: a monitor needs no locks.
class HealthMonitor {
 public:
  virtual ~HealthMonitor() = default;
  virtual void Observe(double t_s, const std::vector<JointSignals>& joints) = 0;
  virtual void Finish(double t_end_s) = 0;
  virtual const MonitorOutput& output() const = 0;
  // Whether output().windows keeps every window (true, the default: trace, the report's run,
  // thesis) or none (false: a campaign's runs, whose scoring reads the verdicts only), so that a
  // campaign's run holds nothing that grows with its length. Called before the first
  // Observe(); a monitor that keeps no windows may ignore it.
  virtual void KeepWindows(bool keep) { (void)keep; }
  // A monitor that publishes the statistics behind its alarms returns a tap on them; nullptr
  // (the default): it is scored at its own operating point and `tune` cannot sweep it.
  virtual std::unique_ptr<DecisionTap> NewDecisionTap(double onset_s) const {
    (void)onset_s;
    return nullptr;
  }
};

}  // namespace armfault
