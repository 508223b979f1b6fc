// A joint-space engine for a serial chain of 1 to 7 revolute joints, contact-free: the arm's
// mass matrix, bias forces and forward and inverse dynamics in the joint coordinates, beside
// ODE, from the same bodies (core/plant/robot/rigid_body_dynamics.h, MakeRigidBodyModel).
//
// Bodies, as the plant has them: per joint i the link body (the payload lumped into the last
// one) and rotor i, isotropic I_m,i, its token mass at `rotor_centre_m` moving with link i, its
// spin inertia turning at ω_r,i = ω_{i-1} + γ_i q̇_i z_i: it rides on link i-1 (the base for
// i = 0) and turns with joint i through the gear. Isotropic, so only ω_r,i matters, not its
// orientation. The model lumps the token mass into link i (exact: it moves rigidly with it)
// and keeps the spin inertia apart.
//
// Frames: frame i has its origin on joint i's axis at `anchor_m` and the world's axes at the
// zero pose; it moves with link i. Its origin in frame i-1 (the world for i = 0) is
// `offset_m`, constant; z_i is `axis` in frame i-1 (and in frame i). A call works in world
// coordinates at the current pose, spatial vectors about the world origin O:
//   R_i = R_{i-1} Rot(axis_i, q_i),  p_i = p_{i-1} + R_{i-1} offset_i,  z_i = R_{i-1} axis_i,
//   joint i's motion s_i = (z_i, p_i × z_i)  (angular; linear velocity of the point at O).
//
// Units: q [rad], q̇ [rad/s], q̈ [rad/s²], Q, b [N m at the link side], M [kg m²].
// Q_i is the generalised force of joint i, the plant's TransmittedTorques_i + RotorTorques_i:
//   M(q) q̈ + b(q, q̇) = Q.
//
// Kinetic energy, and from it M:
//   T = Σ_i ½ (m_i |v_c,i|² + ω_i' I_c,i ω_i) + Σ_i ½ I_m,i |ω_{i-1} + γ_i q̇_i z_i|².
// The rotor's spin γ_i q̇_i z_i on top of its carrier's ω_{i-1} couples joint i to every joint
// k < i: M_ki gains γ_i I_m,i z_k·z_i, M_ii gains γ_i² I_m,i, and M_kl (k, l < i) gains
// I_m,i z_k·z_l. A plain armature (γ² I_m on the diagonal only) drops the first two kinds.
//
// MassMatrix: composite rigid bodies (CRBA). I^C_i = links i..n-1 and the spin inertias of
// rotors i+1..n-1 (riding on links i..n-2), summed about O; M_ki = s_k' I^C_i s_i (k ≤ i),
// plus the rotor terms above.
// Bias: b = Q at q̈ = 0, one recursive Newton-Euler pass (RNEA) with gravity as the base's
// upward acceleration: A_i = A_{i-1} + s_i q̈_i + V_i ×m s_i q̇_i, f_i = I_i A_i + V_i ×f I_i V_i,
// rotor i's wrench (I_m,i α_r,i, 0) on link i-1 with α_r,i = α_{i-1} + γ_i q̈_i z_i +
// γ_i q̇_i ω_{i-1} × z_i; Q_i = s_i · F_i + γ_i z_i · I_m,i α_r,i, F_i = the wrenches beyond
// joint i (links i.., rotors i+1..).
// InverseDynamics: the same pass with q̈ (equal to M q̈ + b, O(n)).
// ForwardDynamics: q̈ = M⁻¹ (Q − b), Cholesky (Eigen LLT). M is positive definite when every
// joint moves some inertia (γ_i² I_m,i > 0 suffices).
//
// Cost: O(n) for Bias and InverseDynamics, O(n²) for MassMatrix, O(n³) for the solve, n ≤ 7;
// the pose (a sine and cosine and the bodies' inertias turned to the world a joint) is most of
// it. Measured (bench/engine_bench.cc, a shared 2-core machine): ForwardDynamics 0.36 us on
// mrr-config1 (3 joints), 0.76 us on ur-class (6); ODE's step of a three-joint arm takes about 4.6 us here.
// No heap: fixed-size storage (at most 7 joints) on the stack. Thread-safe: the model is
// immutable and read-only, a call keeps its state on its own stack.
#pragma once

#include <Eigen/Dense>

#include <array>

#include "core/plant/robot/rigid_body_dynamics.h"

namespace armfault {

constexpr int kMaxEngineJoints = 7;

// n x n, at most 7 x 7, storage inside the object (no heap).
using JointMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxEngineJoints,
                                  kMaxEngineJoints>;

struct JointSpaceJoint {
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();  // frame i's origin in frame i-1 (world for i = 0)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();     // unit z_i in frame i-1 (and frame i)
  // Link i's spatial inertia, the rotor's token mass lumped in, in frame i.
  double mass_kg = 0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();          // centre of mass in frame i
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about it, frame i's axes
  // Rotor i's spin inertia: I_m,i E₃, the same in every frame; rides on link i-1.
  double rotor_inertia_kg_m2 = 0;
  double ratio = 1;  // γ_i, rotor turns per joint turn
  // Rotor i's token mass (lumped into link i above) and its centre in frame i: what the torque
  // sensor of joint i does not carry (MassMatrixBiasAndSensor).
  double rotor_mass_kg = 0;
  Eigen::Vector3d rotor_centre_m = Eigen::Vector3d::Zero();
};

// Built once from the plant's bodies; immutable, shared read-only.
struct JointSpaceModel {
  int joint_count = 0;
  std::array<JointSpaceJoint, kMaxEngineJoints> joints;  // base first; joint_count used
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
};

// Throws std::invalid_argument for a chain of no joint or more than 7 (the caller validates).
JointSpaceModel MakeJointSpaceModel(const RigidBodyModel& bodies);

// Arrays of model.joint_count(). See the header comment.
void MassMatrix(const JointSpaceModel& model, const double* q, JointMatrix* M);
void Bias(const JointSpaceModel& model, const double* q, const double* qd, double* b_Nm);
// Both at one pose (the articulated engine's step, core/plant/engine/articulated_world.h).
void MassMatrixAndBias(const JointSpaceModel& model, const double* q, const double* qd, JointMatrix* M, double* b_Nm);
// The same, and the torque sensors' truth as τ = τ0 + S q̈ [N m, link side]: per joint i the
// torque about z_i that the harmonic drive passes to link i, the plant's TransmittedTorques
// (core/plant/robot/rigid_body_dynamics.h) at (q, q̇, q̈). Q_i = s_i · F_i + γ_i z_i · I_m,i α_r,i
// (F_i the wrench of the bodies beyond joint i); the sensor carries s_i · F_i less rotor i's
// token mass (lumped into link i, yet not beyond its own drive). Both are linear in q̈: τ0 is
// the sensors' reading at q̈ = 0 (from the bias pass), S (n × n) is M less, in row i, rotor i's
// spin and token mass (CRBA's terms). So the step needs no second Newton-Euler pass once it
// knows q̈.
void MassMatrixBiasAndSensor(const JointSpaceModel& model, const double* q, const double* qd, JointMatrix* M, double* b_Nm,
                             JointMatrix* S, double* tau0_Nm);
void ForwardDynamics(const JointSpaceModel& model, const double* q, const double* qd, const double* Q_Nm,
                     double* qdd);
void InverseDynamics(const JointSpaceModel& model, const double* q, const double* qd, const double* qdd,
                     double* Q_Nm);

}  // namespace armfault
