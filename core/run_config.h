// One run as data: the robot, a duration, a seed and a reference trajectory per joint.
// JSON shape (the same "joints" object as a campaign's trajectories):
//   {"robot": "mrr-config1", "duration_s": 10, "seed": 1,
//    "joints": {"3": {"type": "sine_pair", "amplitude_deg": 25, "omega_rad_s": 1.2732}}}
// Optional "start": "cold" (default: every thermal node at ambient) or "warm" (at the steady
// state of each drive's stated duty, core/plant/parts/gear_thermal.h).
// Joints are numbered from 1 at the base; a joint without a trajectory holds its angle.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <memory>
#include <string>

#include "core/monitors/registry.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/simulation.h"
#include "core/plant/motion/trajectory.h"

namespace armfault {

struct RunConfig {
  RobotConfig robot;
  double duration_s = 10.0;
  uint64_t seed = 1;
  ThermalStart start = ThermalStart::kCold;  // "start": "cold" | "warm" (core/plant/simulation.h)
  std::map<int, std::shared_ptr<const Trajectory>> trajectories;  // key: joint number (1-based)
  nlohmann::json trajectories_json = nlohmann::json::object();    // as given, for records
  // "faults": kept as given; the faults library (which core does not depend on) builds them.
  nlohmann::json faults_json = nlohmann::json::array();
  MonitorSpec monitor;  // "monitor": a monitor type and its settings, or a JSON file of them
  InputContext input;   // the run file: a monitor that does not build (a plugin) names it
};

// The monitor a run file names, built for its robot (no tolerances stated, no commissioning).
std::shared_ptr<const MonitorModel> MakeRunMonitor(const RunConfig& run);

// What a joint's hardware can follow at most, from its datasheet values (docs/campaign-format.md):
// the control period [s]; the no-load speed [rad/s, link side], where the line back-EMF
// K_T omega_m equals the bus voltage: U_d / (K_T N); the acceleration [rad/s^2, link side] the
// motor gives its own rotor alone at the current limit, K_T I_max / (J_rotor N): no link,
// gravity or friction, so no real joint reaches it.
struct JointMotionLimits {
  double control_period_s = 0;
  double max_speed_rad_s = 0;
  double max_acceleration_rad_s2 = 0;
};
JointMotionLimits MotionLimitsOf(const ModuleParams& module);

// Throws InputError at `pointer` when a joint's trajectory is not a motion its hardware can
// follow: a non-finite sample, a period shorter than kMinControlStepsPerPeriod control periods,
// an angle outside the joint's range, a speed or an acceleration beyond MotionLimitsOf().
void CheckMotionFeasible(const Trajectory& trajectory, const MotionEnvelope& envelope, const ModuleParams& module,
                         int joint, const std::string& pointer);

// Parses the "joints" object of a run or campaign trajectory and checks each trajectory
// over [0, duration_s] with CheckMotionFeasible. Throws InputError with JSON pointers.
std::map<int, std::shared_ptr<const Trajectory>> JointTrajectoriesFromJson(
    const nlohmann::json& joints, const std::string& pointer, const RobotConfig& robot, double duration_s,
    const InputContext& context);

// "start": "cold" | "warm" at `pointer`; anything else throws InputError (with "did you mean").
ThermalStart ThermalStartFromJson(const nlohmann::json& value, const std::string& pointer);

RunConfig RunConfigFromJson(const nlohmann::json& value, const std::string& pointer, const InputContext& context);

// Thesis experiment 1: mrr-config1, the top joint on sine_pair 25 deg at 8/(2 pi) rad/s, 10 s.
RunConfig ThesisExperiment1();
nlohmann::json ThesisExperiment1Json();

// The RunSpec for Simulate(): trajectories in joint order.
RunSpec MakeRunSpec(const RunConfig& run);

}  // namespace armfault
