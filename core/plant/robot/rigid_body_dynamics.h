// The arm's rigid bodies as a model of their own, outside ODE: what a controller's feedforward
// and a monitor's virtual torque sensor compute from the robot's description (its URDF or its
// links), never from a run's state.
//
// Bodies, as the plant builds them (core/plant/simulation.h): per joint i the link body (the
// payload lumped into the last one) and the rotor, carried by link i with its centre at
// `rotor_centre_m`, isotropic I_m, turning at ω_{i-1} + γ q̇_i z_i (a token mass).
//
// TransmittedTorques: recursive Newton-Euler in world coordinates. Inputs: joint angles q [rad],
// rates q̇ [rad/s], accelerations q̈ [rad/s²]. Output per joint i: the torque about z_i that
// the harmonic drive passes to link i [N m, link side], the reading of an ideal torque sensor on
// the drive's output: z_i · Σ over the bodies beyond the drive (links i..n, rotors i+1..n) of
//   (r_b − p_i) × m_b (a_b − g) + I_b α_b + ω_b × I_b ω_b.
// Rotor i is not beyond its own drive: its inertia is the motor's (the controller's I_m γ q̈
// and the monitor's I_r q̈ and coupling terms).
#pragma once

#include <Eigen/Dense>

#include <vector>

#include "core/plant/robot/robot_config.h"

namespace armfault {

struct RigidJoint {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();      // unit joint axis, zero pose, world
  Eigen::Vector3d anchor_m = Eigen::Vector3d::Zero();   // a point on the axis, zero pose, world
  double mass_kg = 0;                                   // link body (+ payload on the last)
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();      // its centre of mass, zero pose, world
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about the centre of mass, zero-pose world axes
  double ratio = 1;                                     // γ
  double rotor_inertia_kg_m2 = 0;                       // I_m (isotropic)
  double rotor_mass_kg = 0;
  Eigen::Vector3d rotor_centre_m = Eigen::Vector3d::Zero();  // on link i, zero pose, world
};

struct RigidBodyModel {
  std::vector<RigidJoint> joints;  // base first
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
};

// The robot's bodies exactly as ArmModel hands them to ODE, with `payload_kg` lumped into the
// last link (the robot's own payload_kg for the nominal model). No checks: ArmModel checks.
RigidBodyModel MakeRigidBodyModel(const RobotConfig& robot, double payload_kg);

// `q`, `qd`, `qdd`, `tau_Nm`: arrays of joints.size(). See the header comment.
void TransmittedTorques(const RigidBodyModel& model, const double* q, const double* qd, const double* qdd,
                        double* tau_Nm);

// What joint i's own rotor needs beyond the transmitted torque, at the link side: its spin
// geared up, γ z_i · I_m α_rotor,i, and its token mass carried about the joint. With
// TransmittedTorques, the generalised force of joint i: Q_i = τ_i + this. `rotor_Nm`: joints.size().
void RotorTorques(const RigidBodyModel& model, const double* q, const double* qd, const double* qdd, double* rotor_Nm);

}  // namespace armfault
