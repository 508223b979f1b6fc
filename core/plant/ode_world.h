// The arm in ODE for one run (the reference engine, core/plant/engine/arm_world.h): per joint a
// link body with its hinge to the parent, and a rotor body with its hinge to the link, its gear
// (a transmission joint in planetary form) to the parent and its dry-friction row (an AMotor)
// against the parent; the model is described in core/plant/simulation.h. A step is dWorldStep:
// semi-implicit Euler, first order (velocities from the forces at the step's start and the
// constraint rows solved at its end velocity, Dantzig's exact LCP; then positions from the new
// velocities), the rows regularised by the robot's constraint_force_mixing.
//
// Readout after a step (Joint): the hinge's angle, unwrapped against the last one; its rate; the
// rotor's rate relative to its stator; the transmitted torque, the moment about the joint axis
// of the rotor hinge's wrench on the link (the gear reaction through the planet's carrier, read
// from the joint feedback); and the AMotor row's torque on the rotor (its feedback).
#pragma once

#include <ode/ode.h>

#include <Eigen/Dense>

#include <memory>
#include <vector>

#include "core/plant/engine/arm_world.h"
#include "core/plant/simulation.h"

namespace armfault {

struct OwnedWorld;  // the ODE world and its threading implementation (ode_world.cc)

class OdeWorld : public ArmWorld {
 public:
  // Builds the bodies and joints at the angles `q0` and rates `qd0` [rad, rad/s]. Throws
  // OdeError (core/plant/ode_runtime.h) if ODE fails; nothing is left behind then.
  OdeWorld(const ArmModel& model, const std::vector<double>& q0, const std::vector<double>& qd0);
  ~OdeWorld() override;
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;

  // ArmWorld.
  void SetJoint(int j, double couple_Nm, double dry_bound_Nm) override;
  void Step(double dt_s) override;
  JointReadout Joint(int j) const override { return readout_[j]; }
  double KineticEnergy_J() const override { return KineticEnergyOf(bodies_) + KineticEnergyOf(rotors_); }
  double PotentialEnergy_J() const override { return PotentialEnergyOf(bodies_, gravity_m_s2_) + PotentialEnergyOf(rotors_, gravity_m_s2_); }

  // ODE itself, for bare stepping and kinematic cross-checks (core/plant/simulation.h).
  dWorldID world() const { return world_; }
  dBodyID body(int i) const { return bodies_[i]; }
  dJointID joint(int i) const { return joints_[i]; }
  dJointID drag(int i) const { return drags_[i]; }

 private:
  static double KineticEnergyOf(const std::vector<dBodyID>& bodies);
  static double PotentialEnergyOf(const std::vector<dBodyID>& bodies, double g);
  dBodyID parent(int i) const { return i == 0 ? nullptr : bodies_[i - 1]; }  // null: the world
  // Rotor speed relative to its stator (the parent) about the joint axis [rad/s].
  double RotorRate(int i, const Eigen::Vector3d& axis) const;

  std::unique_ptr<OwnedWorld> owned_;  // first: released last, even when the constructor throws
  dWorldID world_ = nullptr;
  dBodyID ground_ = nullptr;
  double gravity_m_s2_ = 0;
  std::vector<dBodyID> bodies_, rotors_;
  std::vector<dJointID> joints_, rotor_hinges_, drags_;
  std::vector<dJointFeedback> rotor_feedback_, drag_feedback_;
  std::vector<double> q_initial_;          // the angles the run started at (the hinges' zero)
  std::vector<Eigen::Vector3d> step_axis_;  // joint axes (world) at the start of the step
  std::vector<JointReadout> readout_;
};

}  // namespace armfault
