#include "core/plant/parts/torque_ripple.h"

#include <cmath>

namespace armfault {

namespace {

constexpr double kRadPerArcmin = M_PI / (180.0 * 60.0);
constexpr double kRadPerDeg = M_PI / 180.0;

// One line of tau_r: amplitude [N m, motor side], harmonic of the rotor angle, phase [rad].
struct Line {
  double amplitude_Nm;
  double harmonic;
  double phase_rad;
};

void LinesOf(const RippleParams& p, double gear_ratio, Line out[3]) {
  const double k = p.drive_stiffness_Nm_per_rad / gear_ratio;  // link-side K e, referred to the rotor
  out[0] = {k * p.kinematic_error_2x_arcmin * kRadPerArcmin, 2.0, p.phase_2x_deg * kRadPerDeg};
  out[1] = {k * p.kinematic_error_1x_arcmin * kRadPerArcmin, 1.0, p.phase_1x_deg * kRadPerDeg};
  out[2] = {p.cogging_Nm, p.cogging_periods_per_rev, p.cogging_phase_deg * kRadPerDeg};
}

}  // namespace

double RippleBandGain(double line_frequency_Hz, double physics_rate_Hz) {
  const double pass = kRipplePassFraction * physics_rate_Hz;
  const double stop = kRippleStopFraction * physics_rate_Hz;
  if (line_frequency_Hz <= pass) return 1.0;
  if (line_frequency_Hz >= stop) return 0.0;
  return 0.5 * (1.0 + std::cos(M_PI * (line_frequency_Hz - pass) / (stop - pass)));
}

double RippleTorqueNm(const RippleParams& p, double gear_ratio, double rotor_angle_rad, double rotor_speed_rad_s,
                      double physics_rate_Hz) {
  Line lines[3];
  LinesOf(p, gear_ratio, lines);
  const double turns_per_s = std::fabs(rotor_speed_rad_s) / (2.0 * M_PI);
  double tau = 0;
  for (const Line& l : lines) {
    if (l.amplitude_Nm == 0) continue;
    const double gain = p.band_limited ? RippleBandGain(l.harmonic * turns_per_s, physics_rate_Hz) : 1.0;
    if (gain == 0) continue;
    tau += gain * l.amplitude_Nm * std::sin(l.harmonic * rotor_angle_rad + l.phase_rad);
  }
  return tau;
}

double RipplePotentialJ(const RippleParams& p, double gear_ratio, double rotor_angle_rad) {
  Line lines[3];
  LinesOf(p, gear_ratio, lines);
  double v = 0;
  for (const Line& l : lines) v += l.amplitude_Nm / l.harmonic * std::cos(l.harmonic * rotor_angle_rad + l.phase_rad);
  return v;
}

RippleLines RippleLineFrequencies(const RippleParams& p, double rotor_speed_rad_s) {
  const double f = std::fabs(rotor_speed_rad_s) / (2.0 * M_PI);
  return {f, 2.0 * f, p.cogging_periods_per_rev * f};
}

}  // namespace armfault
