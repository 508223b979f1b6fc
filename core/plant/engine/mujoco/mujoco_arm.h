// The arm in MuJoCo, for `armfault bench` only: Debian's MuJoCo (libmujoco-dev, 2.2.2 on
// Debian 12) stepping the same chain as ODE and the joint-space engine, so that a user sees the
// three engines' µs per step side by side. An optional dependency: CMake finds it if present
// (ARMFAULT_HAVE_MUJOCO inside mujoco_arm.cc) and the library is opened when first used
// (dlopen: the binary itself does not need it); without it MujocoBuiltIn() is false and
// MujocoArm throws. No run uses MuJoCo.
//
// The model differs from the plant's, and the bench says so: each rotor is a joint armature
// γ²·I_m (the rotor's spin reflected through the gear onto its own joint only), where the plant
// and the joint-space engine have the geared rotor riding on the link before its joint, with its
// I_m·γ coupling to every joint before it and its carrier's rotation
// (core/plant/engine/joint_space_dynamics.h). Links, their inertias (the rotors' token masses
// lumped in), the joint axes, the anchors and gravity are the same.
//
// MujocoArmXml: MJCF text from the chain (JointSpaceModel, built from the robot's rigid bodies):
// one body per joint nested in the previous one at `offset_m` [m] with the world's axes at the
// zero pose, a hinge about `axis` through the body's origin with armature γ²·I_m [kg m²] and
// frictionloss [N m, link side], the link's inertial (mass [kg], centre [m], full inertia about
// it [kg m²], body axes); gravity [m/s²]; timestep `dt_s` [s], MuJoCo's semi-implicit Euler
// integrator (first order, as ODE's step and the joint-space engine's). No geometry: no contacts.
//
// MujocoArm: the model loaded (through MuJoCo's virtual file system, no file on disk) and its
// data. StepFromRest: from rest at the zero pose with no joint torque, `steps` calls of mj_step;
// the dry-friction rows are MuJoCo's frictionloss constraints at `friction_loss_Nm` (link side:
// the plant's motor-side bound times γ). Returns a checksum of the final angles (so that the
// stepping is not optimised away). Loading throws std::runtime_error when MuJoCo is not built in
// or refuses the model (with its message). Not thread-safe: one per thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/plant/engine/joint_space_dynamics.h"

namespace armfault {

// True when armfault was built with MuJoCo's headers and its library loads (opened at the first
// call, so that the binary runs without it).
bool MujocoBuiltIn();
// MuJoCo's version as it reports it ("2.2.2"), or "" when not built in.
std::string MujocoVersion();
// Why MuJoCo is not there ("not built in (...)" or "could not be loaded (...)"); "" when it is.
std::string MujocoProblem();

// `friction_loss_Nm`: per joint, link side (empty: none).
std::string MujocoArmXml(const JointSpaceModel& chain, double dt_s, const std::vector<double>& friction_loss_Nm);

class MujocoArm {
 public:
  // `friction_loss_Nm`: per joint, link side (empty: none).
  MujocoArm(const JointSpaceModel& chain, double dt_s, const std::vector<double>& friction_loss_Nm);
  ~MujocoArm();
  MujocoArm(const MujocoArm&) = delete;
  MujocoArm& operator=(const MujocoArm&) = delete;

  double StepFromRest(long steps);
  // MuJoCo's joint-space mass matrix (n × n, row-major in `M`) [kg m²] and bias forces
  // (Coriolis, centrifugal and gravity, `bias_Nm`, n) [N m] at angles `q` [rad] and rates `qd`
  // [rad/s]: the tests' check of the generated model.
  void MassAndBias(const double* q, const double* qd, std::vector<double>* M, std::vector<double>* bias_Nm);

 private:
  struct Loaded;
  std::unique_ptr<Loaded> loaded_;
};

}  // namespace armfault
