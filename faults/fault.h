// Fault injection: a fault is a change to the simulated hardware (a HardwareCondition of one
// joint) over time, never to the monitor.
//
// One family = one file in faults/ implementing Fault + one line in the table in registry.cc.
// Dependencies go one way: registry.cc (the table, and what reads it: MakeFault, the
// Fault* queries by family, NotExcitedReason) uses the family files, and both use the shared
// pieces (fault.cc, onset_condition.cc, family_support.h), which never call back into the table.
// JSON shape (campaign files, run files, `armfault trace --fault`):
//   {"family": "kt_degradation", "joint": 3, "kt_factor": 0.6,
//    "onset_s": 2.0, "profile": "abrupt" | "incipient" | "intermittent",
//    "ramp_s": 2.0 (incipient), "period_s": 1.0, "duty": 0.5 (intermittent)}
// Joints are numbered from 1 at the base.
#pragma once

#include <nlohmann/json.hpp>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/plant/parts/hardware_condition.h"
#include "core/base/json_input.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/simulation.h"
#include "faults/onset_condition.h"

namespace armfault {

enum class FaultProfile { kAbrupt, kIncipient, kIntermittent };

// When and how strongly a fault acts: Severity() is the fraction of the full magnitude.
//   abrupt:       1 from onset_s on;
//   incipient:    rises linearly from 0 at onset_s to 1 at onset_s + ramp_s;
//   intermittent: 1 during the first duty x period_s of every period_s from onset_s, else 0.
// Discrete faults (a stuck lead, a short) are present while the severity is at least 0.5.
// A conditional onset ("onset": {...}, faults/onset_condition.h) has onset_s = +infinity (the
// fault never acts) until it fires: then fired_s is the fire time and onset_s = fired_s +
// its delay_s, and the profile runs from there as for any onset.
struct FaultTiming {
  double onset_s = 0.0;
  std::shared_ptr<const OnsetCondition> condition;  // null: onset_s as given
  double fired_s = std::numeric_limits<double>::quiet_NaN();  // the condition's fire time, NaN before
  FaultProfile profile = FaultProfile::kAbrupt;
  double ramp_s = 1.0;
  double period_s = 1.0;
  double duty = 0.5;
  double Severity(double t_s) const;
};

// Plant-level evidence that a fault changed the hardware, measured from the simulator's
// truth (never from the monitor): the measure on the healthy plant and under the fault.
struct FaultEffect {
  std::string measure;        // e.g. "torque_per_ampere_Nm_per_A"
  double healthy = 0.0;       // before onset, or the healthy plant's value
  double faulty = 0.0;        // after onset
  bool took_effect = false;   // false: reported as "no effect", never silently counted
  std::string note;           // why not, when there was no effect
  bool measured = true;       // false: too few informative samples after the onset to judge
  // How far the faulted joint's reference moved from the onset on: the motion asked of it (a
  // locked brake stops the joint itself).
  double joint_travel_rad = 0.0;
  nlohmann::json ToJson() const;
};

// A faulted joint whose reference moved less than this from the onset on counts as still.
constexpr double kMinTravelToExcite_rad = 0.05;  // about 3 degrees

// Watches the ticks of the faulted joint during a run and judges the effect at the end.
class EffectMeter {
 public:
  virtual ~EffectMeter() = default;
  virtual void Observe(double t_s, const JointTick& joint) = 0;
  virtual FaultEffect Result() const = 0;
};

class Fault {
 public:
  Fault(std::string family, int joint_index, FaultTiming timing)
      : family_(std::move(family)), joint_index_(joint_index), timing_(timing) {}
  virtual ~Fault() = default;

  const std::string& family() const { return family_; }
  int joint_index() const { return joint_index_; }  // 0-based
  const FaultTiming& timing() const { return timing_; }

  // Changes `condition` for a severity in (0, 1] at time t_s; composes with other faults on
  // the same joint (factors multiply, drags add).
  virtual void Apply(double severity, double t_s, HardwareCondition* condition) const = 0;
  // The family's own parameters as written in JSON (e.g. {"kt_factor": 0.6}).
  virtual nlohmann::json Parameters() const = 0;
  virtual std::unique_ptr<EffectMeter> MakeEffectMeter(const JointModel& joint) const = 0;

  // The whole fault as JSON, in the input shape.
  nlohmann::json ToJson() const;
  // A conditional onset fired at fired_s: the fault acts from fired_s + the condition's delay_s.
  void FireOnset(double fired_s);

 private:
  std::string family_;
  int joint_index_;
  FaultTiming timing_;
};

// Builds one fault from JSON, checking it against the robot (joint exists, values in range).
// Throws InputError naming the family, the JSON pointer and the value.
std::unique_ptr<Fault> MakeFault(const nlohmann::json& spec, const std::string& pointer, const RobotConfig& robot);
std::vector<std::unique_ptr<Fault>> MakeFaults(const nlohmann::json& specs, const std::string& pointer,
                                               const RobotConfig& robot);
std::vector<std::string> FaultFamilyNames();
// The parameter that sizes a fault of `family` ("kt_factor" ...), "" if none or unknown.
std::string FaultMagnitudeKey(const std::string& family);
// The values a family's magnitude may take: [min, max], min itself excluded when min_exclusive,
// 0 excluded when zero_excluded (a drift of 0 is no drift).
struct FaultMagnitudeRange {
  double min = 0, max = 0;
  bool min_exclusive = false;
  bool zero_excluded = false;
};
// The range of `family`'s magnitude; false for a family without one (or unknown).
bool FaultMagnitudeRangeOf(const std::string& family, FaultMagnitudeRange* range);
// The range as docs/faults.md writes it: "0 < `kt_factor` ≤ 1", "−100 ≤ `drift_Nm_per_s` ≤ 100, ≠ 0";
// "" for a family without one.
std::string FaultMagnitudeRangeText(const std::string& family);
// The unit of a magnitude key ("kt_factor": "× nominal K_T"), "" if unknown.
std::string FaultMagnitudeUnit(const std::string& magnitude_key);
// Severity of a magnitude, the distance from healthy (> 0) in which detection should rise, by
// the family that `magnitude_key` sizes: 1 - kt_factor, friction_factor - 1,
// resistance_factor - 1, 1 / resistance_ohm (a short's conductance), drag_fraction,
// drift_Nm_per_s (an unknown key: the magnitude itself); and back.
double FaultSeverity(const std::string& magnitude_key, double magnitude);
double FaultMagnitudeOfSeverity(const std::string& magnitude_key, double severity);
// The family's colour in the report's plots ("#1f77b4"), "" for an unknown family.
std::string FaultFamilyColor(const std::string& family);
// True when the family's signature needs its joint to move: friction and brake drag act only
// in motion, and on a still joint a K_T loss shows only as another holding current, which an
// unknown payload explains as well. A stuck sensor, a short, a drift show at rest.
bool FaultNeedsMotion(const std::string& family);
// True for the families that are present or absent (a stuck lead, a short) rather than graded
// by a magnitude: for them "no effect" means the fault could not act, while a graded fault
// with a small effect is simply small (and missing it is a miss).
bool FaultIsDiscrete(const std::string& family);

// Why a run's fault could not be seen by any monitor ("" when it could): its joint was left
// still although its signature needs motion, its effect had nothing to act on (too few
// informative samples after the onset), or a discrete fault took no effect.
std::string NotExcitedReason(const Fault& fault, const FaultEffect& effect);

// Resolves the conditional onsets among `faults` (timing().condition, not yet fired) by
// simulating `run` with the faults acting (run.hardware is replaced): each condition is
// watched on the plant's truth at every controller tick and FireOnset is called at the first
// tick it holds; one that never holds stays unfired (the fault never acts). The simulation is
// deterministic and a fault does nothing before its onset, so the real run, with the resolved
// onsets, passes through the same states and its conditions fire at the same ticks. A pass
// stops at the earliest onset it found; a condition that fired after it is watched again in
// a further pass with that fault acting. Returns the passes simulated (0 when none is pending).
int ResolveConditionalOnsets(const ArmModel& model, const RunSpec& run, const std::vector<Fault*>& faults);
// Why a fault with a conditional onset never acted in a run that ended at end_s ("" when it
// did, or when its onset is not conditional): its condition never fired, or it fired so late
// that fire time + delay_s is after the end.
std::string NotInjectedReason(const Fault& fault, double end_s);

// All faults of a run as the plant's hardware schedule.
class FaultSchedule : public HardwareSchedule {
 public:
  explicit FaultSchedule(std::vector<std::shared_ptr<const Fault>> faults) : faults_(std::move(faults)) {}
  void Apply(double t_s, std::vector<HardwareCondition>* conditions) const override;
  const std::vector<std::shared_ptr<const Fault>>& faults() const { return faults_; }

 private:
  std::vector<std::shared_ptr<const Fault>> faults_;
};

// Observes a run's ticks with one meter per fault; Results() in fault order.
class EffectRecorder {
 public:
  EffectRecorder(const ArmModel& model, const std::vector<std::shared_ptr<const Fault>>& faults);
  void Observe(const Tick& tick);
  std::vector<FaultEffect> Results() const;

 private:
  std::vector<int> joints_;
  std::vector<double> onsets_s_;
  std::vector<double> travel_rad_;  // per fault: its joint's travel from the onset on
  double last_t_s_ = -1;
  std::vector<std::unique_ptr<EffectMeter>> meters_;
};

}  // namespace armfault
