#include "core/run_config.h"

#include <filesystem>

#include <cmath>
#include <sstream>

#include "core/base/json_input.h"

namespace armfault {

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
      const ModuleParams& m = robot.modules[joint - 1];
      const AngleRange range = SampleRange(*trajectory, duration_s);
      const double lo = range.min_rad * 180 / M_PI, hi = range.max_rad * 180 / M_PI;
      if (lo < m.min_angle_deg || hi > m.max_angle_deg) {
        std::ostringstream msg;
        msg << "the trajectory spans [" << lo << ", " << hi << "] deg, beyond joint " << joint << "'s range ["
            << m.min_angle_deg << ", " << m.max_angle_deg << "] deg";
        throw InputError("", ptr, msg.str());
      }
      out[joint] = std::move(trajectory);
    });
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

RunConfig RunConfigFromJson(const nlohmann::json& value, const std::string& pointer, const InputContext& context) {
  try {
    ObjectReader reader(value, pointer);
    // Independent parts each on their own, so every error is reported; the joints' checks
    // need the robot and the duration and are skipped when either is bad.
    ErrorList errors;
    errors.Try([&] { reader.AllowOnly({"robot", "duration_s", "seed", "joints", "faults", "monitor"}); });
    RunConfig run;
    run.input = context;
    const bool robot_ok = errors.Try([&] {
      if (const auto* robot = reader.Find("robot")) run.robot = RobotFromJson(*robot, reader.PointerTo("robot"));
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
  spec.joints.resize(run.robot.modules.size());
  for (const auto& [joint, trajectory] : run.trajectories) spec.joints[joint - 1].trajectory = trajectory;
  return spec;
}

}  // namespace armfault
