#include "core/run_config.h"

#include <filesystem>

#include <cmath>
#include <sstream>

#include "core/base/json_input.h"
#include "core/base/suggest.h"

namespace armfault {

JointMotionLimits MotionLimitsOf(const ModuleParams& m) {
  JointMotionLimits limits;
  limits.control_period_s = 1.0 / m.controller.rate_Hz;
  limits.max_speed_rad_s = m.inverter.bus_voltage_V / (m.motor.kt_Nm_per_A * m.drive.ratio);
  limits.max_acceleration_rad_s2 =
      m.motor.kt_Nm_per_A * m.inverter.command_limit_A / (m.motor.rotor_inertia_kg_m2 * m.drive.ratio);
  return limits;
}

void CheckMotionFeasible(const Trajectory& trajectory, const MotionEnvelope& envelope, const ModuleParams& m,
                         int joint, const std::string& pointer) {
  const std::string of_joint = "joint " + std::to_string(joint);
  const JointMotionLimits limits = MotionLimitsOf(m);
  const double shortest_s = trajectory.shortest_period_s();
  if (!(shortest_s >= kMinControlStepsPerPeriod * limits.control_period_s)) {
    throw InputError("", pointer, "a period of " + FormatNumber(shortest_s) + " s in the motion is shorter than " +
                                      FormatNumber(kMinControlStepsPerPeriod) + " control periods of " + of_joint +
                                      " (" + FormatNumber(kMinControlStepsPerPeriod * limits.control_period_s) +
                                      " s at " + FormatNumber(m.controller.rate_Hz) + " Hz)");
  }
  if (!envelope.finite) {
    throw InputError("", pointer, "the trajectory gives an angle, velocity or acceleration that is not a finite number");
  }
  const double lo = envelope.min_rad * 180 / M_PI, hi = envelope.max_rad * 180 / M_PI;
  if (lo < m.min_angle_deg || hi > m.max_angle_deg) {
    std::ostringstream msg;
    msg << "the trajectory spans [" << lo << ", " << hi << "] deg, beyond " << of_joint << "'s range ["
        << m.min_angle_deg << ", " << m.max_angle_deg << "] deg";
    throw InputError("", pointer, msg.str());
  }
  if (envelope.peak_speed_rad_s > limits.max_speed_rad_s) {
    throw InputError("", pointer, "the trajectory reaches " + FormatNumber(envelope.peak_speed_rad_s) +
                                      " rad/s, beyond " + of_joint + "'s no-load speed of " +
                                      FormatNumber(limits.max_speed_rad_s) +
                                      " rad/s (bus voltage / (K_T x gear ratio))");
  }
  if (envelope.peak_acceleration_rad_s2 > limits.max_acceleration_rad_s2) {
    throw InputError("", pointer, "the trajectory reaches " + FormatNumber(envelope.peak_acceleration_rad_s2) +
                                      " rad/s^2, beyond what " + of_joint + "'s motor can give its own rotor, " +
                                      FormatNumber(limits.max_acceleration_rad_s2) +
                                      " rad/s^2 (K_T x current limit / (rotor inertia x gear ratio))");
  }
}

std::map<int, std::shared_ptr<const Trajectory>> JointTrajectoriesFromJson(
    const nlohmann::json& joints, const std::string& pointer, const RobotConfig& robot, double duration_s,
    const InputContext& context) {
  if (!joints.is_object()) {
    throw InputError("", pointer, "expected an object mapping joint numbers to trajectories, got " + Describe(joints));
  }
  std::map<int, std::shared_ptr<const Trajectory>> out;
  const int n = static_cast<int>(robot.modules.size());
  ErrorList errors;  // each joint's trajectory on its own: all bad ones are reported
  for (auto it = joints.begin(); it != joints.end(); ++it) {
    errors.Try([&] {
      const std::string ptr = PointerJoin(pointer, it.key());
      // Canonical joint numbers only ("3", not "03" or " 3"), so no two keys name one joint.
      const std::string& key = it.key();
      const bool canonical = !key.empty() && key.size() <= 4 && key[0] >= '1' && key[0] <= '9' &&
                             key.find_first_not_of("0123456789") == std::string::npos;
      const int joint = canonical ? std::stoi(key) : 0;
      if (joint < 1 || joint > n) {
        throw InputError("", ptr, "\"" + it.key() + "\" is not a joint of robot " + robot.name + " (joints 1.." +
                                      std::to_string(n) + ")");
      }
      std::shared_ptr<const Trajectory> trajectory = MakeTrajectory(it.value(), ptr, context);
      CheckMotionFeasible(*trajectory, SampleMotion(*trajectory, duration_s), robot.modules[joint - 1], joint, ptr);
      out[joint] = std::move(trajectory);
    });
  }
  // A joint without a trajectory rests at 0: its range must hold it (a URDF joint's need not).
  for (int joint = 1; joint <= n; ++joint) {
    const ModuleParams& m = robot.modules[joint - 1];
    if (out.count(joint) || joints.contains(std::to_string(joint)) || (m.min_angle_deg <= 0 && 0 <= m.max_angle_deg)) continue;
    errors.Add(InputError("", pointer, "joint " + std::to_string(joint) + " has no trajectory and would rest at 0 deg, " +
                                           "outside its range [" + FormatNumber(m.min_angle_deg) + ", " +
                                           FormatNumber(m.max_angle_deg) + "] deg: give it one (a \"hold\" inside the range)"));
  }
  errors.ThrowIfAny();
  return out;
}

std::shared_ptr<const MonitorModel> MakeRunMonitor(const RunConfig& run) {
  MonitorContext context;
  context.robot = run.robot;
  context.input = run.input;
  return MakeMonitorModel(run.monitor, context);
}

ThermalStart ThermalStartFromJson(const nlohmann::json& value, const std::string& pointer) {
  if (!value.is_string()) {
    throw InputError("", pointer, "expected \"cold\" or \"warm\", got " + Describe(value));
  }
  const std::string mode = value.get<std::string>();
  if (mode == "cold") return ThermalStart::kCold;
  if (mode == "warm") return ThermalStart::kWarm;
  const std::string near = NearestWord(mode, {"cold", "warm"});
  throw InputError("", pointer, "unknown start " + Describe(value) + " (known: cold, warm)",
                   near.empty() ? "" : "did you mean \"" + near + "\"?");
}

RunConfig RunConfigFromJson(const nlohmann::json& value, const std::string& pointer, const InputContext& context) {
  try {
    ObjectReader reader(value, pointer);
    // Independent parts each on their own, so every error is reported; the joints' checks
    // need the robot and the duration and are skipped when either is bad.
    ErrorList errors;
    errors.Try([&] { reader.AllowOnly({"robot", "engine", "duration_s", "seed", "start", "joints", "faults", "monitor"}); });
    RunConfig run;
    run.input = context;
    const bool robot_ok = errors.Try([&] {
      if (const auto* robot = reader.Find("robot")) run.robot = RobotFromJson(*robot, reader.PointerTo("robot"), context.base_dir);
      else run.robot = RobotPreset("mrr-config1");
    });
    const bool duration_ok = errors.Try([&] {
      reader.OptionalNumber("duration_s", &run.duration_s);
      RequireInRange(run.duration_s, 0.002, 3600, reader.PointerTo("duration_s"));
    });
    errors.Try([&] {
      if (const auto* seed = reader.Find("seed")) {
        const double s = AsNumber(*seed, reader.PointerTo("seed"));
        if (s < 0 || s != std::floor(s) || s > 9007199254740991.0) {
          throw InputError("", reader.PointerTo("seed"), "expected a whole number >= 0, got " + Describe(*seed));
        }
        run.seed = static_cast<uint64_t>(s);
      }
    });
    errors.Try([&] {
      if (const auto* start = reader.Find("start")) run.start = ThermalStartFromJson(*start, reader.PointerTo("start"));
    });
    // The run's engine overrides the robot's (RobotConfig::engine).
    errors.Try([&] {
      if (const auto* engine = reader.Find("engine")) {
        const PhysicsEngine e = EngineFromJson(*engine, reader.PointerTo("engine"));
        if (robot_ok) {
          run.robot.engine = e;
          CheckEngineTakes(run.robot, reader.PointerTo("engine"));
        }
      }
    });
    if (const auto* joints = reader.Find("joints"); joints && robot_ok && duration_ok) {
      errors.Try([&] {
        run.trajectories = JointTrajectoriesFromJson(*joints, reader.PointerTo("joints"), run.robot, run.duration_s, context);
        run.trajectories_json = *joints;
      });
    }
    errors.Try([&] {
      if (const auto* faults = reader.Find("faults")) {
        if (!faults->is_array()) {
          throw InputError("", reader.PointerTo("faults"), "expected an array of faults, got " + Describe(*faults));
        }
        run.faults_json = *faults;
      }
    });
    errors.Try([&] {
      if (const auto* monitor = reader.Find("monitor")) {
        run.monitor = MonitorSpecFromJson(*monitor, reader.PointerTo("monitor"), context);
      }
    });
    errors.ThrowIfAny();
    return run;
  } catch (const InputError& e) {
    throw e.WithSource(context.source);  // fills in only the errors that name no file
  }
}

nlohmann::json ThesisExperiment1Json() {
  return {{"robot", "mrr-config1"},
          {"duration_s", 10},
          {"seed", 1},
          {"joints", {{"3", {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 8.0 / (2.0 * M_PI)}}}}}};
}

RunConfig ThesisExperiment1() {
  InputContext context;
  context.source = "<thesis experiment 1>";
  return RunConfigFromJson(ThesisExperiment1Json(), "", context);
}

RunSpec MakeRunSpec(const RunConfig& run) {
  RunSpec spec;
  spec.duration_s = run.duration_s;
  spec.seed = run.seed;
  spec.start = run.start;
  spec.joints.resize(run.robot.modules.size());
  for (const auto& [joint, trajectory] : run.trajectories) spec.joints[joint - 1].trajectory = trajectory;
  return spec;
}

}  // namespace armfault
