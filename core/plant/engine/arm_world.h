// The mechanics of one run as the simulation sees it, whichever engine steps it: ODE's world of
// bodies and constraint rows (core/plant/ode_world.h) or the joint-space engine
// (core/plant/engine/articulated_world.h). The simulation (core/plant/simulation.cc) drives the
// joints through this interface only; the drive network, sensors and controllers are the same.
//
// A physics step, per joint j (all torques about z_j, motor side: on the rotor, the reaction on
// its stator, the link before joint j or the world):
//   SetJoint(j, couple_Nm, dry_bound_Nm)  the motor torque less viscous friction plus ripple, a
//       couple between rotor and stator; and the bound of the dry-friction row (Coulomb,
//       Stribeck, mesh loss, load friction and brake) that drives the rotor's rate relative to
//       its stator to zero within ±dry_bound_Nm.
//   Step(dt_s)
//   Joint(j)  the state at the step's end and what the step's constraint rows carried.
#pragma once

namespace armfault {

struct JointReadout {
  double q_rad = 0;               // joint angle, unwrapped (continuous from the run's start)
  double qd_rad_s = 0;            // joint rate
  double rotor_rate_rad_s = 0;    // rotor rate relative to its stator about z_j
  double tau_transmitted_Nm = 0;  // the torque the harmonic drive passes to link j (the sensor's truth)
  double dry_torque_Nm = 0;       // the dry-friction row's torque on the rotor in the step (motor side, signed)
};

class ArmWorld {
 public:
  virtual ~ArmWorld() = default;
  // Joint j's inputs for the next Step; each joint is set before every Step.
  virtual void SetJoint(int j, double couple_Nm, double dry_bound_Nm) = 0;
  virtual void Step(double dt_s) = 0;
  virtual JointReadout Joint(int j) const = 0;
  // Links and rotors: kinetic energy, and potential energy in gravity (world z up) [J].
  virtual double KineticEnergy_J() const = 0;
  virtual double PotentialEnergy_J() const = 0;
};

}  // namespace armfault
