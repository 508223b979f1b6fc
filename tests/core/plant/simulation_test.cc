// Physical laws and behaviour of the simulated arm: analytic pendulum, rotor coupling between
// parallel joints, energy balance (electrical and mechanical), thesis experiment 1 tracking
// with and without K_T loss, determinism, thread safety.
#include "core/plant/simulation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <thread>

#include "core/base/json_input.h"
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

// A smooth rest-to-rest swing for a driven joint: q = A (1 - cos(2 pi t / T)) / 2.
class SwingTrajectory : public Trajectory {
 public:
  SwingTrajectory(double amplitude_rad, double period_s) : a_(amplitude_rad), w_(2 * M_PI / period_s) {}
  TrajectoryPoint At(double t) const override {
    return {0.5 * a_ * (1 - std::cos(w_ * t)), 0.5 * a_ * w_ * std::sin(w_ * t),
            0.5 * a_ * w_ * w_ * std::cos(w_ * t)};
  }
  const char* type() const override { return "swing"; }

 private:
  double a_, w_;
};

// Two joints with parallel vertical axes (gravity does no work about them). Link 2 has its
// centre of mass on its own axis, so its only coupling to joint 1 about axis 2 is its
// inertia I_L2 and joint 2's rotor: M21 = I_L2 + I_m gamma, M22 = I_L2 + I_m gamma^2.
// Joint 2 has no friction or mesh loss so that only the brake (when engaged) acts on it.
constexpr double kLink2Inertia_kg_m2 = 1e-3;
RobotConfig ParallelAxesRobot() {
  RobotConfig robot;
  robot.name = "parallel-axes";
  robot.modules = {ModuleDefaults("MRR2", ""), ModuleDefaults("MRR2", "")};
  robot.modules[1].friction = {0, 0, 0, 0};
  robot.modules[1].drive.mesh_loss_fraction = 0;
  LinkParams l1;
  l1.mass_kg = 1.0;
  l1.length_m = 0.3;
  l1.direction = {1, 0, 0};
  l1.joint_axis = {0, 0, 1};
  LinkParams l2 = l1;
  l2.com_fraction = 0;
  l2.has_inertia = true;
  l2.inertia_kg_m2 = {kLink2Inertia_kg_m2, kLink2Inertia_kg_m2, kLink2Inertia_kg_m2};
  robot.links = {l1, l2};
  return robot;
}

RunSpec SwingJoint1(bool brake_holds_joint2) {
  RunSpec spec;
  spec.duration_s = 1.0;
  JointRunOptions j1;
  j1.trajectory = std::make_shared<SwingTrajectory>(0.5, 1.0);
  JointRunOptions j2;
  j2.powered = false;                           // no motor torque on joint 2
  j2.brake_held_released = !brake_holds_joint2;
  spec.joints = {j1, j2};
  return spec;
}

// Joint 2 free: its generalized momentum M21 q_dot_1 + M22 q_dot_2 stays 0, so
// q_dot_2 / q_dot_1 = -(I_L2 + I_m gamma) / (I_L2 + I_m gamma^2) = -0.0127. With the rotor
// lumped on link 2 (the old model) it was -(I_L2 + I_m gamma^2) / (...) = -1.
TEST(RotorCouplingTest, FreeUpperJointFollowsTheAnalyticRotorCoupling) {
  const RobotConfig robot = ParallelAxesRobot();
  const ArmModel model(robot);
  Recording rec;
  ASSERT_TRUE(Simulate(model, SwingJoint1(false), rec.Observer()).ok);
  size_t peak = 0;
  for (size_t k = 0; k < rec.ticks.size(); ++k) {
    if (std::fabs(rec.ticks[k][0].qd_rad_s) > std::fabs(rec.ticks[peak][0].qd_rad_s)) peak = k;
  }
  const double qd1 = rec.ticks[peak][0].qd_rad_s;
  ASSERT_GT(std::fabs(qd1), 0.5) << "joint 1 did not move";
  const double im = robot.modules[1].motor.rotor_inertia_kg_m2, gamma = robot.modules[1].drive.ratio;
  const double expected = -(kLink2Inertia_kg_m2 + im * gamma) / (kLink2Inertia_kg_m2 + im * gamma * gamma);
  const double measured = rec.ticks[peak][1].qd_rad_s / qd1;
  RecordProperty("measured_ratio", std::to_string(measured));
  RecordProperty("expected_ratio", std::to_string(expected));
  EXPECT_NEAR(measured / expected, 1.0, 0.01) << "q_dot_2 / q_dot_1 " << measured << ", expected " << expected;
}

// Joint 2 held by its brake (rotor locked to its stator, q_dot_2 = 0): the brake supplies
// joint 2's generalized force M21 q_ddot_1, the torque sensor sees the link's share
// I_L2 q_ddot_1; the difference is the rotor coupling torque I_m gamma q_ddot_1. Integrated
// over the accelerating first quarter: brake - sensor = I_m gamma (q_dot_1(T/4) - q_dot_1(0)).
TEST(RotorCouplingTest, HeldUpperJointCouplingTorqueIsImGammaTimesLowerAcceleration) {
  const RobotConfig robot = ParallelAxesRobot();
  const ArmModel model(robot);
  Recording rec;
  ASSERT_TRUE(Simulate(model, SwingJoint1(true), rec.Observer()).ok);
  const double tc = model.control_dt_s();
  const size_t end = static_cast<size_t>(std::lround(0.25 / tc));  // q_ddot_1 > 0 before
  double coupling_impulse = 0;
  for (size_t k = 1; k <= end; ++k) {
    const JointTick& now = rec.ticks[k][1];
    const JointTick& before = rec.ticks[k - 1][1];
    // Brake torque is a period mean of |torque|; the sensor's truth is sampled at the ticks.
    coupling_impulse += (now.brake_torque_Nm - 0.5 * (now.tau_true_Nm + before.tau_true_Nm)) * tc;
    EXPECT_LT(std::fabs(now.qd_rad_s), 1e-3) << "the brake must hold joint 2";
  }
  const double dqd1 = rec.ticks[end][0].qd_rad_s - rec.ticks[0][0].qd_rad_s;
  ASSERT_GT(dqd1, 0.5) << "joint 1 did not accelerate";
  const double im = robot.modules[1].motor.rotor_inertia_kg_m2, gamma = robot.modules[1].drive.ratio;
  const double expected = im * gamma * dqd1;
  RecordProperty("measured_coupling_impulse_Nms", std::to_string(coupling_impulse));
  RecordProperty("expected_coupling_impulse_Nms", std::to_string(expected));
  EXPECT_NEAR(coupling_impulse / expected, 1.0, 0.02)
      << "coupling impulse " << coupling_impulse << " N m s, I_m gamma dq_dot_1 = " << expected
      << " (I_m gamma^2 would give " << expected * gamma << ")";
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
  // The mechanical side: the electromagnetic work on the rotors = change of kinetic (links and
  // rotors) and potential energy + friction, mesh and brake dissipation, to 1 % of the
  // mechanical energy moved (the gross electromagnetic work, sum of |p_emf| dt).
  double emf = 0, friction = 0, moved = 0;
  for (const JointEnergy& e : r.result.energy) {
    emf += e.emf_J;
    friction += e.friction_J;
  }
  for (const auto& tick : r.rec.ticks) {
    for (const JointTick& j : tick) moved += std::fabs(j.p_emf_W) * (r.rec.t[1] - r.rec.t[0]);
  }
  RecordProperty("mechanical_moved_J", std::to_string(moved));
  RecordProperty("mechanical_residual_J", std::to_string(emf - stored - friction));
  EXPECT_GT(moved, 10.0);  // the top joint really worked
  EXPECT_NEAR(emf, stored + friction, 0.01 * moved)
      << "emf " << emf << " J, stored " << stored << " J, friction " << friction << " J, moved " << moved << " J";
}

TEST(Experiment1Test, TopJointTracksWithinHalfADegree) {
  const Exp1Result r = RunExperiment1(1.0);
  ASSERT_TRUE(r.result.ok) << r.result.failure_reason;
  std::vector<double> err;
  double peak_ref = 0;
  for (const auto& tick : r.rec.ticks) {
    err.push_back((tick[2].q_rad - tick[2].signals.q_ref_rad) * 180 / M_PI);
    peak_ref = std::max(peak_ref, std::fabs(tick[2].signals.q_ref_rad) * 180 / M_PI);
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
    err.push_back((weak.rec.ticks[k][2].q_rad - weak.rec.ticks[k][2].signals.q_ref_rad) * 180 / M_PI);
    i_healthy.push_back(healthy.rec.ticks[k][2].signals.i_cmd_A);
    i_weak.push_back(weak.rec.ticks[k][2].signals.i_cmd_A);
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
