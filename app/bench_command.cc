// `armfault bench`: the cost of a full run against bare ODE stepping of the same arm, and
// campaign throughput with one thread and with all cores.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <time.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <functional>
#include <limits>

#include "app/commands.h"
#include "campaigns/campaign.h"
#include "campaigns/runner.h"
#include "core/monitors/detector_statistics.h"
#include "core/monitors/power_monitor.h"
#include "core/plant/simulation.h"

namespace armfault {

namespace {

double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The least CPU time of each workload over `repeats` rounds, the workloads taking turns within
// a round: on a shared machine other jobs only ever add time, so the minimum is the cost, and
// taking turns exposes every workload to the same load.
template <size_t N>
std::array<double, N> LeastCpuSeconds(int repeats, const std::array<std::function<void()>, N>& workloads) {
  std::array<double, N> least;
  least.fill(std::numeric_limits<double>::infinity());
  for (const auto& w : workloads) w();  // warm-up
  for (int r = 0; r < repeats; ++r) {
    for (size_t k = 0; k < N; ++k) {
      const double start = ThreadCpuSeconds();
      workloads[k]();
      least[k] = std::min(least[k], ThreadCpuSeconds() - start);
    }
  }
  return least;
}

}  // namespace

int BenchCommand(int repeats) {
  const Campaign campaign = DefaultCampaign();
  const std::vector<CaseSpec> cases = ExpandCases(campaign);
  const ArmModel model(campaign.robot);
  const CaseSpec& healthy = cases.back();
  const auto [bare, bare_rows, full] = LeastCpuSeconds<3>(
      repeats, {[&] { StepBareOde(model, campaign.duration_s, false); },
                [&] { StepBareOde(model, campaign.duration_s, true); }, [&] { RunCase(campaign, healthy); }});
  std::printf("one %.0f-s run of %s (monitor in the loop): %.2f ms; bare ODE bodies, hinges and gears: %.2f ms; "
              "with the friction rows: %.2f ms (least CPU time of %d rounds)\n",
              campaign.duration_s, campaign.robot.name.c_str(), 1e3 * full, 1e3 * bare, 1e3 * bare_rows, repeats);
  std::printf("ratio: %.2f\n", full / bare);
  std::printf("ratio against bare ODE with the friction rows: %.2f\n", full / bare_rows);

  // The monitor alone: the same run's signals replayed through it and its decision tap.
  std::vector<double> times;
  std::vector<std::vector<JointSignals>> signals;
  RunCase(campaign, healthy, [&](const Tick& tick) {
    times.push_back(tick.t_s);
    std::vector<JointSignals> s;
    for (const JointTick& j : *tick.joints) s.push_back(j.signals);
    signals.push_back(std::move(s));
  });
  const double monitor = LeastCpuSeconds<1>(repeats, {[&] {
    const std::unique_ptr<HealthMonitor> m = campaign.monitor_model->NewMonitor();
    const std::unique_ptr<DecisionTap> tap = m->NewDecisionTap(0.0);
    for (size_t k = 0; k < times.size(); ++k) {
      m->Observe(times[k], signals[k]);
      if (tap) tap->AfterObserve(times[k]);
    }
    m->Finish(times.back());
  }})[0];
  std::printf("monitor (%s) and its decision tap alone: %.2f ms per run, %.1f %% of the run (%.2f us per tick)\n",
              campaign.monitor_model->type().c_str(), 1e3 * monitor, 100 * monitor / full, 1e6 * monitor / static_cast<double>(times.size()));

  const int cores = tbb::this_task_arena::max_concurrency();
  // Every case twice per core: the cores get equal shares (15 runs on 2 cores could at best reach
  // 15/16 of the ideal, a measure of the split, not of the threads).
  const int n = static_cast<int>(cases.size()) * 2 * cores;
  auto throughput = [&](int threads) {
    tbb::task_arena arena(threads);
    const auto start = std::chrono::steady_clock::now();
    arena.execute([&] {
      tbb::parallel_for(0, n, [&](int i) { RunCase(campaign, cases[static_cast<size_t>(i) % cases.size()]); });
    });
    return n / std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const double one = throughput(1);
  const double all = throughput(cores);
  std::printf("runs per second: %.1f with 1 thread, %.1f with %d threads\n", one, all, cores);
  std::printf("parallel efficiency: %.2f\n", all / (cores * one));
  return 0;
}

}  // namespace armfault
