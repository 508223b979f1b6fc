// Physical laws and behaviour of the simulated arm: analytic pendulum, energy balance,
// thesis experiment 1 tracking with and without K_T loss, determinism, thread safety.
#include "core/simulation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <thread>

#include "core/json_input.h"
#include "core/run_config.h"
#include "reports/trace_csv.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using testing_support::ConstantCondition;
using testing_support::Recording;

double Rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return std::sqrt(s / v.size());
}

TEST(PendulumTest, PassiveSwingMatchesAnalyticSmallAnglePeriod) {
  RobotConfig robot = RobotPreset("pendulum");
  robot.modules[0].friction = {0, 0, 0, 0};
  robot.modules[0].drive.mesh_loss_fraction = 0;
  const ArmModel model(robot);
  RunSpec spec;
  spec.duration_s = 12;
  JointRunOptions joint;
  joint.powered = false;             // motor unpowered
  joint.brake_held_released = true;  // brake released
  joint.has_initial_angle = true;
  joint.initial_angle_rad = 2.0 * M_PI / 180;
  spec.joints = {joint};
  Recording rec;
  ASSERT_TRUE(Simulate(model, spec, rec.Observer()).ok);

  // Upward zero crossings of q, interpolated between ticks.
  std::vector<double> crossings;
  for (size_t k = 1; k < rec.t.size(); ++k) {
    const double a = rec.ticks[k - 1][0].q_rad, b = rec.ticks[k][0].q_rad;
    if (a < 0 && b >= 0) crossings.push_back(rec.t[k - 1] + (rec.t[k] - rec.t[k - 1]) * (-a) / (b - a));
  }
  ASSERT_GE(crossings.size(), 3u);
  const double measured = (crossings.back() - crossings.front()) / (crossings.size() - 1);

  // Physical pendulum: rod about its end plus the rotor reflected through the gear.
  const LinkParams& l = robot.links[0];
  const double d = l.com_fraction * l.length_m;
  const double rod = l.mass_kg * (3 * l.radius_m * l.radius_m + l.length_m * l.length_m) / 12 + l.mass_kg * d * d;
  const double rotor = robot.modules[0].motor.rotor_inertia_kg_m2 * 101.0 * 101.0;
  const double analytic = 2 * M_PI * std::sqrt((rod + rotor) / (l.mass_kg * robot.gravity_m_s2 * d));
  RecordProperty("measured_period_s", std::to_string(measured));
  RecordProperty("analytic_period_s", std::to_string(analytic));
  EXPECT_NEAR(measured / analytic, 1.0, 0.005) << "measured " << measured << " s, analytic " << analytic << " s";
}

struct Exp1Result {
  RunResult result;
  Recording rec;
};

Exp1Result RunExperiment1(double kt_factor) {
  const RunConfig run = ThesisExperiment1();
  const ArmModel model(run.robot);
  RunSpec spec = MakeRunSpec(run);
  if (kt_factor != 1.0) {
    HardwareCondition c;
    c.kt_factor = kt_factor;
    spec.hardware = std::make_shared<ConstantCondition>(2, c);
  }
  Exp1Result out;
  out.result = Simulate(model, spec, out.rec.Observer());
  return out;
}

TEST(EnergyBalanceTest, SupplyEnergyEqualsStoredPlusLossesOnExperiment1) {
  const Exp1Result r = RunExperiment1(1.0);
  ASSERT_TRUE(r.result.ok) << r.result.failure_reason;
  double supply = 0, losses = 0;
  for (const JointEnergy& e : r.result.energy) {
    supply += e.supply_J;
    losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
  }
  const double stored = (r.result.kinetic_end_J - r.result.kinetic_start_J) +
                        (r.result.potential_end_J - r.result.potential_start_J);
  EXPECT_GT(supply, 0);
  RecordProperty("supply_J", std::to_string(supply));
  RecordProperty("residual_J", std::to_string(supply - stored - losses));
  EXPECT_NEAR(supply, stored + losses, 0.01 * supply);
  // The electrical side closes by itself: supply = copper + emf + magnetic + inverter + quiescent.
  for (const JointEnergy& e : r.result.energy) {
    EXPECT_NEAR(e.supply_J, e.copper_J + e.emf_J + e.magnetic_J + e.inverter_J + e.quiescent_J, 1e-4 * e.supply_J);
  }
}

TEST(Experiment1Test, TopJointTracksWithinHalfADegree) {
  const Exp1Result r = RunExperiment1(1.0);
  ASSERT_TRUE(r.result.ok) << r.result.failure_reason;
  std::vector<double> err;
  double peak_ref = 0;
  for (const auto& tick : r.rec.ticks) {
    err.push_back((tick[2].q_rad - tick[2].q_ref_rad) * 180 / M_PI);
    peak_ref = std::max(peak_ref, std::fabs(tick[2].q_ref_rad) * 180 / M_PI);
  }
  RecordProperty("rms_error_deg", std::to_string(Rms(err)));
  EXPECT_LT(Rms(err), 0.5);
  EXPECT_GT(peak_ref, 25.0);  // the motion really happened
  // The lower joints hold still.
  for (const auto& tick : r.rec.ticks) {
    EXPECT_LT(std::fabs(tick[0].q_rad) * 180 / M_PI, 0.5);
    EXPECT_LT(std::fabs(tick[1].q_rad) * 180 / M_PI, 0.5);
  }
}

TEST(Experiment1Test, HalvedTorqueConstantStillTracksWithAboutTwiceTheCurrent) {
  const Exp1Result healthy = RunExperiment1(1.0);
  const Exp1Result weak = RunExperiment1(0.5);
  ASSERT_TRUE(weak.result.ok) << weak.result.failure_reason;
  std::vector<double> err, i_healthy, i_weak;
  for (size_t k = 0; k < weak.rec.ticks.size(); ++k) {
    err.push_back((weak.rec.ticks[k][2].q_rad - weak.rec.ticks[k][2].q_ref_rad) * 180 / M_PI);
    i_healthy.push_back(healthy.rec.ticks[k][2].i_cmd_A);
    i_weak.push_back(weak.rec.ticks[k][2].i_cmd_A);
  }
  RecordProperty("rms_error_deg", std::to_string(Rms(err)));
  EXPECT_LT(Rms(err), 0.5);
  const double ratio = Rms(i_weak) / Rms(i_healthy);
  RecordProperty("current_ratio", std::to_string(ratio));
  EXPECT_NEAR(ratio, 2.0, 0.3) << "commanded current ratio " << ratio;
}

std::string TraceText(const RunConfig& run) {
  const ArmModel model(run.robot);
  std::ostringstream out;
  TraceCsvWriter writer(&out, model.joint_count());
  Simulate(model, MakeRunSpec(run), writer.Observer());
  return out.str();
}

TEST(DeterminismTest, SameInputsAndSeedGiveBitIdenticalTraces) {
  RunConfig run = ThesisExperiment1();
  run.duration_s = 2;
  const std::string a = TraceText(run);
  const std::string b = TraceText(run);
  EXPECT_EQ(a, b);
  run.seed = 2;
  EXPECT_NE(a, TraceText(run)) << "the seed must change the sensor noise";
}

TEST(ThreadSafetyTest, WorldsSteppingOnSeveralThreadsMatchSerialResults) {
  RunConfig run = ThesisExperiment1();
  run.duration_s = 1;
  constexpr int kRuns = 4;
  std::vector<std::string> serial(kRuns), parallel(kRuns);
  std::vector<RunConfig> runs(kRuns, run);
  for (int i = 0; i < kRuns; ++i) {
    runs[i].seed = 100 + i;
    serial[i] = TraceText(runs[i]);
  }
  std::vector<std::thread> threads;
  for (int i = 0; i < kRuns; ++i) {
    threads.emplace_back([&, i] { parallel[i] = TraceText(runs[i]); });
  }
  for (auto& t : threads) t.join();
  for (int i = 0; i < kRuns; ++i) EXPECT_EQ(serial[i], parallel[i]) << "run " << i;
}

TEST(SimulationTest, RejectsRunSpecWithWrongJointCount) {
  const ArmModel model(RobotPreset("mrr-config1"));
  RunSpec spec;
  spec.joints.resize(2);
  EXPECT_THROW(Simulate(model, spec, nullptr), InputError);
}

}  // namespace
}  // namespace armfault
