// The joint-space engine (core/plant/engine/joint_space_dynamics.h) against the plant's own
// recursive Newton-Euler (core/plant/robot/rigid_body_dynamics.h), against itself (forward then
// inverse dynamics), against the bodies' kinetic energy computed here from their velocities,
// against the independent model of tests/core/plant/independent_model.h, against a two-joint
// chain's mass matrix written down by hand, and along the free motion of an unforced,
// frictionless chain (its energy kept).
#include "core/plant/engine/joint_space_dynamics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"
#include "tests/core/plant/independent_model.h"

namespace armfault {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

// The plant's generalised forces: Q_i = τ_i + rotor_i.
VectorXd PlantQ(const RigidBodyModel& m, const VectorXd& q, const VectorXd& qd, const VectorXd& qdd) {
  const int n = static_cast<int>(q.size());
  VectorXd tau(n), rotor(n);
  TransmittedTorques(m, q.data(), qd.data(), qdd.data(), tau.data());
  RotorTorques(m, q.data(), qd.data(), qdd.data(), rotor.data());
  return tau + rotor;
}

VectorXd EngineQ(const JointSpaceModel& m, const VectorXd& q, const VectorXd& qd, const VectorXd& qdd) {
  VectorXd Q(q.size());
  InverseDynamics(m, q.data(), qd.data(), qdd.data(), Q.data());
  return Q;
}

MatrixXd Mass(const JointSpaceModel& m, const VectorXd& q) {
  JointMatrix M;
  MassMatrix(m, q.data(), &M);
  return M;
}

// The presets with a payload beyond their own.
std::vector<std::pair<std::string, RigidBodyModel>> Presets() {
  std::vector<std::pair<std::string, RigidBodyModel>> out;
  for (const char* name : {"mrr-config1", "ur-class"}) {
    const RobotConfig robot = RobotPreset(name);
    out.emplace_back(name, MakeRigidBodyModel(robot, robot.payload_kg + 1.5));
  }
  return out;
}

struct State {
  VectorXd q, qd, qdd;
};

State RandomState(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), rate(-2.5, 2.5), acc(-8.0, 8.0);
  State s{VectorXd(n), VectorXd(n), VectorXd(n)};
  for (int i = 0; i < n; ++i) s.q[i] = angle(*rng), s.qd[i] = rate(*rng), s.qdd[i] = acc(*rng);
  return s;
}

// A chain of n joints with random axes, anchors, bodies and rotors (each link's inertia
// positive definite), for the lengths the presets lack.
RigidBodyModel RandomChain(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.2, 1.0);
  RigidBodyModel m;
  Vector3d anchor(0, 0, 0.1);
  for (int i = 0; i < n; ++i) {
    RigidJoint j;
    j.axis = Vector3d(u(*rng), u(*rng), u(*rng)).normalized();
    j.anchor_m = anchor;
    j.mass_kg = 5 * pos(*rng);
    j.com_m = anchor + 0.3 * Vector3d(u(*rng), u(*rng), u(*rng));
    const Matrix3d A = Matrix3d::Random() * 0.1;
    j.inertia_kg_m2 = A * A.transpose() + 0.01 * Matrix3d::Identity();
    j.ratio = 50 + 100 * pos(*rng);
    j.rotor_inertia_kg_m2 = 1e-5 * pos(*rng);
    j.rotor_mass_kg = 0.3 * pos(*rng);
    j.rotor_centre_m = anchor + 0.05 * j.axis.unitOrthogonal();
    m.joints.push_back(j);
    anchor += 0.4 * Vector3d(u(*rng), u(*rng), u(*rng));
  }
  return m;
}

// Every body's motion, written from rigid_body_dynamics.h's description: the zero-pose geometry
// carried by X_i = X_{i-1} ∘ (rotation by q_i about joint i); a point x of link i moves at
// Σ_{k≤i} q̇_k z_k × (x − p_k); rotor i's centre is a point of link i, it turns at
// ω_{i-1} + γ_i q̇_i z_i. Returns the kinetic energy (links and rotors, translation and
// rotation) and the potential energy of gravity.
struct Energies {
  double kinetic_J = 0, potential_J = 0;
};

Energies BodyEnergies(const RigidBodyModel& m, const VectorXd& q, const VectorXd& qd) {
  const int n = static_cast<int>(m.joints.size());
  std::vector<Vector3d> z(n), p(n), w(n);
  Matrix3d R = Matrix3d::Identity();
  Vector3d t = Vector3d::Zero(), wp = Vector3d::Zero();
  Energies e;
  auto velocity = [&](const Vector3d& x, int i) {
    Vector3d v = Vector3d::Zero();
    for (int k = 0; k <= i; ++k) v += qd[k] * z[k].cross(x - p[k]);
    return v;
  };
  for (int i = 0; i < n; ++i) {
    const RigidJoint& j = m.joints[i];
    p[i] = R * j.anchor_m + t;
    z[i] = R * j.axis;
    const Matrix3d Rq = Eigen::AngleAxisd(q[i], j.axis).toRotationMatrix();
    t = R * (j.anchor_m - Rq * j.anchor_m) + t;
    R = R * Rq;
    w[i] = wp + qd[i] * z[i];
    const Vector3d c = R * j.com_m + t, cr = R * j.rotor_centre_m + t;
    const Vector3d wr = wp + j.ratio * qd[i] * z[i];
    const Matrix3d I = R * j.inertia_kg_m2 * R.transpose();
    e.kinetic_J += 0.5 * j.mass_kg * velocity(c, i).squaredNorm() + 0.5 * w[i].dot(I * w[i]);
    e.kinetic_J += 0.5 * j.rotor_mass_kg * velocity(cr, i).squaredNorm() + 0.5 * j.rotor_inertia_kg_m2 * wr.squaredNorm();
    e.potential_J -= m.gravity_m_s2.dot(j.mass_kg * c + j.rotor_mass_kg * cr);
    wp = w[i];
  }
  return e;
}

TEST(JointSpaceDynamicsTest, InverseDynamicsIsThePlantsNewtonEuler) {
  std::mt19937 rng(52);
  for (const auto& [name, bodies] : Presets()) {
    const JointSpaceModel model = MakeJointSpaceModel(bodies);
    const int n = model.joint_count;
    ASSERT_EQ(n, static_cast<int>(bodies.joints.size()));
    for (int k = 0; k < 36; ++k) {
      const State s = RandomState(n, &rng);
      const VectorXd ref = PlantQ(bodies, s.q, s.qd, s.qdd);
      const VectorXd Q = EngineQ(model, s.q, s.qd, s.qdd);
      EXPECT_LT((Q - ref).norm(), 1e-9 * ref.norm()) << name << " state " << k;
      // M q̈ + b, the mass matrix by composite bodies and the bias by a pass at q̈ = 0.
      VectorXd b(n);
      Bias(model, s.q.data(), s.qd.data(), b.data());
      EXPECT_LT((Mass(model, s.q) * s.qdd + b - ref).norm(), 1e-9 * ref.norm()) << name << " state " << k;
      EXPECT_LT((b - PlantQ(bodies, s.q, s.qd, VectorXd::Zero(n))).norm(), 1e-9 * b.norm()) << name << " state " << k;
    }
  }
}

TEST(JointSpaceDynamicsTest, InverseDynamicsIsThePlantsOnChainsOfOneToSevenJoints) {
  std::mt19937 rng(7);
  for (int n = 1; n <= kMaxEngineJoints; ++n) {
    const RigidBodyModel bodies = RandomChain(n, &rng);
    const JointSpaceModel model = MakeJointSpaceModel(bodies);
    for (int k = 0; k < 12; ++k) {
      const State s = RandomState(n, &rng);
      const VectorXd ref = PlantQ(bodies, s.q, s.qd, s.qdd);
      EXPECT_LT((EngineQ(model, s.q, s.qd, s.qdd) - ref).norm(), 1e-9 * ref.norm()) << n << " joints, state " << k;
      VectorXd b(n);
      Bias(model, s.q.data(), s.qd.data(), b.data());
      EXPECT_LT((Mass(model, s.q) * s.qdd + b - ref).norm(), 1e-9 * ref.norm()) << n << " joints, state " << k;
    }
  }
}

// The torque sensors' truth as the articulated step has it, τ0 + S q̈ from its one pose, is the
// plant's TransmittedTorques, on the presets and on random chains of 1 to 7 joints.
TEST(JointSpaceDynamicsTest, SensorTruthFromThePoseIsThePlantsTransmittedTorques) {
  std::mt19937 rng(11);
  std::vector<std::pair<std::string, RigidBodyModel>> chains = Presets();
  for (int n = 1; n <= kMaxEngineJoints; ++n) chains.emplace_back(std::to_string(n) + " joints", RandomChain(n, &rng));
  for (const auto& [name, bodies] : chains) {
    const JointSpaceModel model = MakeJointSpaceModel(bodies);
    const int n = model.joint_count;
    for (int k = 0; k < 12; ++k) {
      const State s = RandomState(n, &rng);
      VectorXd ref(n), tau0(n), b(n);
      TransmittedTorques(bodies, s.q.data(), s.qd.data(), s.qdd.data(), ref.data());
      JointMatrix M, S;
      MassMatrixBiasAndSensor(model, s.q.data(), s.qd.data(), &M, b.data(), &S, tau0.data());
      const VectorXd tau = tau0 + MatrixXd(S) * s.qdd;
      EXPECT_LT((tau - ref).norm(), 1e-9 * ref.norm()) << name << " state " << k;
      // The same M and bias as the engine's other calls.
      EXPECT_LT((MatrixXd(M) - Mass(model, s.q)).norm(), 1e-12 * MatrixXd(M).norm()) << name << " state " << k;
    }
  }
}

// The independent model's mass matrix, gravity and free-motion accelerations (its Coriolis and
// centrifugal terms from M's derivatives by central differences), on the plant's own ArmModel.
TEST(JointSpaceDynamicsTest, MatchesTheIndependentModel) {
  std::mt19937 rng(57);
  for (const char* preset : {"mrr-config1", "ur-class"}) {
    const ArmModel arm(RobotPreset(preset));
    const JointSpaceModel model = MakeJointSpaceModel(arm.rigid_bodies());
    const int n = model.joint_count;
    for (int k = 0; k < 6; ++k) {
      const State s = RandomState(n, &rng);
      const testing_support::RigidModel ref =
          testing_support::Independent(arm, std::vector<double>(s.q.data(), s.q.data() + n));
      EXPECT_LT((Mass(model, s.q) - ref.mass).norm(), 1e-9 * ref.mass.norm()) << preset;
      VectorXd hold(n), qdd(n);
      const VectorXd zero = VectorXd::Zero(n);
      Bias(model, s.q.data(), zero.data(), hold.data());
      EXPECT_LT((hold + ref.gravity).norm(), 1e-9 * ref.gravity.norm()) << preset;
      ForwardDynamics(model, s.q.data(), s.qd.data(), zero.data(), qdd.data());
      const VectorXd expected = testing_support::Accelerations(arm, s.q, s.qd);
      EXPECT_LT((qdd - expected).norm(), 1e-6 * expected.norm()) << preset << "\n" << qdd.transpose() << "\n"
                                                                 << expected.transpose();
    }
  }
}

// τ -> q̈ -> τ: the Cholesky solve of the composite bodies' M against the Newton-Euler pass.
TEST(JointSpaceDynamicsTest, ForwardThenInverseDynamicsReturnsTheForces) {
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> force(-60.0, 60.0);
  std::vector<std::pair<std::string, RigidBodyModel>> chains = Presets();
  chains.emplace_back("random 7-joint chain", RandomChain(7, &rng));
  for (const auto& [name, bodies] : chains) {
    const JointSpaceModel model = MakeJointSpaceModel(bodies);
    const int n = model.joint_count;
    for (int k = 0; k < 36; ++k) {
      const State s = RandomState(n, &rng);
      VectorXd Q(n), qdd(n);
      for (int i = 0; i < n; ++i) Q[i] = force(rng);
      ForwardDynamics(model, s.q.data(), s.qd.data(), Q.data(), qdd.data());
      EXPECT_LT((EngineQ(model, s.q, s.qd, qdd) - Q).norm(), 1e-9 * Q.norm()) << name << " state " << k;
      EXPECT_LT((PlantQ(bodies, s.q, s.qd, qdd) - Q).norm(), 1e-9 * Q.norm()) << name << " state " << k;
    }
  }
}

TEST(JointSpaceDynamicsTest, MassMatrixIsPositiveDefiniteAndGivesTheBodiesKineticEnergy) {
  std::mt19937 rng(54);
  for (const auto& [name, bodies] : Presets()) {
    const JointSpaceModel model = MakeJointSpaceModel(bodies);
    const int n = model.joint_count;
    for (int k = 0; k < 36; ++k) {
      const State s = RandomState(n, &rng);
      const MatrixXd M = Mass(model, s.q);
      EXPECT_EQ((M - M.transpose()).norm(), 0.0) << name;
      EXPECT_EQ(Eigen::LLT<MatrixXd>(M).info(), Eigen::Success) << name << " state " << k;
      const double T = BodyEnergies(bodies, s.q, s.qd).kinetic_J;
      EXPECT_NEAR(0.5 * s.qd.dot(M * s.qd), T, 1e-12 * T) << name << " state " << k;
    }
  }
}

// Two parallel vertical axes (a planar arm), token masses off: the rotors' energies
// ½ I_m0 (γ0 q̇0)² and ½ I_m1 (q̇0 + γ1 q̇1)², rotor 1 riding on link 0, give
//   M00 = I1 + m1 c1² + I2 + m2 (l1² + c2² + 2 l1 c2 cos q1) + γ0² I_m0 + I_m1
//   M01 = I2 + m2 (c2² + l1 c2 cos q1) + γ1 I_m1
//   M11 = I2 + m2 c2² + γ1² I_m1.
// A plain armature (γ² I_m on the diagonal) lacks γ1 I_m1 in M01 and I_m1 in M00.
TEST(JointSpaceDynamicsTest, RotorCouplingOnATwoJointChain) {
  const double m1 = 3.0, c1 = 0.2, I1 = 0.05, l1 = 0.5, m2 = 2.0, c2 = 0.25, I2 = 0.03;
  const double g0 = 101, g1 = 81, Im0 = 3.5e-5, Im1 = 2.0e-5;
  RigidBodyModel bodies;
  RigidJoint j0, j1;
  j0.mass_kg = m1, j0.com_m = Vector3d(c1, 0, 0), j0.inertia_kg_m2 = Vector3d(0.02, 0.04, I1).asDiagonal();
  j0.ratio = g0, j0.rotor_inertia_kg_m2 = Im0, j0.rotor_centre_m = Vector3d(0, 0.05, 0);
  j1.anchor_m = Vector3d(l1, 0, 0);
  j1.mass_kg = m2, j1.com_m = Vector3d(l1 + c2, 0, 0), j1.inertia_kg_m2 = Vector3d(0.01, 0.02, I2).asDiagonal();
  j1.ratio = g1, j1.rotor_inertia_kg_m2 = Im1, j1.rotor_centre_m = Vector3d(l1, 0.05, 0);
  bodies.joints = {j0, j1};
  const JointSpaceModel model = MakeJointSpaceModel(bodies);
  for (double q1 : {0.0, 0.7, -2.1}) {
    const VectorXd q = Eigen::Vector2d(0.4, q1);
    Eigen::Matrix2d expected;
    expected(0, 0) = I1 + m1 * c1 * c1 + I2 + m2 * (l1 * l1 + c2 * c2 + 2 * l1 * c2 * std::cos(q1)) + g0 * g0 * Im0 + Im1;
    expected(0, 1) = expected(1, 0) = I2 + m2 * (c2 * c2 + l1 * c2 * std::cos(q1)) + g1 * Im1;
    expected(1, 1) = I2 + m2 * c2 * c2 + g1 * g1 * Im1;
    const MatrixXd M = Mass(model, q);
    EXPECT_LT((M - expected).norm(), 1e-12 * expected.norm()) << M;
    // A plain armature's M is off by far more than the tolerance above.
    Eigen::Matrix2d armature = expected;
    armature(0, 0) -= Im1;
    armature(0, 1) = armature(1, 0) = expected(0, 1) - g1 * Im1;
    EXPECT_GT((M - armature).norm(), 1e-3 * expected.norm());
  }
}

// On the presets: the rotors' share of M, M − M(I_m = 0), is Σ_i I_m,i J_r,i' J_r,i with
// rotor i's angular Jacobian J_r,i = [z_0 .. z_{i-1}, γ_i z_i, 0 ..]; its off-diagonal
// γ_i I_m,i z_k·z_i is what a plain armature model drops.
TEST(JointSpaceDynamicsTest, RotorCouplingOnThePresets) {
  std::mt19937 rng(55);
  for (const auto& [name, bodies] : Presets()) {
    RigidBodyModel without = bodies;
    for (RigidJoint& j : without.joints) j.rotor_inertia_kg_m2 = 0;
    const JointSpaceModel model = MakeJointSpaceModel(bodies), bare = MakeJointSpaceModel(without);
    const int n = model.joint_count;
    for (int k = 0; k < 12; ++k) {
      const State s = RandomState(n, &rng);
      // z_i at this pose, from the plant's rotations.
      std::vector<Vector3d> z(n);
      Matrix3d R = Matrix3d::Identity();
      for (int i = 0; i < n; ++i) {
        z[i] = R * bodies.joints[i].axis;
        R = R * Eigen::AngleAxisd(s.q[i], bodies.joints[i].axis).toRotationMatrix();
      }
      MatrixXd expected = MatrixXd::Zero(n, n), armature = MatrixXd::Zero(n, n);
      for (int i = 0; i < n; ++i) {
        const RigidJoint& j = bodies.joints[i];
        MatrixXd Jr = MatrixXd::Zero(3, n);
        for (int c = 0; c < i; ++c) Jr.col(c) = z[c];
        Jr.col(i) = j.ratio * z[i];
        expected += j.rotor_inertia_kg_m2 * Jr.transpose() * Jr;
        armature(i, i) = j.ratio * j.ratio * j.rotor_inertia_kg_m2;
      }
      const MatrixXd rotors = Mass(model, s.q) - Mass(bare, s.q);
      EXPECT_LT((rotors - expected).norm(), 1e-9 * expected.norm()) << name << "\n" << rotors << "\n" << expected;
      for (int i = 1; i < n; ++i) {
        const RigidJoint& j = bodies.joints[i];
        if (std::fabs(z[i - 1].dot(z[i])) < 0.1) continue;  // crossed axes: no coupling
        // M_{i-1,i}'s rotor share: rotor i's gear coupling, and the rotors beyond carried along.
        const double coupling = j.ratio * j.rotor_inertia_kg_m2 * z[i - 1].dot(z[i]);
        double carried = 0;
        for (int r = i + 1; r < n; ++r) carried += bodies.joints[r].rotor_inertia_kg_m2 * z[i - 1].dot(z[i]);
        EXPECT_NEAR(rotors(i - 1, i) - carried, coupling, 1e-9 * std::fabs(coupling)) << name << " joints " << i << ", " << i + 1;
        EXPECT_GT(std::fabs(coupling), 10 * std::fabs(carried)) << name;
        EXPECT_EQ(armature(i - 1, i), 0.0);  // what a plain armature has there
      }
    }
  }
}

// Q = 0, gravity on, no friction: RK4 at 0.2 ms over 3 s keeps kinetic + potential energy (from
// the bodies here) within 1e-10 of the largest kinetic energy (measured: 2e-14 mrr-config1, 4e-14 ur-class).
TEST(JointSpaceDynamicsTest, UnforcedChainKeepsItsEnergy) {
  for (const auto& [name, bodies] : Presets()) {
    const JointSpaceModel model = MakeJointSpaceModel(bodies);
    const int n = model.joint_count;
    const VectorXd zero = VectorXd::Zero(n);
    auto accel = [&](const VectorXd& q, const VectorXd& qd) {
      VectorXd qdd(n);
      ForwardDynamics(model, q.data(), qd.data(), zero.data(), qdd.data());
      return qdd;
    };
    VectorXd q = VectorXd::LinSpaced(n, 0.3, -0.9), qd = VectorXd::LinSpaced(n, 1.0, -1.5);
    const double h_s = 2e-4, duration_s = 3.0;
    auto energy = [&](const VectorXd& a, const VectorXd& b) {
      const Energies e = BodyEnergies(bodies, a, b);
      return e.kinetic_J + e.potential_J;
    };
    const double e0 = energy(q, qd);
    double drift = 0, kinetic_max = 0;
    for (int k = 0; k < static_cast<int>(duration_s / h_s); ++k) {
      const VectorXd k1q = qd, k1v = accel(q, qd);
      const VectorXd k2q = qd + 0.5 * h_s * k1v, k2v = accel(q + 0.5 * h_s * k1q, k2q);
      const VectorXd k3q = qd + 0.5 * h_s * k2v, k3v = accel(q + 0.5 * h_s * k2q, k3q);
      const VectorXd k4q = qd + h_s * k3v, k4v = accel(q + h_s * k3q, k4q);
      q += h_s / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
      qd += h_s / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      drift = std::max(drift, std::fabs(energy(q, qd) - e0));
      kinetic_max = std::max(kinetic_max, BodyEnergies(bodies, q, qd).kinetic_J);
    }
    char text[64];
    std::snprintf(text, sizeof text, "%.3g J of %.3g J kinetic", drift, kinetic_max);
    RecordProperty(name + "_energy_drift", text);
    EXPECT_GT(kinetic_max, 1.0) << name;  // it moves
    EXPECT_LT(drift, 1e-10 * kinetic_max) << name << ": drift " << drift << " J, kinetic up to " << kinetic_max << " J";
  }
}

TEST(JointSpaceDynamicsTest, TakesOneToSevenJoints) {
  std::mt19937 rng(56);
  EXPECT_THROW(MakeJointSpaceModel(RigidBodyModel{}), std::invalid_argument);
  EXPECT_THROW(MakeJointSpaceModel(RandomChain(8, &rng)), std::invalid_argument);
  EXPECT_EQ(MakeJointSpaceModel(RandomChain(7, &rng)).joint_count, 7);
}

}  // namespace
}  // namespace armfault
