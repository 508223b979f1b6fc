// Position-dependent torque ripple of a joint module (docs/assumptions.md, "Torque ripple"):
// the strain-wave gear's kinematic error and the motor's cogging. Both are functions of one
// angle, the rotor's (= the wave generator's) angle theta relative to the stator, theta = gamma q:
//
//   kinematic error, link side [rad]:  e(theta) = E2 sin(2 theta + phi2) + E1 sin(theta + phi1)
//   its torque, link side [N m]:       tau_ke  = K e(theta)     (K: the drive's torsional stiffness)
//   cogging, motor side [N m]:         tau_cog = C sin(N theta + phi_c)   (N: periods per revolution,
//                                                                          lcm of slots and poles)
//   on the rotor, motor side [N m]:    tau_r   = sum over lines of G(f_line) a_line sin(n theta + phi)
//                                      with a = K E / gamma for the gear's lines, C for cogging.
//
// tau_r acts as a couple between rotor and stator, like the motor torque (the gear passes K e on
// to the link). Without the band limit G it is minus the derivative of a periodic potential of
// zero mean over a revolution, so it is conservative: it stores and returns energy, never makes
// any over a revolution (RipplePotentialJ).
//
// Band limit: the line n of a rotor turning at omega has the frequency f = n |omega| / 2 pi; the
// physics step (rate f_s) samples the torque, so a line above f_s / 2 would alias. Each line is
// weighted by G(f) = 1 up to kRipplePassFraction f_s, a raised-cosine roll-off to 0 at
// kRippleStopFraction f_s, and 0 above (200 and 400 Hz at 1 kHz): cogging at speed fades out
// instead of folding back to a false low frequency.
#pragma once

namespace armfault {

// The "ripple" group of a module (docs/robot-format.md). Absent (enabled = false): no ripple,
// the plant as before. Defaults are those of a size-20 strain-wave gear and the MRR2 motor.
struct RippleParams {
  bool enabled = false;  // the module's "ripple" group was given
  double kinematic_error_2x_arcmin = 0.3;     // E2, amplitude at twice the wave generator's frequency, link side
  double kinematic_error_1x_arcmin = 0.1;     // E1, amplitude at the wave generator's frequency, link side
  double phase_2x_deg = 0;                    // phi2 (this unit's)
  double phase_1x_deg = 0;                    // phi1
  double drive_stiffness_Nm_per_rad = 13000;  // K, link side (catalogue K1 of a size-20 gear)
  double cogging_Nm = 0.01;                   // C, motor side (2 % of the MRR2's rated 0.508 N m)
  double cogging_periods_per_rev = 18;        // N: lcm(9 slots, 6 poles)
  double cogging_phase_deg = 0;               // phi_c
  // Not a JSON key: false only in tests, to show what the spectrum test catches without G.
  bool band_limited = true;
};

// Fractions of the physics rate where the band limit's roll-off starts and ends.
inline constexpr double kRipplePassFraction = 0.2;
inline constexpr double kRippleStopFraction = 0.4;

// G(f) for a line at `line_frequency_Hz` (>= 0) under a physics rate of `physics_rate_Hz`.
double RippleBandGain(double line_frequency_Hz, double physics_rate_Hz);

// tau_r [N m, motor side, on the rotor against the stator] at rotor angle `rotor_angle_rad`
// (relative to the stator) turning at `rotor_speed_rad_s`; `gear_ratio` gamma.
double RippleTorqueNm(const RippleParams& p, double gear_ratio, double rotor_angle_rad, double rotor_speed_rad_s,
                      double physics_rate_Hz);

// The potential V(theta) [J] of tau_r without the band limit: tau_r = -dV/dtheta, zero mean over
// a revolution. The ripple's work from theta_a to theta_b is V(theta_a) - V(theta_b).
double RipplePotentialJ(const RippleParams& p, double gear_ratio, double rotor_angle_rad);

// The line frequencies [Hz] of a rotor turning at `rotor_speed_rad_s`: 1x, 2x and cogging.
struct RippleLines {
  double once_Hz = 0, twice_Hz = 0, cogging_Hz = 0;
};
RippleLines RippleLineFrequencies(const RippleParams& p, double rotor_speed_rad_s);

}  // namespace armfault
