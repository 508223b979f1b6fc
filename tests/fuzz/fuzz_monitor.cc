// Fuzz target: a monitor file's text ("monitor": "file.json", or the "monitor" object of a run
// or campaign file), read by MonitorSpecFromJson and built by MakeMonitorModel for the
// thesis's robot (mrr-config1) as a run file builds it, then fed 0.5 s of recorded signals of
// a healthy thesis run (one simulation, made once) and finished. Inputs that mention "plugin"
// are skipped (fuzz_common.h).
#include <vector>

#include "core/monitors/registry.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/simulation.h"
#include "core/plant/motion/trajectory.h"
#include "tests/fuzz/fuzz_common.h"

namespace {

struct Recording {
  std::vector<double> t_s;
  std::vector<std::vector<armfault::JointSignals>> joints;
};

// 0.5 s of mrr-config1 with its top joint on the thesis's sine (25 deg, 8/(2 pi) rad/s).
const Recording& HealthyRecording() {
  static const Recording recording = [] {
    using namespace armfault;
    Recording r;
    const ArmModel model(RobotPreset("mrr-config1"));
    RunSpec spec;
    spec.duration_s = 0.5;
    spec.joints.resize(model.joint_count());
    spec.joints.back().trajectory = MakeTrajectory(
        {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1.2732}}, "", InputContext{});
    Simulate(model, spec, [&](const Tick& tick) {
      r.t_s.push_back(tick.t_s);
      std::vector<JointSignals> signals;
      for (const JointTick& j : *tick.joints) signals.push_back(j.signals);
      r.joints.push_back(std::move(signals));
    });
    return r;
  }();
  return recording;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  const Recording& recording = HealthyRecording();
  return fuzz::RejectCleanly([&] {
    const nlohmann::json value = ParseJsonText(fuzz::Text(data, size), fuzz::kSource);
    if (fuzz::MentionsPlugin(value)) return;
    const InputContext input = fuzz::Context();
    const MonitorSpec spec = MonitorSpecFromJson(value, "", input);
    MonitorContext context;
    context.robot = RobotPreset("mrr-config1");
    context.input = input;
    const auto model = MakeMonitorModel(spec, context, "");
    const auto monitor = model->NewMonitor();
    for (size_t k = 0; k < recording.t_s.size(); ++k) monitor->Observe(recording.t_s[k], recording.joints[k]);
    monitor->Finish(recording.t_s.empty() ? 0 : recording.t_s.back());
  });
}
