// Fuzz target: a run file's text (`armfault trace RUN.json`), read by RunConfigFromJson (robot,
// duration, seed, trajectories checked against the joints' ranges, monitor), its faults made
// for its robot (MakeFaults) and its monitor built (MakeRunMonitor), without simulating (the
// robot target simulates). Inputs that mention "plugin" are skipped (fuzz_common.h).
#include "core/run_config.h"
#include "faults/fault.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace armfault;
  return fuzz::RejectCleanly([&] {
    const nlohmann::json value = ParseJsonText(fuzz::Text(data, size), fuzz::kSource);
    if (fuzz::MentionsPlugin(value)) return;
    InputContext input;
    input.source = fuzz::kSource;
    input.base_dir = fuzz::kNoDir;
    const RunConfig run = RunConfigFromJson(value, "", input);
    MakeFaults(run.faults_json, "/faults", run.robot);
    MakeRunMonitor(run);
    MakeRunSpec(run);
  });
}
