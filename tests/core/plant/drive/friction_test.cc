// Friction: the eq 3-8 law itself, and the simulated joint coasting down under it.
#include "core/plant/drive/friction.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/plant/simulation.h"
#include "tests/core/test_support.h"

namespace armfault {
namespace {

const FrictionParams kTable52;  // defaults: thesis table 5-2

TEST(FrictionLawTest, MatchesEquation38AcrossVelocities) {
  for (double qd : {-2.0, -0.3, -0.05, 0.05, 0.3, 2.0}) {
    const double expected = 0.00124 * qd + (0.025 + 0.027 * std::exp(-15 * qd * qd)) * (qd > 0 ? 1 : -1);
    EXPECT_DOUBLE_EQ(FrictionTorqueNm(kTable52, 1.0, qd), expected) << "qd " << qd;
    EXPECT_DOUBLE_EQ(FrictionTorqueNm(kTable52, 1.0, -qd), -expected) << "odd in qd";
  }
  EXPECT_EQ(FrictionTorqueNm(kTable52, 1.0, 0.0), 0.0);  // sat(0) = 0
  EXPECT_DOUBLE_EQ(BreakawayFrictionNm(kTable52, 1.0, 0.0), 0.052);
  EXPECT_DOUBLE_EQ(FrictionTorqueNm(kTable52, 2.0, 0.7), 2.0 * FrictionTorqueNm(kTable52, 1.0, 0.7));
}

// One joint with no gravity, motor unpowered and brake released, set spinning: the only
// torque left is friction, so the dissipated power must be ratio x f(qd) x qd.
class CoastTest : public ::testing::TestWithParam<double> {};

TEST_P(CoastTest, SimulatedFrictionFollowsEquation38AndSticksAtRest) {
  RobotConfig robot = RobotPreset("pendulum");
  robot.gravity_m_s2 = 0;
  robot.modules[0].drive.mesh_loss_fraction = 0;  // only the eq 3-8 friction
  const ArmModel model(robot);
  RunSpec spec;
  spec.duration_s = 25;
  JointRunOptions joint;
  joint.powered = false;
  joint.brake_held_released = true;
  joint.initial_velocity_rad_s = GetParam();
  spec.joints = {joint};
  testing_support::Recording rec;
  ASSERT_TRUE(Simulate(model, spec, rec.Observer()).ok);

  int compared = 0;
  for (size_t k = 1; k < rec.ticks.size(); ++k) {
    const double qd0 = rec.ticks[k - 1][0].qd_rad_s, qd1 = rec.ticks[k][0].qd_rad_s;
    if (std::fabs(qd1) < 0.02 || qd0 * qd1 <= 0) continue;  // moving throughout the period
    // The period has two physics steps. Each sets its friction bound from the velocity at its
    // start (mean (3 qd0 + qd1)/4) and dissipates at the velocity after it (mean (qd0 + 3 qd1)/4).
    const double qd_force = 0.75 * qd0 + 0.25 * qd1;
    const double qd_power = 0.25 * qd0 + 0.75 * qd1;
    const double expected = 101.0 * FrictionTorqueNm(robot.modules[0].friction, 1.0, qd_force) * qd_power;
    EXPECT_NEAR(rec.ticks[k][0].p_friction_W, expected, 0.01 * std::fabs(expected) + 1e-4) << "qd " << qd_power;
    ++compared;
  }
  EXPECT_GT(compared, 100);
  // Friction brought the joint to rest, and static friction keeps it there.
  EXPECT_NEAR(rec.ticks.back()[0].qd_rad_s, 0.0, 1e-12);
  EXPECT_NEAR(rec.ticks.back()[0].q_rad, rec.ticks[rec.ticks.size() - 100][0].q_rad, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(BothDirections, CoastTest, ::testing::Values(1.5, -1.5));

}  // namespace
}  // namespace armfault
