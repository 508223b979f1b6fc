// Joint friction, thesis eq 3-8. Inputs: link velocity q_dot [rad/s]. Output: friction torque
// on the motor shaft [N m], opposing motion:
//   f(q_dot) = b q_dot + (F_c + F_s exp(-F_t q_dot^2)) sat(q_dot),  sat(0) = 0.
// In the simulation the Coulomb + Stribeck part is imposed as a bounded constraint torque
// (exact stiction, no chatter at zero velocity) and the viscous part as an applied torque.
#pragma once

#include "core/plant/robot/robot_config.h"

namespace armfault {

// |Coulomb + Stribeck| part at q_dot [N m, motor side]; at q_dot = 0 it is F_c + F_s, the
// breakaway torque.
double BreakawayFrictionNm(const FrictionParams& p, double factor, double qd_rad_s);
// Viscous part b q_dot [N m, motor side], signed.
double ViscousFrictionNm(const FrictionParams& p, double factor, double qd_rad_s);
// The full eq 3-8 value, signed [N m, motor side].
double FrictionTorqueNm(const FrictionParams& p, double factor, double qd_rad_s);

}  // namespace armfault
