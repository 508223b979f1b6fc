// The plugin path's cost per run (docs/monitor-api.md, "C plugin"): one healthy 8-s
// run of tests/core/monitors/data/plugin_campaign.json (exp1, mrr-config1, 4001 ticks x 3
// joints) with the built-in power-efficiency monitor, with a no-op C plugin (the call path
// alone: signals copied to C structs, step and verdicts called at every tick) and with the
// example C plugin; then each monitor alone on that run's recorded signals.
//   build/armfault_plugin_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Goal: the example plugin adds less than 5 % to a run over the built-in path.
#include <benchmark/benchmark.h>

#include "campaigns/spec/campaign.h"
#include "campaigns/running/runner.h"
#include "core/monitors/monitor.h"

namespace armfault {
namespace {

const char* const kMonitorNames[] = {"builtin", "noop_plugin", "example_plugin"};

// The campaign with monitor `which` (an index into kMonitorNames).
Campaign WithMonitor(int which) {
  const std::string path = std::string(ARMFAULT_SOURCE_DIR) + "/tests/core/monitors/data/plugin_campaign.json";
  nlohmann::json campaign = ReadJsonFile(path);
  if (which == 0) campaign["monitor"] = nlohmann::json::object();
  if (which == 1) campaign["monitor"] = {{"type", "plugin"}, {"library", ARMFAULT_NOOP_PLUGIN}};
  if (which == 2) campaign["monitor"] = {{"type", "plugin"}, {"library", ARMFAULT_EXAMPLE_PLUGIN}};
  return CampaignFromJson(campaign, path, ".");
}

// The first healthy run (exp1: joint 3 moves).
CaseSpec Healthy(const Campaign& c) {
  for (const CaseSpec& s : ExpandCases(c)) {
    if (s.fault.is_null()) return s;
  }
  return {};
}

void BM_Run(benchmark::State& state) {
  const Campaign c = WithMonitor(static_cast<int>(state.range(0)));
  const CaseSpec spec = Healthy(c);
  state.SetLabel(kMonitorNames[state.range(0)]);
  for (auto _ : state) {
    const RunRecord r = RunCase(c, spec);
    if (!r.ok) state.SkipWithError(r.failure_reason.c_str());
    benchmark::DoNotOptimize(r.detected);
  }
}
BENCHMARK(BM_Run)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

// The monitor alone on the run's recorded signals; items are ticks (all joints).
void BM_MonitorOnly(benchmark::State& state) {
  const Campaign c = WithMonitor(static_cast<int>(state.range(0)));
  const CaseSpec spec = Healthy(c);
  std::vector<double> times;
  std::vector<std::vector<JointSignals>> signals;
  RunCase(c, spec, [&](const Tick& tick) {
    times.push_back(tick.t_s);
    std::vector<JointSignals> s;
    for (const JointTick& j : *tick.joints) s.push_back(j.signals);
    signals.push_back(std::move(s));
  });
  state.SetLabel(kMonitorNames[state.range(0)]);
  for (auto _ : state) {
    const std::unique_ptr<HealthMonitor> m = c.monitor_model->NewMonitor();
    for (size_t k = 0; k < times.size(); ++k) m->Observe(times[k], signals[k]);
    m->Finish(times.back());
    benchmark::DoNotOptimize(m->output().verdicts.size());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * times.size()));
}
BENCHMARK(BM_MonitorOnly)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace armfault

BENCHMARK_MAIN();
