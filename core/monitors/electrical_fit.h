// The electrical balance of one joint module as its monitor fits it (docs/monitor.md,
// "Electrical balance, every tick"), and the winding read from it as a thermometer.
//
// Inputs per tick: y = U_d I_d - fixed losses [W], the calibration's rotor power P_r and copper
// loss P_copper [W]. Fitted, weighted least squares with forgetting:
//   y = n P_r + rho P_copper + q
// n the K_T factor, rho the winding-resistance factor, q a constant power the calibration does
// not hold [W], pulled to 0 with the weight of its stated uncertainty. Weak priors n = rho = 1
// (weight prior_W2) keep the fit defined at rest. n may exceed 1 only as far as a magnet as
// cold as the winding reads strengthens: n <= 1 + s (1 - rho), s = magnet flux loss per
// copper resistance rise (material data).
// Outputs: n, rho, q with standard errors; the residual sum of squares.
#pragma once

#include <array>

namespace armfault {

struct MonitorConfig;

struct ElectricalFit {
  double forget = 1;
  double prior_W2 = 0;                // weight of the pulls n -> 1, rho -> 1
  double magnet_per_resistance = 0;   // s: K_T loss per resistance rise of a magnet as warm as its winding
  double max_resistance_rise = 0;     // beyond this rise of rho: no temperature
  double constant_prior = 0;          // weight of the pull of q to 0, in ticks
  std::array<double, 6> a{};  // of (P_r, P_copper, 1): 00 01 02 11 12 22
  std::array<double, 3> b{};
  double yy = 0, weight = 0;
  double n = 1, n_se = 0, rho = 1, rho_se = 0, constant_W = 0;
  double sse = 0;  // the fit's residual sum of squares

  // `time_constant_s` of forgetting at tick `dt_s`; `constant_sd_W`: 1 sigma of q.
  ElectricalFit() = default;
  ElectricalFit(const MonitorConfig& c, double time_constant_s, double dt_s, double constant_sd_W);
  void Add(double y, double p_rotor, double p_copper);
  // Residual sum of squares of parameters (tn, tr, tq) on the accumulated data.
  double Sse(double tn, double tr, double tq) const;
  // How strongly the data reject a magnet as warm as a winding with resistance factor at most
  // `rho_cap`: the residual sum of squares of the fit on the line n = 1 - s (rho - 1),
  // rho <= rho_cap, over the free fit's, in units of the free fit's residual variance. Infinite
  // where the line needs a winding beyond max_resistance_rise.
  double WarmMagnetRejection(double rho_cap) const;

 private:
  // The fit on the line n = 1 + s (1 - rho): a two-parameter fit (the weak n prior kept).
  bool FitOnColdMagnetBound();
  // Solves with prior weight `n_prior` on n = 1.
  bool Fit(double n_prior);
};

// The winding's resistance factor read as a temperature, from the joint fit's rho while the
// copper loss is enough to judge it (min_copper_energy_J).
struct WindingThermometer {
  double rho = 1;        // slow: the fit's own for winding_thermometer_time_constant_s, then following it
  double judged_s = 0;   // time since the copper loss was first enough to judge it [s]
  double reading = 1;    // averaged with winding_reading_time_constant_s (a plain mean until then)
  void Update(const MonitorConfig& c, double fit_rho, double dt_s);
};

// One joint's electrical estimator: the K_T and resistance detectors' fit, a fast one whose n is
// the torque balance's gain, the excitation each has seen, and the winding thermometer.
struct ElectricalEstimator {
  ElectricalEstimator(const MonitorConfig& c, double dt_s, double constant_sd_W);
  // Adds one tick; updates the thermometer while rho can be judged.
  void Add(const MonitorConfig& c, double y, double p_rotor, double p_copper, double dt_s);
  ElectricalFit fit, fast;
  double excitation_rotor_J = 0, excitation_copper_J = 0;
  double kt_judged_s = 0;  // time the rotor power has been enough to judge K_T [s]
  WindingThermometer winding;
};

}  // namespace armfault
