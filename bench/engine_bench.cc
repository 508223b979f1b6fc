// Cost of one call of the joint-space engine (core/plant/engine/joint_space_dynamics.h) on the
// presets' chains, with the plant's own Newton-Euler (rigid_body_dynamics.h) for reference.
//   build/armfault_engine_bench --benchmark_min_time=1
// For scale on this machine: ODE's step of a three-joint arm takes about 4.6 us.
#include <benchmark/benchmark.h>

#include <vector>

#include "core/plant/engine/joint_space_dynamics.h"
#include "core/plant/robot/robot_config.h"

namespace armfault {
namespace {

// A preset's chain with its own payload, at a pose and rates off every symmetry.
struct Chain {
  RigidBodyModel bodies;
  JointSpaceModel model;
  std::vector<double> q, qd, Q, qdd;
  explicit Chain(const char* preset) {
    const RobotConfig robot = RobotPreset(preset);
    bodies = MakeRigidBodyModel(robot, robot.payload_kg);
    model = MakeJointSpaceModel(bodies);
    const int n = model.joint_count;
    for (int i = 0; i < n; ++i) {
      q.push_back(0.3 - 0.4 * i), qd.push_back(0.8 - 0.5 * i), Q.push_back(5.0 - 2.0 * i), qdd.push_back(1.5 - i);
    }
  }
};

void BM_ForwardDynamics(benchmark::State& state, const char* preset) {
  Chain c(preset);
  std::vector<double> out(c.q.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(c.q.data());
    ForwardDynamics(c.model, c.q.data(), c.qd.data(), c.Q.data(), out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK_CAPTURE(BM_ForwardDynamics, mrr-config1, "mrr-config1");
BENCHMARK_CAPTURE(BM_ForwardDynamics, ur-class, "ur-class");

void BM_InverseDynamics(benchmark::State& state, const char* preset) {
  Chain c(preset);
  std::vector<double> out(c.q.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(c.q.data());
    InverseDynamics(c.model, c.q.data(), c.qd.data(), c.qdd.data(), out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK_CAPTURE(BM_InverseDynamics, mrr-config1, "mrr-config1");
BENCHMARK_CAPTURE(BM_InverseDynamics, ur-class, "ur-class");

void BM_MassMatrix(benchmark::State& state, const char* preset) {
  Chain c(preset);
  JointMatrix M;
  for (auto _ : state) {
    benchmark::DoNotOptimize(c.q.data());
    MassMatrix(c.model, c.q.data(), &M);
    benchmark::DoNotOptimize(M.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK_CAPTURE(BM_MassMatrix, mrr-config1, "mrr-config1");
BENCHMARK_CAPTURE(BM_MassMatrix, ur-class, "ur-class");

// The plant's Q = TransmittedTorques + RotorTorques, the same inverse dynamics.
void BM_PlantNewtonEuler(benchmark::State& state, const char* preset) {
  Chain c(preset);
  std::vector<double> tau(c.q.size()), rotor(c.q.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(c.q.data());
    TransmittedTorques(c.bodies, c.q.data(), c.qd.data(), c.qdd.data(), tau.data());
    RotorTorques(c.bodies, c.q.data(), c.qd.data(), c.qdd.data(), rotor.data());
    benchmark::DoNotOptimize(tau.data());
    benchmark::DoNotOptimize(rotor.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK_CAPTURE(BM_PlantNewtonEuler, mrr-config1, "mrr-config1");
BENCHMARK_CAPTURE(BM_PlantNewtonEuler, ur-class, "ur-class");

}  // namespace
}  // namespace armfault

BENCHMARK_MAIN();
