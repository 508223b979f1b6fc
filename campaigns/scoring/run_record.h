// One line of results.jsonl: the outcome of one run of a campaign. Written by the runner,
// read by the summary, merge and tuning. See docs/campaign-format.md, "results.jsonl". The
// run's decision statistics go to a line of their own in decisions.jsonl (DecisionLine), so
// results.jsonl stays about 1 kB a run for pandas and for people.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <optional>
#include <string>

namespace armfault {

struct RunRecord {
  long case_index = 0;        // position in the campaign's case order (0-based)
  std::string run_id;         // stable: "<trajectory>/<fault entry>/<values>/j<joint>/r<rep>" or "<trajectory>/healthy/<k>"
  std::string trajectory;     // the campaign trajectory's name
  // The injected fault as the faults library reads it ({"family", "joint", parameters...,
  // "onset_s", "profile", ...}); null for a healthy run.
  nlohmann::json fault;
  std::string family;         // fault family, "" for healthy
  int joint = 0;              // faulted joint (1-based), 0 for healthy
  double onset_s = 0;         // 0 for healthy
  std::string magnitude_key;  // the fault's parameter that sizes it ("kt_factor"...), "" if none
  double magnitude = 0;       // its value
  std::string group;          // family x parameters x joint, e.g. "kt_degradation kt_factor=0.9 joint=2"
  unsigned long long seed = 0;
  std::string engine = "ode";  // the engine that stepped the run (RobotConfig::engine: "ode", "articulated")
  int repetition = 0;
  nlohmann::json variation;   // what this run drew: payload, noise, friction factors
  bool ok = true;             // status "ok" / "failed"
  bool excited() const { return not_excited_reason.empty(); }
  std::string failure_reason;
  nlohmann::json effect;      // the fault's took-effect measure (FaultEffect::ToJson), null if healthy
  // Non-empty: the fault could not act on anything a monitor sees (NotExcitedReason); such a
  // run is listed apart and left out of the rates unless the campaign includes it.
  std::string not_excited_reason;
  // Monitor diagnosis (alarms from the fault's onset on; for healthy runs from t = 0).
  bool detected = false;
  std::optional<double> detection_time_s;
  std::optional<double> latency_s;       // detection_time_s - onset_s
  std::string isolated_family;           // "" if not detected
  int isolated_joint = 0;
  std::string magnitude_name;            // the monitor's magnitude ("kt_factor"...), "" if none
  std::optional<double> magnitude_estimate;
  double confidence = 0;
  bool alarm_before_onset = false;       // any alarm before the fault's onset (a false alarm)
  // Why a faulty run was missed or named the wrong family or joint, or why a healthy run
  // alarmed: the strongest statistic against its threshold, the gate that never opened, or
  // what won instead. "" for a run scored right.
  std::string miss_reason;
  // Seconds each joint's torque spent beyond its sensor's range (the reading held on its rail
  // while the true torque went further: saturation, plant truth), by joint number; only the
  // joints that saturated, and written only when any did ("sensor_saturated_s").
  std::map<int, double> sensor_saturated_s;
  // A conditional onset (the fault's "onset": {...}, faults/onset_condition.h): the time its
  // condition fired (onset_s is this + its delay_s), unset if it never fired; and, non-empty,
  // why the fault never acted (it never fired, or too late): such a run is "not injected",
  // neither a detection nor a miss, listed apart and left out of every rate. Written only for
  // a fault with a conditional onset, so other records are unchanged.
  bool conditional_onset = false;
  std::optional<double> onset_fired_s;
  std::string not_injected_reason;
  bool injected() const { return not_injected_reason.empty(); }
  // The monitor's decision statistics (DecisionStats JSON, core/monitors/detector_statistics.h): what
  // `armfault tune` re-scores thresholds from. Null for a run that could not be set up. Kept
  // in memory only: written to decisions.jsonl (DecisionLineJson), not by ToJson; read from
  // an older results.jsonl line that still carries it inline.
  nlohmann::json decision;
  // What the monitor's calls cost in this run (MonitorClock::ToJson, campaigns/running/monitor_cost.h):
  // a measurement, so in memory only, written to monitor_cost.jsonl. Null when not measured.
  nlohmann::json cost;
  // A compound fault (docs/campaign-format.md, "Compound faults"): family "compound", joint 0,
  // onset_s the earliest element's, and here one object per element: {"family", "joint",
  // "onset_s", "magnitude_key", "magnitude", "effect", "excited", "isolated",
  // "detection_time_s"}. Null (not written) for every other run.
  nlohmann::json compound;
  bool is_compound() const { return compound.is_array(); }
  // A recorded run with no fault label at all (an imported log: docs/monitor-api.md, "Replay"):
  // not known to be healthy nor faulty, so scored for false alarms only, as a healthy run is
  // (family ""). Written as "label": "unlabelled" only for such a run, so other records are
  // unchanged.
  bool unlabelled = false;
};

// Whether a detected run's first alarm named its fault: the family and joint of the fault, or
// for a compound run those of one of its elements.
bool IsolatedRight(const RunRecord& r);

// The results.jsonl line, without "decision".
nlohmann::json ToJson(const RunRecord& r);
// Throws std::runtime_error (with the key) if a required key is missing or has the wrong type.
// Accepts an older line with an inline "decision" (kept in `decision`).
RunRecord RunRecordFromJson(const nlohmann::json& j);

// One line of decisions.jsonl: {"case_index", "decision", "run_id"}, one per run, in the
// order of results.jsonl. "decision" is null for a run that could not be set up.
struct DecisionLine {
  long case_index = 0;
  std::string run_id;
  nlohmann::json decision;
};
nlohmann::json DecisionLineJson(const RunRecord& r);
// One line of monitor_cost.jsonl, with its line end: case, run_id and the run's cost ("ticks": 0
// without one).
std::string MonitorCostLine(const RunRecord& r);
// Throws std::runtime_error (with the key) if a key is missing or has the wrong type.
DecisionLine DecisionLineFromJson(const nlohmann::json& j);

}  // namespace armfault
