// Cost of one simulated run against bare ODE stepping of the same bodies and joints.
//   build/armfault_bench --benchmark_min_time=2
// Goal (plant issue): a full 10 s run of mrr-config1 costs at most 1.5x the bare stepping.
#include <benchmark/benchmark.h>

#include "core/monitors/monitor.h"
#include "core/plant/ode_runtime.h"
#include "core/monitors/power_monitor.h"
#include "core/observe.h"
#include "core/run_config.h"
#include "core/plant/simulation.h"

namespace armfault {
namespace {

// Bodies (links and rotors), hinges and the rotors' gears only.
void BM_BareOdeStepping10s(benchmark::State& state) {
  const ArmModel model(RobotPreset("mrr-config1"));
  for (auto _ : state) benchmark::DoNotOptimize(StepBareOde(model, 10.0, false));
}
BENCHMARK(BM_BareOdeStepping10s)->Unit(benchmark::kMillisecond);

// The same with the rotors' dry-friction rows a run adds (a bounded LCP).
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

// The same run with the power-efficiency monitor in the loop.
void BM_FullRunWithMonitorExperiment1_10s(benchmark::State& state) {
  const RunConfig run = ThesisExperiment1();
  const ArmModel model(run.robot);
  const RunSpec spec = MakeRunSpec(run);
  const std::shared_ptr<const MonitorModel> monitor_model = MakeRunMonitor(run);
  for (auto _ : state) {
    const std::unique_ptr<HealthMonitor> monitor = monitor_model->NewMonitor();
    benchmark::DoNotOptimize(Simulate(model, spec, ObserveWith(monitor.get())).ok);
  }
}
BENCHMARK(BM_FullRunWithMonitorExperiment1_10s)->Unit(benchmark::kMillisecond);

// The monitor alone, replaying the recorded signals of experiment 1 (5001 ticks x 3 joints):
// its own cost; items are controller ticks (all joints), so 1 / items_per_second is the
// cost per tick.
void BM_MonitorOnlyPerTick(benchmark::State& state) {
  const RunConfig run = ThesisExperiment1();
  const ArmModel model(run.robot);
  std::vector<double> times;
  std::vector<std::vector<JointSignals>> signals;
  Simulate(model, MakeRunSpec(run), [&](const Tick& tick) {
    times.push_back(tick.t_s);
    std::vector<JointSignals> s;
    for (const JointTick& j : *tick.joints) s.push_back(j.signals);
    signals.push_back(s);
  });
  const std::shared_ptr<const MonitorModel> monitor_model = MakeRunMonitor(run);
  for (auto _ : state) {
    const std::unique_ptr<HealthMonitor> monitor = monitor_model->NewMonitor();
    for (size_t k = 0; k < times.size(); ++k) monitor->Observe(times[k], signals[k]);
    monitor->Finish(times.back());
    benchmark::DoNotOptimize(monitor->output().windows.size());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(times.size()));
}
BENCHMARK(BM_MonitorOnlyPerTick)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace armfault

int main(int argc, char** argv) {
  armfault::InitOde();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
