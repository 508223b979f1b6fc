// Fuzz target: a robot object's text ("robot": {...} of a run or campaign file, or a preset's
// name), read by RobotFromJson and built into an ArmModel, then, when it parsed, simulated for
// 0.02 s with every joint holding its start under control and the default monitor watching.
// Inputs that parse but make ODE assert (which aborts the process) are the bug class this
// target is for: a robot must be rejected with an InputError before ODE sees it.
#include "core/monitors/registry.h"
#include "core/observe.h"
#include "core/plant/robot/robot_config.h"
#include "core/plant/simulation.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  return fuzz::RejectCleanly([&] {
    const nlohmann::json value = ParseJsonText(fuzz::Text(data, size), fuzz::kSource);
    const RobotConfig robot = RobotFromJson(value, "/robot");
    const ArmModel model(robot);
    MonitorContext context;
    context.robot = robot;
    const auto monitor_model = MakeMonitorModel(MonitorSpec{}, context);
    const auto monitor = monitor_model->NewMonitor();
    RunSpec spec;
    spec.duration_s = 0.02;
    const RunResult result = Simulate(model, spec, ObserveWith(monitor.get()));
    monitor->Finish(result.end_time_s);
  });
}
