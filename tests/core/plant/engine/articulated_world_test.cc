// The articulated engine (core/plant/engine/articulated_world.h) in the plant's runs, against
// ODE (the reference): its box-constrained friction rows against an enumeration of every
// active set; the same motions on mrr-config1 (3 joints) and ur-class (6) in both engines, each
// converging to its own run at a quarter of the step at first order, the gap between them at the
// shipped step within a frozen bound; the brake's lock and stiction below breakaway in both;
// slipping above it; the energy balance; determinism; the robots it refuses.
#include "core/plant/engine/articulated_world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/base/json_input.h"
#include "core/plant/drive/friction.h"
#include "core/plant/simulation.h"
#include "core/run_config.h"
#include "reports/trace_csv.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

using testing_support::ConstantCondition;
using testing_support::Recording;

// ---------------------------------------------------------------------------------------------
// The box LCP against brute force: every assignment of each row to lower bound, upper bound or
// free; the one whose free rows solve A λ + c = 0 inside the box and whose bound rows have the
// gradient's sign is the solution (unique: the problem is strictly convex).

bool Kkt(const JointMatrix& A, const std::vector<double>& c, const std::vector<double>& F, const std::vector<double>& x,
         double tol) {
  const int n = static_cast<int>(c.size());
  for (int i = 0; i < n; ++i) {
    double g = c[i];
    for (int j = 0; j < n; ++j) g += A(i, j) * x[j];
    if (x[i] > F[i] + tol || x[i] < -F[i] - tol) return false;
    if (std::fabs(x[i] - F[i]) <= tol && F[i] > 0) {
      if (g > tol) return false;
    } else if (std::fabs(x[i] + F[i]) <= tol && F[i] > 0) {
      if (g < -tol) return false;
    } else if (F[i] > 0 && std::fabs(g) > tol) {
      return false;
    }
  }
  return true;
}

std::vector<double> Enumerate(const JointMatrix& A, const std::vector<double>& c, const std::vector<double>& F) {
  const int n = static_cast<int>(c.size());
  int combos = 1;
  for (int i = 0; i < n; ++i) combos *= 3;
  for (int code = 0; code < combos; ++code) {
    std::vector<int> s(n);
    for (int i = 0, k = code; i < n; ++i, k /= 3) s[i] = k % 3;  // 0 free, 1 lower, 2 upper
    std::vector<double> x(n, 0.0);
    std::vector<int> fr;
    for (int i = 0; i < n; ++i) {
      if (F[i] == 0) continue;
      if (s[i] == 0) fr.push_back(i);
      else x[i] = s[i] == 1 ? -F[i] : F[i];
    }
    const int m = static_cast<int>(fr.size());
    Eigen::MatrixXd Aff(m, m);
    Eigen::VectorXd r(m);
    for (int a = 0; a < m; ++a) {
      r[a] = -c[fr[a]];
      for (int j = 0; j < n; ++j) {
        if (std::find(fr.begin(), fr.end(), j) == fr.end()) r[a] -= A(fr[a], j) * x[j];
      }
      for (int b = 0; b < m; ++b) Aff(a, b) = A(fr[a], fr[b]);
    }
    const Eigen::VectorXd y = m ? Eigen::VectorXd(Aff.llt().solve(r)) : Eigen::VectorXd();
    for (int a = 0; a < m; ++a) x[fr[a]] = y[a];
    if (Kkt(A, c, F, x, 1e-9)) return x;
  }
  return {};
}

TEST(SolveBoxLcpTest, MatchesTheEnumeratedActiveSetOnRandomProblems) {
  std::mt19937_64 gen(52);
  std::uniform_real_distribution<double> u(-1, 1);
  int sticking = 0, slipping = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 6;
    Eigen::MatrixXd B(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) B(i, j) = u(gen);
    const Eigen::MatrixXd S = B * B.transpose() + 0.05 * Eigen::MatrixXd::Identity(n, n);
    JointMatrix A = S;
    std::vector<double> c(n), F(n);
    for (int i = 0; i < n; ++i) {
      c[i] = 2 * u(gen);
      F[i] = trial % 7 == 0 && i == 0 ? 0.0 : std::fabs(u(gen));
    }
    std::vector<double> x(n);
    SolveBoxLcp(A, c.data(), F.data(), x.data());
    const std::vector<double> want = Enumerate(A, c, F);
    ASSERT_EQ(static_cast<int>(want.size()), n) << "trial " << trial << ": no enumerated solution";
    ASSERT_TRUE(Kkt(A, c, F, x, 1e-9)) << "trial " << trial;
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(x[i], want[i], 1e-9) << "trial " << trial << " row " << i;
      if (F[i] > 0 && std::fabs(x[i]) < F[i] - 1e-9) ++sticking;
      else if (F[i] > 0) ++slipping;
    }
  }
  EXPECT_GT(sticking, 100);  // both kinds of row were exercised
  EXPECT_GT(slipping, 100);
}

// ---------------------------------------------------------------------------------------------
// The same motions in both engines.

// `preset` with every joint moving (a sine pair at its own frequency, as `armfault bench`'s
// robot runs), `engine`, at `rate_Hz` with the electrical sub-step kept at 50 us.
RunConfig Motion(const std::string& preset, PhysicsEngine engine, double rate_Hz, double duration_s) {
  const RobotConfig robot = RobotPreset(preset);
  nlohmann::json joints = nlohmann::json::object();
  for (size_t i = 0; i < robot.modules.size(); ++i) {
    const ModuleParams& m = robot.modules[i];
    const double amplitude = std::min(20.0, 0.4 * std::min(-m.min_angle_deg, m.max_angle_deg));
    joints[std::to_string(i + 1)] = {{"type", "sine_pair"}, {"amplitude_deg", amplitude},
                                     {"omega_rad_s", 0.8 + 0.15 * static_cast<double>(i)}};
  }
  InputContext context;
  context.source = "<articulated_world_test>";
  RunConfig run = RunConfigFromJson({{"robot", preset}, {"duration_s", duration_s}, {"seed", 3}, {"joints", joints}}, "", context);
  run.robot.engine = engine;
  run.robot.electrical_substeps = static_cast<int>(std::lround(20 * 1000 / rate_Hz));
  run.robot.physics_rate_Hz = rate_Hz;
  return run;
}

Recording Record(const RunConfig& run, RunResult* result = nullptr) {
  const ArmModel model(run.robot);
  Recording rec;
  const RunResult r = Simulate(model, MakeRunSpec(run), rec.Observer());
  EXPECT_TRUE(r.ok) << r.failure_reason;
  if (result) *result = r;
  return rec;
}

// Every joint's friction scaled by one factor.
class AllJointsCondition : public HardwareSchedule {
 public:
  explicit AllJointsCondition(double friction_factor) { c_.friction_factor = friction_factor; }
  void Apply(double, std::vector<HardwareCondition>* conditions) const override {
    for (HardwareCondition& c : *conditions) c = c_;
  }

 private:
  HardwareCondition c_;
};

// The arm swinging under gravity with no controller: drives off, brakes released, the dry
// friction at a tenth, from a pose away from rest. Open loop, so the step's error is not
// corrected by feedback (nor masked by the encoder's quantisation).
Recording Swing(const RunConfig& like, double duration_s) {
  const ArmModel model(like.robot);
  RunSpec spec;
  spec.duration_s = duration_s;
  spec.seed = like.seed;
  spec.joints.resize(model.joint_count());
  for (int j = 0; j < model.joint_count(); ++j) {
    spec.joints[j].has_initial_angle = true;
    spec.joints[j].initial_angle_rad = 0.3 + 0.1 * j;
    spec.joints[j].powered = false;
    spec.joints[j].brake_held_released = true;
  }
  spec.hardware = std::make_shared<AllJointsCondition>(0.1);
  Recording rec;
  const RunResult r = Simulate(model, spec, rec.Observer());
  EXPECT_TRUE(r.ok) << r.failure_reason;
  return rec;
}

// Distances between two recordings at the same ticks, over every joint: the largest, and the
// mean over time (L1: an event such as a friction reversal that a step moves by O(dt) adds O(dt)
// to it, so a first-order engine converges at first order in it; the largest does not).
struct Gap {
  double q_rad = 0, tau_Nm = 0, sensor_Nm = 0;  // largest |Δq|, |Δτ_true|, |Δ reading|
  double q_mean_rad = 0, tau_mean_Nm = 0;        // mean over ticks of the largest over joints
};

Gap Between(const Recording& a, const Recording& b) {
  Gap g;
  EXPECT_EQ(a.ticks.size(), b.ticks.size());
  const size_t ticks = std::min(a.ticks.size(), b.ticks.size());
  for (size_t k = 0; k < ticks; ++k) {
    double dq = 0, dtau = 0;
    for (size_t j = 0; j < a.ticks[k].size(); ++j) {
      dq = std::max(dq, std::fabs(a.ticks[k][j].q_rad - b.ticks[k][j].q_rad));
      dtau = std::max(dtau, std::fabs(a.ticks[k][j].tau_true_Nm - b.ticks[k][j].tau_true_Nm));
      const double ds = std::fabs(a.ticks[k][j].signals.tau_sensor_Nm - b.ticks[k][j].signals.tau_sensor_Nm);
      g.sensor_Nm = std::max(g.sensor_Nm, ds);
    }
    g.q_rad = std::max(g.q_rad, dq);
    g.tau_Nm = std::max(g.tau_Nm, dtau);
    g.q_mean_rad += dq / static_cast<double>(ticks);
    g.tau_mean_Nm += dtau / static_cast<double>(ticks);
  }
  return g;
}

double PeakTorque(const Recording& a) {
  double p = 0;
  for (const auto& tick : a.ticks)
    for (const JointTick& j : tick) p = std::max(p, std::fabs(j.tau_true_Nm));
  return p;
}

struct Bound {
  const char* preset;
  // The gap between the engines at 1 kHz on the controlled motions, frozen with margin.
  double q_rad, tau_Nm, tau_mean_Nm;
};
void PrintTo(const Bound& b, std::ostream* os) { *os << b.preset; }

void PrintLevels(const char* what, const std::vector<Recording>& ode, const std::vector<Recording>& art) {
  const Gap gap = Between(ode[0], art[0]), gap4 = Between(ode[2], art[2]);
  const Gap o01 = Between(ode[0], ode[1]), o12 = Between(ode[1], ode[2]);
  const Gap a01 = Between(art[0], art[1]), a12 = Between(art[1], art[2]);
  std::printf("  %s, gap ode-articulated at dt: max q %.3e rad, tau %.3e N m, sensor %.3e N m; mean q %.3e rad, tau %.3e N m\n",
              what, gap.q_rad, gap.tau_Nm, gap.sensor_Nm, gap.q_mean_rad, gap.tau_mean_Nm);
  std::printf("  %s, gap at dt/4: max q %.3e, tau %.3e; mean q %.3e, tau %.3e\n", what, gap4.q_rad, gap4.tau_Nm, gap4.q_mean_rad,
              gap4.tau_mean_Nm);
  std::printf("  %s, ode self: dt vs dt/2 mean q %.3e tau %.3e; dt/2 vs dt/4 mean q %.3e tau %.3e\n", what, o01.q_mean_rad,
              o01.tau_mean_Nm, o12.q_mean_rad, o12.tau_mean_Nm);
  std::printf("  %s, articulated self: dt vs dt/2 mean q %.3e tau %.3e; dt/2 vs dt/4 mean q %.3e tau %.3e\n", what,
              a01.q_mean_rad, a01.tau_mean_Nm, a12.q_mean_rad, a12.tau_mean_Nm);
}

class EngineGapTest : public ::testing::TestWithParam<Bound> {};

// Both engines are first order in the step (semi-implicit Euler). Open loop (the swing: no
// controller to correct the step's error, no encoder quantisation), halving the step halves
// the articulated engine's distance to its own run at a quarter of the step: the ratio of
// successive differences, in the mean over time, is 1.90 on mrr-config1 and 1.97 on ur-class
// (asserted in 1.6 .. 2.6; its torques 2.0 and 2.7, in 1.5 .. 3.0). ODE's differences fall
// faster, by about 4 a halving (4.3 to 4.5: at these steps its error is dominated by a dt²
// term, its constraint stabilisation), asserted at least first order (> 1.6). Both converge
// to one motion: the gap between them falls from 1 kHz to 4 kHz by more than 4 (measured 13
// and 18). On the controlled motions the gap does not fall with the step (the feedback holds
// both to the reference; what is left is the encoder's quantisation and the sensor's noise
// passing through the loop, and friction reversals a tick apart, up to twice the link-side dry
// friction in one tick): there the gap at the shipped step (1 kHz) is frozen as the bound,
// about 1.5x to 1.8x the measured gap (measured: mrr-config1 q 2.8e-4 rad, tau 1.93 N m, mean
// tau 0.14 N m; ur-class q 4.6e-4 rad, tau 4.9 N m of 89 N m peak, mean 0.31 N m).
TEST_P(EngineGapTest, ConvergeAtFirstOrderAndStayWithinTheFrozenGap) {
  const Bound bound = GetParam();
  std::vector<Recording> ode, art, ode_swing, art_swing;
  for (double rate : {1000.0, 2000.0, 4000.0}) {
    const RunConfig o = Motion(bound.preset, PhysicsEngine::kOde, rate, 2.0);
    const RunConfig a = Motion(bound.preset, PhysicsEngine::kArticulated, rate, 2.0);
    ode.push_back(Record(o));
    art.push_back(Record(a));
    ode_swing.push_back(Swing(o, 1.0));
    art_swing.push_back(Swing(a, 1.0));
  }
  std::printf("%s: peak |tau| %.4g N m on the controlled motions\n", bound.preset, PeakTorque(ode[0]));
  PrintLevels("controlled", ode, art);
  PrintLevels("swing", ode_swing, art_swing);
  const Gap a01 = Between(art_swing[0], art_swing[1]), a12 = Between(art_swing[1], art_swing[2]);
  EXPECT_GT(a01.q_mean_rad / a12.q_mean_rad, 1.6) << "articulated q: not first order";
  EXPECT_LT(a01.q_mean_rad / a12.q_mean_rad, 2.6) << "articulated q: not first order";
  EXPECT_GT(a01.tau_mean_Nm / a12.tau_mean_Nm, 1.5) << "articulated tau: not first order";
  EXPECT_LT(a01.tau_mean_Nm / a12.tau_mean_Nm, 3.0) << "articulated tau: not first order";
  const Gap o01 = Between(ode_swing[0], ode_swing[1]), o12 = Between(ode_swing[1], ode_swing[2]);
  EXPECT_GT(o01.q_mean_rad / o12.q_mean_rad, 1.6) << "ode q: not converging at first order";
  EXPECT_GT(o01.tau_mean_Nm / o12.tau_mean_Nm, 1.6) << "ode tau: not converging at first order";
  const Gap swing = Between(ode_swing[0], art_swing[0]), swing4 = Between(ode_swing[2], art_swing[2]);
  EXPECT_LT(swing4.q_mean_rad, swing.q_mean_rad / 4) << "the engines do not converge to one motion";

  const Gap gap = Between(ode[0], art[0]);
  RecordProperty("gap_q_rad", std::to_string(gap.q_rad));
  RecordProperty("gap_tau_Nm", std::to_string(gap.tau_Nm));
  RecordProperty("gap_tau_mean_Nm", std::to_string(gap.tau_mean_Nm));
  EXPECT_LT(gap.q_rad, bound.q_rad);
  EXPECT_LT(gap.tau_Nm, bound.tau_Nm);
  EXPECT_LT(gap.tau_mean_Nm, bound.tau_mean_Nm);
  EXPECT_LT(gap.sensor_Nm, bound.tau_Nm);  // the sensors read the truth through the same noise
}

INSTANTIATE_TEST_SUITE_P(Presets, EngineGapTest,
                         ::testing::Values(Bound{"mrr-config1", 5e-4, 3.0, 0.25}, Bound{"ur-class", 7e-4, 7.5, 0.5}),
                         [](const auto& info) { return std::string(info.param.preset) == "ur-class" ? "UrClass" : "MrrConfig1"; });

// ---------------------------------------------------------------------------------------------
// Stiction and the brake, at rest under gravity on mrr-config1: every joint unpowered with its
// brake engaged, except the joint under test (`released`: its brake released, its dry friction
// scaled to `friction_factor`).

const std::vector<double> kPose = {0.3, 0.6, 0.4};  // joints 2 and 3 carry their links' weight

struct Held {
  double travel_rad = 0;  // largest |q − q0| of the joint under test
  double peak_rate_rad_s = 0;
};

Held HoldAtRest(PhysicsEngine engine, int joint, bool released, double friction_factor) {
  RobotConfig robot = RobotPreset("mrr-config1");
  robot.engine = engine;
  const ArmModel model(robot);
  RunSpec spec;
  spec.duration_s = 1.0;
  spec.joints.resize(3);
  for (int j = 0; j < 3; ++j) {
    spec.joints[j].has_initial_angle = true;
    spec.joints[j].initial_angle_rad = kPose[j];
    spec.joints[j].powered = false;
  }
  spec.joints[joint].brake_held_released = released;
  HardwareCondition c;
  c.friction_factor = friction_factor;
  spec.hardware = std::make_shared<ConstantCondition>(joint, c);
  Recording rec;
  const RunResult r = Simulate(model, spec, rec.Observer());
  EXPECT_TRUE(r.ok) << r.failure_reason;
  Held h;
  for (const auto& tick : rec.ticks) {
    h.travel_rad = std::max(h.travel_rad, std::fabs(tick[joint].q_rad - kPose[joint]));
    h.peak_rate_rad_s = std::max(h.peak_rate_rad_s, std::fabs(tick[joint].qd_rad_s));
  }
  return h;
}

// Joint 2's static load, motor side, over its breakaway torque at friction factor 1.
double LoadOverBreakaway(int joint) {
  const RobotConfig robot = RobotPreset("mrr-config1");
  const RigidBodyModel bodies = MakeRigidBodyModel(robot, robot.payload_kg);
  std::vector<double> zero(3, 0.0), tau(3);
  TransmittedTorques(bodies, kPose.data(), zero.data(), zero.data(), tau.data());
  const ModuleParams& m = robot.modules[joint];
  return std::fabs(tau[joint]) / m.drive.ratio / BreakawayFrictionNm(m.friction, 1.0, 0.0);
}

TEST(ArticulatedHoldTest, BrakeLocksTheJointInBothEngines) {
  const int joint = 1;
  // The brake alone holds: the friction is scaled far below the load.
  for (PhysicsEngine e : {PhysicsEngine::kOde, PhysicsEngine::kArticulated}) {
    const Held h = HoldAtRest(e, joint, false, 0.01);
    EXPECT_LT(h.travel_rad, 1e-6) << EngineName(e);
    EXPECT_LT(h.peak_rate_rad_s, 1e-5) << EngineName(e);
  }
  // Without it the same joint falls (the check above can fail).
  for (PhysicsEngine e : {PhysicsEngine::kOde, PhysicsEngine::kArticulated}) {
    EXPECT_GT(HoldAtRest(e, joint, true, 0.01).travel_rad, 0.05) << EngineName(e);
  }
}

TEST(ArticulatedHoldTest, FrictionSticksBelowBreakawayAndSlipsAboveInBothEngines) {
  const int joint = 1;
  const double load = LoadOverBreakaway(joint);  // at friction factor 1
  ASSERT_GT(load, 0.1);
  const double mesh = RobotPreset("mrr-config1").modules[joint].drive.mesh_loss_fraction;
  // Sticking: the breakaway torque alone 1.5x the load (the mesh loss, lagging a step, adds to it).
  // Slipping: breakaway and mesh loss together half the load.
  const double stick = 1.5 * load, slip = 0.5 * (1.0 - mesh) * load;
  for (PhysicsEngine e : {PhysicsEngine::kOde, PhysicsEngine::kArticulated}) {
    const Held held = HoldAtRest(e, joint, true, stick);
    EXPECT_LT(held.travel_rad, 1e-6) << EngineName(e);
    EXPECT_LT(held.peak_rate_rad_s, 1e-5) << EngineName(e);
    EXPECT_GT(HoldAtRest(e, joint, true, slip).travel_rad, 0.05) << EngineName(e);
  }
}

// ---------------------------------------------------------------------------------------------
// The energy balance of thesis experiment 1 (the oracle of tests/core/plant/simulation_test.cc)
// in the articulated engine: the supply's energy is the stored energy plus the losses, and the
// electromagnetic work on the rotors the stored energy plus the friction.

TEST(ArticulatedEnergyTest, SupplyAndMechanicalWorkBalanceOnExperiment1) {
  RunConfig run = ThesisExperiment1();
  run.robot.engine = PhysicsEngine::kArticulated;
  RunResult result;
  const Recording rec = Record(run, &result);
  ASSERT_TRUE(result.ok) << result.failure_reason;
  double supply = 0, losses = 0, emf = 0, friction = 0, moved = 0;
  for (const JointEnergy& e : result.energy) {
    supply += e.supply_J;
    losses += e.copper_J + e.inverter_J + e.quiescent_J + e.friction_J + e.magnetic_J;
    emf += e.emf_J;
    friction += e.friction_J;
    EXPECT_NEAR(e.supply_J, e.copper_J + e.emf_J + e.magnetic_J + e.inverter_J + e.quiescent_J, 1e-4 * e.supply_J);
  }
  const double stored = (result.kinetic_end_J - result.kinetic_start_J) + (result.potential_end_J - result.potential_start_J);
  for (const auto& tick : rec.ticks) {
    for (const JointTick& j : tick) moved += std::fabs(j.p_emf_W) * (rec.t[1] - rec.t[0]);
  }
  std::printf("articulated: supply %.4f J, residual %.3e J; emf %.4f J, mechanical residual %.3e J of %.4f J moved\n", supply,
              supply - stored - losses, emf, emf - stored - friction, moved);
  RecordProperty("mechanical_residual_J", std::to_string(emf - stored - friction));
  EXPECT_GT(moved, 10.0);
  EXPECT_NEAR(supply, stored + losses, 0.01 * supply);
  EXPECT_NEAR(emf, stored + friction, 5e-4 * moved);
}

// ---------------------------------------------------------------------------------------------
// Determinism: the same run twice, and on several threads at once, bit for bit.

std::string TraceText(const RunConfig& run) {
  const ArmModel model(run.robot);
  std::ostringstream out;
  TraceCsvWriter writer(&out, model.joint_count());
  Simulate(model, MakeRunSpec(run), writer.Observer());
  return out.str();
}

TEST(ArticulatedDeterminismTest, SameRunGivesBitIdenticalTracesSeriallyAndOnThreads) {
  const RunConfig run = Motion("ur-class", PhysicsEngine::kArticulated, 1000, 1.0);
  const std::string a = TraceText(run);
  EXPECT_EQ(a, TraceText(run));
  std::vector<std::string> parallel(3);
  std::vector<std::thread> threads;
  for (int i = 0; i < 3; ++i) threads.emplace_back([&, i] { parallel[i] = TraceText(run); });
  for (auto& t : threads) t.join();
  for (const std::string& p : parallel) EXPECT_EQ(a, p);
  EXPECT_NE(a, TraceText(Motion("ur-class", PhysicsEngine::kOde, 1000, 1.0))) << "the engine must be the articulated one";
}

// ---------------------------------------------------------------------------------------------
// What it refuses.

nlohmann::json EightJointRobot() {
  nlohmann::json robot = RobotToJson(RobotPreset("mrr-config1"));
  while (robot["modules"].size() < 8) {
    robot["modules"].push_back(robot["modules"][2]);
    robot["links"].push_back(robot["links"][2]);
  }
  return robot;
}

TEST(ArticulatedRefusalTest, MoreThanSevenJointsIsAnInputErrorNamingWhy) {
  nlohmann::json robot = EightJointRobot();
  EXPECT_NO_THROW(RobotFromJson(robot, "/robot")) << "ODE takes it";
  robot["engine"] = "articulated";
  try {
    RobotFromJson(robot, "/robot");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/robot/engine");
    EXPECT_NE(e.message().find("1 to 7 revolute joints; this robot has 8"), std::string::npos) << e.message();
  }
  RobotConfig config = RobotFromJson(EightJointRobot(), "");
  config.engine = PhysicsEngine::kArticulated;
  EXPECT_THROW(ArmModel{config}, InputError);
}

TEST(ArticulatedRefusalTest, UnknownEngineNamesTheNearest) {
  try {
    EngineFromJson("articulatd", "/engine");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.pointer(), "/engine");
    EXPECT_NE(e.message().find("\"articulatd\""), std::string::npos) << e.message();
    EXPECT_EQ(e.hint(), "did you mean \"articulated\"?");
  }
  EXPECT_THROW(EngineFromJson(3, "/engine"), InputError);
  EXPECT_EQ(EngineFromJson("ode", "/engine"), PhysicsEngine::kOde);
}

}  // namespace
}  // namespace armfault
