// Load-dependent friction of the strain-wave gear: grows with the transmitted
// torque and depends on the direction of power flow,
//   F_load = mu |tau| / ratio   [N m, motor side],  mu = load_friction_driving     if tau qd > 0
//                                                       = load_friction_backdriven  if tau qd < 0
//                                                       = load_friction_driving     if tau qd = 0
// (at rest the drive holds its load: the driving coefficient). It is added to the rotor's
// bounded dry-friction row (core/plant/simulation.h), so it always opposes the rotor's motion
// relative to its stator and only dissipates; the row's constraint torque, not this bound, is
// what the energy books (p_friction).
//
// The transmitted torque and the velocity come out of the ODE step this bound is an input to:
// the term uses the PREVIOUS physics step's values (no iteration), as the existing mesh loss
// (HarmonicDriveParams::mesh_loss_fraction) does. At 1 kHz the lag is 1 ms, far below the
// drive's mechanical time constants; the energy balance still closes because the dissipated
// power is read back from the constraint (tests: LoadFriction* in simulation_test.cc).
#pragma once

#include "core/plant/parts/gear_thermal.h"

namespace armfault {

enum class PowerFlow { kDriving, kBackDriven };

// Which way power flows through the gear for transmitted torque tau (link side) at link
// velocity qd: driving when the motor does work on the link (tau qd >= 0).
PowerFlow PowerFlowOf(double tau_Nm, double qd_rad_s);

// The load-dependent dry-friction bound [N m, motor side] (>= 0), 0 without a gearbox group.
double LoadFrictionNm(const GearboxParams& p, double tau_Nm, double qd_rad_s, double ratio);

}  // namespace armfault
