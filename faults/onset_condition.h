// Conditional onsets (docs/campaign-format.md, "Conditional onsets"): a fault's onset given as a
// condition on the plant's truth, which the monitor never sees, instead of a time:
//   "onset": {"when": "joint_velocity_above", "joint": 2, "rad_s": 0.5}
//   "onset": {"when": "joint_position_crosses", "joint": 2, "deg": 10, "direction": "rising"}
//   "onset": {"when": "after_reversals", "joint": 2, "count": 3}
// each with optional "delay_s" (>= 0) and "not_before_s" (>= 0). The condition is watched at
// every controller tick from not_before_s on and fires once; the fault then acts exactly as if
// its onset_s were the fire time + delay_s (profiles unchanged).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "core/plant/robot/robot_config.h"
#include "core/plant/simulation.h"

namespace armfault {

enum class OnsetWhen { kJointVelocityAbove, kJointPositionCrosses, kAfterReversals };

// Default deadband of after_reversals: the true velocity must pass this far beyond zero for
// its sign to change, so the dither of a joint at rest does not count as reversals.
constexpr double kDefaultReversalDeadband_rad_s = 0.02;

struct OnsetCondition {
  OnsetWhen when = OnsetWhen::kJointVelocityAbove;
  int joint_index = 0;            // 0-based
  double rad_s = 0;               // joint_velocity_above: |true velocity| > rad_s
  double position_rad = 0;        // joint_position_crosses: the value crossed
  int direction = 0;              // joint_position_crosses: +1 rising, -1 falling, 0 either
  int count = 1;                  // after_reversals: the count-th reversal
  double deadband_rad_s = kDefaultReversalDeadband_rad_s;  // after_reversals
  double delay_s = 0;             // the onset is the fire time + delay_s
  double not_before_s = 0;        // ticks before this are not watched
  nlohmann::json input;           // as written (the record's fault shows it so)
  // One line for messages: "joint 2's |velocity| above 0.5 rad/s".
  std::string Text() const;
};

// Reads an "onset" object (at `pointer`, e.g. "/faults/0/onset") against the robot; throws an
// InputError listing every error (unknown "when" or key, a joint the robot lacks, missing or
// out-of-range values), each naming its JSON pointer and value.
OnsetCondition ReadOnsetCondition(const nlohmann::json& value, const std::string& pointer, const RobotConfig& robot);

// Watches one condition tick by tick on the truth of its joint (JointTick::q_rad, qd_rad_s).
class OnsetWatcher {
 public:
  explicit OnsetWatcher(const OnsetCondition& condition) : c_(condition) {}
  // True at the first tick the condition holds (and never again).
  bool Observe(double t_s, const JointTick& joint);
  bool fired() const { return fired_; }

 private:
  const OnsetCondition& c_;
  bool fired_ = false;
  bool has_previous_ = false;
  double previous_q_rad_ = 0;
  int sign_ = 0;  // after_reversals: the velocity's sign beyond the deadband, 0 before it first left it
  int reversals_ = 0;
};

}  // namespace armfault
