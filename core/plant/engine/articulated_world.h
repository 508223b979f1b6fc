// The articulated engine: one run's mechanics in the joint coordinates of a contact-free serial
// chain of 1 to 7 revolute joints (core/plant/engine/joint_space_dynamics.h), beside ODE
// (core/plant/ode_world.h) and behind the same interface (core/plant/engine/arm_world.h).
//
// Model (ArticulatedModel, built once, immutable, shared between threads): the plant's bodies
// (core/plant/robot/rigid_body_dynamics.h: links, payload in the last, geared rotors with the
// I_m γ coupling) as a JointSpaceModel, and the rows' constraint force mixing (the robot's
// constraint_force_mixing, as ODE's world has it). Per-run state: ArticulatedWorld.
//
// A step of dt from (q, q̇), with per joint the couple C_j [N m, motor side] between rotor and
// stator and the dry-friction bound F_j ≥ 0 [N m, motor side] (core/plant/engine/arm_world.h):
//   M(q) q̈ = Q − b(q, q̇) + Γ λ,     Q_j = γ_j C_j,  Γ = diag(γ_j)
// The couple acts on the rotor and its reaction on the stator; its virtual power is C_j times
// the rotor's rate relative to the stator, γ_j q̇_j, hence Q_j = γ_j C_j; the same holds for the
// dry-friction torque λ_j on the rotor. λ solves, as ODE's AMotor rows with dParamFMax do, the
// box-constrained problem at the step's end velocity, row j's velocity being the rotor's rate
// relative to its stator, w_j = γ_j q̇⁺_j (target 0), soft by the CFM ε as ODE makes its rows:
//   w + ε λ = A λ + c,  A = dt Γ M⁻¹ Γ + ε E,  c = Γ (q̇ + dt M⁻¹ (Q − b)),
//   |λ_j| ≤ F_j;  λ_j = −F_j ⇒ (w + ελ)_j ≥ 0;  λ_j = F_j ⇒ (w + ελ)_j ≤ 0;  else (w + ελ)_j = 0,
// i.e. min ½ λ'Aλ + c'λ over the box: strictly convex (M, A positive definite), one solution,
// found exactly by a primal active-set method (SolveBoxLcp; n ≤ 7). A joint whose rows stick
// ends the step with its rotor at rest relative to its stator (to ε λ_j): the brake and
// stiction hold exactly, not by a stiff spring. The bound F_j is what the caller sets before
// the step, from the previous step's transmitted torque and rate (mesh loss, load friction,
// Stribeck): the one-step lag of the friction row is kept, as in the ODE path (the simulation's
// DriveJoint computes the bound for either engine).
//
// Integrator: semi-implicit (symplectic) Euler, first order, as ODE's dWorldStep:
//   q̇⁺ = q̇ + dt q̈(q, q̇, λ),  q⁺ = q + dt q̇⁺,
// M and b at the step's start. The joints' constraints (hinges, gears) are exact here, where
// ODE keeps them to within its CFM and ERP: part of the gap between the engines is that model
// difference (tests/core/plant/engine/articulated_world_test.cc measures it).
//
// Readout (JointReadout): q⁺, q̇⁺, the rotor rate γ q̇⁺, the dry-friction torque λ; the
// transmitted torque is the torque sensor's truth as the ODE path defines it, the moment about
// z_j of what the harmonic drive passes to link j: the plant's TransmittedTorques at the step's
// start state (q, q̇) with the step's acceleration q̈ = (q̇⁺ − q̇)/dt, exactly what ODE's joint
// feedback carries (its constraint forces act over the step from the start state).
// Energies: kinetic ½ q̇'M(q)q̇ (links, rotors' token masses and spin), potential Σ m g z of the
// links and the rotors' token masses.
//
// Cost per step: one pose (MassMatrixBiasAndSensor: CRBA, the bias pass and the sensors' τ0 and
// S, so the sensor's truth τ0 + S q̈ needs no second Newton-Euler pass), a Cholesky of M and
// M⁻¹ by plain loops, the active set's few Cholesky solves. Measured (`armfault bench [--robot
// ur-class] --engine articulated`, a shared 2-core machine, least CPU of 10 rounds, 2026-12-02):
// bare stepping with the friction rows 0.86 us a step on mrr-config1 (0.93-0.95 us before the
// one-pose step), ODE's 7.3-7.9 us, MuJoCo 2.2.2's 1.7-1.8 us (a different model: plain armature);
// a full 10-s run (drives, controllers, monitor) 2.6-2.7 us a step, `ratio:` 0.44-0.46 of bare
// ODE stepping (0.43-0.48 before; the machine's noise is as large as the gain). Instructions
// (valgrind --tool=callgrind, Simulate only, one healthy 10-s run, every joint moving, as
// `bench --robot`): mrr-config1 283 M → 242 M, the seven-joint KUKA iiwa 781 M → 686 M (2.8×
// the three-joint run). Of what is left on mrr-config1: this step 34 %, the drives' electrical
// sub-steps (core/plant/drive/motor.cc) 27 %, the monitor 26 %, controllers and the rest 13 %.
#pragma once

#include <memory>
#include <vector>

#include "core/plant/engine/arm_world.h"
#include "core/plant/engine/joint_space_dynamics.h"
#include "core/plant/robot/rigid_body_dynamics.h"

namespace armfault {

struct ArticulatedModel {
  JointSpaceModel chain;
  RigidBodyModel bodies;  // the same bodies: the sensor's truth and the potential energy
  double constraint_force_mixing = 0;
};

// Throws std::invalid_argument for a chain of no joint or more than 7 (the caller validates).
ArticulatedModel MakeArticulatedModel(const RigidBodyModel& bodies, double constraint_force_mixing);

// The box-constrained problem above: A (n × n, symmetric positive definite), c, bounds
// `bound` (≥ 0; 0 fixes λ_j = 0); writes λ. Returns the active-set iterations it took.
int SolveBoxLcp(const JointMatrix& A, const double* c, const double* bound, double* lambda);

class ArticulatedWorld : public ArmWorld {
 public:
  // At the angles `q0` and rates `qd0` [rad, rad/s]. Keeps a reference to `model`.
  ArticulatedWorld(const ArticulatedModel& model, const std::vector<double>& q0, const std::vector<double>& qd0);

  void SetJoint(int j, double couple_Nm, double dry_bound_Nm) override;
  void Step(double dt_s) override;
  JointReadout Joint(int j) const override;
  double KineticEnergy_J() const override;
  double PotentialEnergy_J() const override;

 private:
  const ArticulatedModel& model_;
  int n_ = 0;
  double q_[kMaxEngineJoints] = {}, qd_[kMaxEngineJoints] = {};
  double couple_Nm_[kMaxEngineJoints] = {}, bound_Nm_[kMaxEngineJoints] = {};
  double lambda_Nm_[kMaxEngineJoints] = {}, tau_Nm_[kMaxEngineJoints] = {};
};

}  // namespace armfault
