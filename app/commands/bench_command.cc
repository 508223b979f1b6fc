// `armfault bench`: the cost of a full run against bare ODE stepping of the same arm, and
// campaign throughput with one thread and with all cores.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "app/commands/commands.h"
#include "campaigns/spec/campaign.h"
#include "campaigns/spec/cases.h"
#include "campaigns/running/run_pipeline.h"
#include "campaigns/running/runner.h"
#include "core/monitors/detector_statistics.h"
#include "core/monitors/power_monitor.h"
#include "core/plant/drive/friction.h"
#include "core/plant/engine/mujoco/mujoco_arm.h"
#include "core/plant/robot/robot_config.h"
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

// One healthy case of mrr-config1 with all three joints moving, `duration_s` long: the
// length benchmark's run (each joint at its own frequency, so the windows and the coupling
// terms of every joint are exercised).
Campaign LengthCampaign(double duration_s) {
  const nlohmann::json j = {
      {"name", "bench-length"},
      {"seed", 7},
      {"robot", "mrr-config1"},
      {"duration_s", duration_s},
      {"trajectories",
       {{{"name", "all3"},
         {"joints",
          {{"1", {{"type", "sine_pair"}, {"amplitude_deg", 30}, {"omega_rad_s", 0.8}}},
           {"2", {{"type", "sine_pair"}, {"amplitude_deg", 20}, {"omega_rad_s", 1.0}}},
           {"3", {{"type", "sine_pair"}, {"amplitude_deg", 25}, {"omega_rad_s", 1.2732}}}}}}}},
      {"faults", nlohmann::json::array()},
      {"healthy", 1},
      {"monitor", nlohmann::json::object()}};
  return CampaignFromJson(j, "<bench --duration>", ".");
}

struct LengthFigures {
  double cpu_s = 0;    // least CPU time of one run
  double peak_kB = 0;  // the process's peak resident set
};

// Runs the length's repeats in a forked child (so that its peak RSS is its own) and reads the
// figures back through a pipe. Returns false when the child failed.
bool MeasureLength(double duration_s, int repeats, LengthFigures* out) {
  int fds[2];
  if (pipe(fds) != 0) return false;
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    close(fds[0]);
    LengthFigures f;
    f.cpu_s = std::numeric_limits<double>::infinity();
    try {
      const Campaign campaign = LengthCampaign(duration_s);
      const CaseSpec cs = CaseAt(campaign, 0);
      for (int r = 0; r < repeats; ++r) {
        const double start = ThreadCpuSeconds();
        const RunRecord record = RunCase(campaign, cs);
        f.cpu_s = std::min(f.cpu_s, ThreadCpuSeconds() - start);
        if (!record.ok) _exit(3);
      }
    } catch (const std::exception&) {
      _exit(3);
    }
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    f.peak_kB = static_cast<double>(u.ru_maxrss);
    const ssize_t n = write(fds[1], &f, sizeof f);
    _exit(n == static_cast<ssize_t>(sizeof f) ? 0 : 3);
  }
  close(fds[1]);
  const ssize_t n = read(fds[0], out, sizeof *out);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  return n == static_cast<ssize_t>(sizeof *out) && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

int BenchLengthCommand(const std::vector<double>& durations_s, int repeats) {
  std::printf("healthy mrr-config1 runs, all joints moving, through the campaign pipeline; least CPU time of %d "
              "runs, peak RSS of a process of its own per length\n",
              repeats);
  std::printf("%12s %10s %14s %14s %16s\n", "simulated_s", "peak_MB", "cpu_s", "ms_per_sim_s", "marginal_ms_per_s");
  std::vector<std::pair<double, LengthFigures>> done;
  for (double d : durations_s) {
    LengthFigures f;
    if (!MeasureLength(d, repeats, &f)) {
      std::fprintf(stderr, "error: the %.0f-s run failed\n", d);
      return 1;
    }
    char marginal[32] = "-";
    if (!done.empty() && d > done.back().first) {
      std::snprintf(marginal, sizeof marginal, "%.3f",
                    1e3 * (f.cpu_s - done.back().second.cpu_s) / (d - done.back().first));
    }
    std::printf("%12.0f %10.1f %14.3f %14.3f %16s\n", d, f.peak_kB / 1024.0, f.cpu_s, 1e3 * f.cpu_s / d, marginal);
    std::fflush(stdout);
    done.emplace_back(d, f);
  }
  if (done.size() >= 3) {
    // The marginal cost of the last step against the first: 1.00 when the time per simulated
    // second does not depend on the run's length.
    const auto m = [&](size_t k) {
      return (done[k].second.cpu_s - done[k - 1].second.cpu_s) / (done[k].first - done[k - 1].first);
    };
    std::printf("marginal ratio (last step / first step): %.3f\n", m(done.size() - 1) / m(1));
  }
  return 0;
}

namespace {

// Healthy 10-s runs of `robot` with every joint moving (a sine pair at its own frequency, 20 deg
// or 40 % of the half range where that is less; a joint whose range excludes 0 holds its middle).
Campaign RobotBenchCampaign(const RobotConfig& robot) {
  nlohmann::json joints = nlohmann::json::object();
  for (size_t i = 0; i < robot.modules.size(); ++i) {
    const ModuleParams& m = robot.modules[i];
    if (m.min_angle_deg < 0 && m.max_angle_deg > 0) {
      const double amplitude = std::min(20.0, 0.4 * std::min(-m.min_angle_deg, m.max_angle_deg));
      joints[std::to_string(i + 1)] = {{"type", "sine_pair"}, {"amplitude_deg", amplitude},
                                       {"omega_rad_s", 0.8 + 0.15 * static_cast<double>(i)}};
    } else {
      joints[std::to_string(i + 1)] = {{"type", "hold"}, {"angle_deg", 0.5 * (m.min_angle_deg + m.max_angle_deg)}};
    }
  }
  const nlohmann::json j = {{"name", "bench-" + robot.name},
                            {"seed", 7},
                            {"robot", RobotToJson(robot)},
                            {"duration_s", 10},
                            {"trajectories", {{{"name", "all"}, {"joints", joints}}}},
                            {"faults", nlohmann::json::array()},
                            {"healthy", 4},
                            {"monitor", nlohmann::json::object()}};
  return CampaignFromJson(j, "<bench --robot>", ".");
}

}  // namespace

int BenchCommand(int repeats, const std::string& robot_argument, const std::string& engine_name) {
  Campaign campaign = robot_argument.empty() ? DefaultCampaign() : RobotBenchCampaign(ReadRobotArgument(robot_argument));
  if (!engine_name.empty()) {
    // The full runs in this engine; the bare stepping stays ODE's, the reference cost.
    campaign.robot.engine = EngineFromJson(engine_name, "--engine");
    CheckEngineTakes(campaign.robot, "--engine");
  }
  const std::vector<CaseSpec> cases = ExpandCases(campaign);
  const ArmModel model(campaign.robot);
  const CaseSpec& healthy = cases.back();
  const long steps_per_run = std::lround(campaign.duration_s / model.physics_dt_s());
  // MuJoCo, when built in: the same chain with the same dry-friction bounds at the link side
  // (core/plant/engine/mujoco/mujoco_arm.h); loaded once, outside the timing.
  std::unique_ptr<MujocoArm> mujoco;
  std::string mujoco_problem = MujocoProblem();
  if (MujocoBuiltIn()) {
    std::vector<double> friction_loss_Nm;
    for (int j = 0; j < model.joint_count(); ++j) {
      friction_loss_Nm.push_back(model.joint(j).ratio * BreakawayFrictionNm(model.joint(j).params.friction, 1.0, 1.0));
    }
    try {
      mujoco = std::make_unique<MujocoArm>(MakeJointSpaceModel(model.rigid_bodies()), model.physics_dt_s(), friction_loss_Nm);
    } catch (const std::exception& e) {
      mujoco_problem = e.what();
    }
  }
  const auto [bare, bare_rows, full, bare_articulated, bare_mujoco] = LeastCpuSeconds<5>(
      repeats, {[&] { StepBareOde(model, campaign.duration_s, false); },
                [&] { StepBareOde(model, campaign.duration_s, true); }, [&] { RunCase(campaign, healthy); },
                [&] { StepBareArticulated(model, campaign.duration_s); },
                [&] {
                  if (mujoco) mujoco->StepFromRest(steps_per_run);
                }});
  const char* engine = EngineName(campaign.robot.engine);
  std::printf("one %.0f-s run of %s, %d joints (monitor in the loop, engine %s): %.2f ms; bare ODE bodies, hinges and gears: %.2f ms; "
              "with the friction rows: %.2f ms (least CPU time of %d rounds)\n",
              campaign.duration_s, campaign.robot.name.c_str(), static_cast<int>(campaign.robot.modules.size()), engine, 1e3 * full,
              1e3 * bare, 1e3 * bare_rows, repeats);
  std::printf("ratio: %.2f\n", full / bare);
  std::printf("ratio against bare ODE with the friction rows: %.2f\n", full / bare_rows);
  const double steps = std::round(campaign.duration_s / model.physics_dt_s());
  std::printf("us per physics step: full run (%s) %.3f; bare ODE %.3f, with the friction rows %.3f; bare articulated engine "
              "with its friction rows %.3f\n",
              engine, 1e6 * full / steps, 1e6 * bare / steps, 1e6 * bare_rows / steps, 1e6 * bare_articulated / steps);
  if (mujoco) {
    std::printf("us per physics step: bare MuJoCo %s with its frictionloss rows %.3f (a different model: each rotor "
                "an armature γ²·I_m on its own joint, without the geared rotor's I_m·γ coupling)\n",
                MujocoVersion().c_str(), 1e6 * bare_mujoco / steps);
  } else {
    std::printf("us per physics step: bare MuJoCo: %s\n", mujoco_problem.c_str());
  }

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
