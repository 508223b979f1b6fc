// The arm's MJCF (core/plant/engine/mujoco/mujoco_arm.h): the text names every joint with its
// armature γ²·I_m; and, when MuJoCo is built in, MuJoCo's mass matrix and bias forces of the
// generated model equal the joint-space engine's for the same links with each rotor's spin as
// a plain armature (the model MuJoCo is given, not the plant's geared rotors): the links,
// inertias, axes, anchors and gravity went across.
#include "core/plant/engine/mujoco/mujoco_arm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"

namespace armfault {
namespace {

JointSpaceModel PresetChain(const char* name) {
  const RobotConfig robot = RobotPreset(name);
  return MakeJointSpaceModel(MakeRigidBodyModel(robot, robot.payload_kg + 1.5));
}

TEST(MujocoArmXml, NamesEveryJointWithItsArmatureAndFrictionLoss) {
  const JointSpaceModel chain = PresetChain("ur-class");
  const std::string xml = MujocoArmXml(chain, 1e-3, std::vector<double>(6, 2.5));
  for (int i = 1; i <= 6; ++i) EXPECT_NE(xml.find("<joint name=\"joint" + std::to_string(i) + "\""), std::string::npos);
  char armature[64];
  std::snprintf(armature, sizeof armature, "armature=\"%.17g\"",
                chain.joints[0].ratio * chain.joints[0].ratio * chain.joints[0].rotor_inertia_kg_m2);
  EXPECT_NE(xml.find(armature), std::string::npos) << xml;
  EXPECT_NE(xml.find("frictionloss=\"2.5\""), std::string::npos);
  EXPECT_NE(xml.find("timestep=\"0.001\""), std::string::npos);
  EXPECT_NE(xml.find("integrator=\"Euler\""), std::string::npos);
}

class MujocoAgainstEngine : public ::testing::TestWithParam<const char*> {};

TEST_P(MujocoAgainstEngine, MassMatrixAndBiasAreThePlainArmatureChains) {
  if (!MujocoBuiltIn()) GTEST_SKIP() << "MuJoCo is not built in (libmujoco-dev)";
  const JointSpaceModel chain = PresetChain(GetParam());
  const int n = chain.joint_count;
  // The same links with no rotor spin; the armature added on the diagonal below.
  JointSpaceModel plain = chain;
  for (int i = 0; i < n; ++i) plain.joints[i].rotor_inertia_kg_m2 = 0;
  MujocoArm mujoco(chain, 1e-3, {});
  for (int pose = 0; pose < 3; ++pose) {
    std::vector<double> q(n), qd(n);
    for (int i = 0; i < n; ++i) q[i] = 0.3 * pose - 0.4 * i, qd[i] = 0.8 - 0.5 * i + 0.2 * pose;
    JointMatrix M;
    MassMatrix(plain, q.data(), &M);
    for (int i = 0; i < n; ++i) M(i, i) += chain.joints[i].ratio * chain.joints[i].ratio * chain.joints[i].rotor_inertia_kg_m2;
    std::vector<double> b(n);
    Bias(plain, q.data(), qd.data(), b.data());
    std::vector<double> M_mj, b_mj;
    mujoco.MassAndBias(q.data(), qd.data(), &M_mj, &b_mj);
    const double m_scale = M.cwiseAbs().maxCoeff();
    double b_scale = 0;
    for (double x : b) b_scale = std::max(b_scale, std::fabs(x));
    for (int i = 0; i < n; ++i) {
      for (int k = 0; k < n; ++k) EXPECT_NEAR(M_mj[i * n + k], M(i, k), 1e-9 * m_scale) << "pose " << pose << " M(" << i << ", " << k << ")";
      EXPECT_NEAR(b_mj[i], b[i], 1e-9 * b_scale) << "pose " << pose << " joint " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Presets, MujocoAgainstEngine, ::testing::Values("mrr-config1", "ur-class"));

TEST(MujocoArm, StepsTheArmFromRestOrSaysItIsNotBuiltIn) {
  const JointSpaceModel chain = PresetChain("mrr-config1");
  if (!MujocoBuiltIn()) {
    EXPECT_THROW(MujocoArm(chain, 1e-3, {}), std::runtime_error);
    return;
  }
  EXPECT_FALSE(MujocoVersion().empty());
  MujocoArm mujoco(chain, 1e-3, {});
  const double once = mujoco.StepFromRest(200);
  EXPECT_TRUE(std::isfinite(once));
  EXPECT_EQ(mujoco.StepFromRest(200), once);  // from rest again: the same steps
}

}  // namespace
}  // namespace armfault
