// Reference trajectories for one joint, link side. One trajectory type = one file in
// core/plant/motion/ implementing Trajectory + one line in the table in trajectory.cc.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

#include "core/base/json_input.h"  // InputContext

namespace armfault {

// Reference for one joint at one instant: angle [rad], velocity [rad/s], acceleration [rad/s^2].
struct TrajectoryPoint {
  double q_rad = 0.0;
  double qd_rad_s = 0.0;
  double qdd_rad_s2 = 0.0;
};

// A reference q(t) of one joint; immutable once built and safe to share between threads.
class Trajectory {
 public:
  virtual ~Trajectory() = default;
  // Reference at time t_s [s] since the start of the run; defined for every t_s >= 0
  // (before the first or after the last sample, trajectories hold their end value).
  virtual TrajectoryPoint At(double t_s) const = 0;
  // The type name as written in JSON ("sine_pair", ...).
  virtual const char* type() const = 0;
  // The period [s] of the fastest periodic component of the motion (infinity if none), checked
  // against the control period: a reference the controller samples fewer than
  // kMinControlStepsPerPeriod times per period is not a motion it can follow.
  virtual double shortest_period_s() const;
};

inline constexpr double kMinControlStepsPerPeriod = 10;

// Builds a trajectory from its JSON object ({"type": "...", ...}). `pointer` is the JSON
// pointer of that object, used in errors. Throws InputError for an unknown type, unknown or
// missing keys, values out of range, or a malformed CSV file.
std::unique_ptr<Trajectory> MakeTrajectory(const nlohmann::json& spec, const std::string& pointer,
                                           const InputContext& context);

// The registered type names, in table order (for help texts and the JSON schema).
std::vector<std::string> TrajectoryTypeNames();

// What a trajectory demands over [0, duration_s], sampled every 1 ms (and at the end): the
// extremes of q_rad and the peaks of |qd| and |qdd|. `finite` is false if any sample of q, qd
// or qdd was not a finite number (the extremes then cover only the finite samples).
struct MotionEnvelope {
  double min_rad = 0.0;
  double max_rad = 0.0;
  double peak_speed_rad_s = 0.0;
  double peak_acceleration_rad_s2 = 0.0;
  bool finite = true;
};
MotionEnvelope SampleMotion(const Trajectory& trajectory, double duration_s);

}  // namespace armfault
