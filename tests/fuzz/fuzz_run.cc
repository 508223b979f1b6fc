// Fuzz target: a run file's text (`armfault trace RUN.json`), read by RunConfigFromJson (robot,
// duration, seed, trajectories checked against the joints' ranges, monitor), its faults made
// for its robot (MakeFaults) and its monitor built (MakeRunMonitor); then, when all of that
// passed, the run's first 0.02 s simulated with its robot and trajectories (no faults), so a
// trajectory that parses but makes ODE assert (a period of 5e-324 s) is found. Inputs that
// mention "plugin" are skipped (fuzz_common.h).
#include <algorithm>

#include "core/observe.h"
#include "core/run_config.h"
#include "faults/fault.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  return fuzz::RejectCleanly([&] {
    const nlohmann::json value = ParseJsonText(fuzz::Text(data, size), fuzz::kSource);
    if (fuzz::MentionsPlugin(value)) return;
    const InputContext input = fuzz::Context();
    const RunConfig run = RunConfigFromJson(value, "", input);
    MakeFaults(run.faults_json, "/faults", run.robot);
    const auto monitor_model = MakeRunMonitor(run);  // outlives its monitor, which borrows it
    const auto monitor = monitor_model->NewMonitor();
    RunSpec spec = MakeRunSpec(run);
    spec.duration_s = std::min(spec.duration_s, 0.02);
    const ArmModel model(run.robot);
    const RunResult result = Simulate(model, spec, ObserveWith(monitor.get()));
    monitor->Finish(result.end_time_s);
  });
}
