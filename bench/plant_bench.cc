// Cost of one simulated run against bare ODE stepping of the same bodies and joints.
//   build/armfault_bench --benchmark_min_time=2
// Goal (plant issue): a full 10 s run of mrr-config1 costs at most 1.5x the bare stepping.
#include <benchmark/benchmark.h>

#include "core/ode_runtime.h"
#include "core/run_config.h"
#include "core/simulation.h"

namespace armfault {
namespace {

// Bodies and hinges only.
void BM_BareOdeStepping10s(benchmark::State& state) {
  const ArmModel model(RobotPreset("mrr-config1"));
  for (auto _ : state) benchmark::DoNotOptimize(StepBareOde(model, 10.0, false));
}
BENCHMARK(BM_BareOdeStepping10s)->Unit(benchmark::kMillisecond);

// Bodies and hinges with the dry-friction rows a run adds (a bounded LCP).
void BM_BareOdeSteppingWithFrictionRows10s(benchmark::State& state) {
  const ArmModel model(RobotPreset("mrr-config1"));
  for (auto _ : state) benchmark::DoNotOptimize(StepBareOde(model, 10.0, true));
}
BENCHMARK(BM_BareOdeSteppingWithFrictionRows10s)->Unit(benchmark::kMillisecond);

void BM_FullRunExperiment1_10s(benchmark::State& state) {
  const RunConfig run = ThesisExperiment1();
  const ArmModel model(run.robot);
  const RunSpec spec = MakeRunSpec(run);
  for (auto _ : state) benchmark::DoNotOptimize(Simulate(model, spec, nullptr).ok);
}
BENCHMARK(BM_FullRunExperiment1_10s)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace armfault

int main(int argc, char** argv) {
  armfault::InitOde();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
