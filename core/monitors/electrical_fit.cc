#include "core/monitors/electrical_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/monitors/linear_solve.h"
#include "core/monitors/monitor_config.h"

namespace armfault {

namespace {
// The weight that holds a parameter at its prior (a numerical device, not a tuned value).
constexpr double kHeldPrior = 1e12;
}  // namespace

ElectricalFit::ElectricalFit(const MonitorConfig& c, double time_constant_s, double dt_s, double constant_sd_W)
    : forget(std::exp(-dt_s / time_constant_s)),
      prior_W2(c.electrical_prior_W2),
      magnet_per_resistance(c.max_magnet_kt_loss_per_K / c.copper_resistance_per_K),
      max_resistance_rise(c.copper_resistance_per_K * c.max_winding_rise_K) {
  // q's pull: as many ticks as make its standard error the stated uncertainty.
  const double sd = std::max(1e-3, constant_sd_W);
  constant_prior = c.electrical_tick_sigma_W * c.electrical_tick_sigma_W / (sd * sd);
}

void ElectricalFit::Add(double y, double p_rotor, double p_copper) {
  const double x[3] = {p_rotor, p_copper, 1.0};
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j, ++k) a[k] = forget * a[k] + x[i] * x[j];
    b[i] = forget * b[i] + x[i] * y;
  }
  yy = forget * yy + y * y;
  weight = forget * weight + 1.0;
  if (!Fit(prior_W2)) return;
  if (n > 1.0) {
    // K_T rises only as far as a magnet as cold as the winding reads can strengthen it:
    // n <= 1 + s (1 - rho) for rho < 1, n <= 1 otherwise. Beyond that, supply power above the
    // model is an extra loss. Rotor and copper power are nearly collinear in many motions, so
    // holding n at 1 on a cold unit pushes the cold magnet's extra rotor power into rho, and the
    // winding then reads warmer than it is (docs/monitor.md, "Estimators"). The bound is not
    // convex: the best fit on each of its two pieces, the one with the smaller residual.
    const double se = n_se;
    Fit(kHeldPrior);
    const double held_sse = sse;
    const double held_rho = rho, held_rho_se = rho_se, held_q = constant_W;
    if (!(FitOnColdMagnetBound() && rho < 1.0 && sse < held_sse)) {
      n = 1.0;
      rho = held_rho;
      rho_se = held_rho_se;
      constant_W = held_q;
      sse = held_sse;
    }
    n_se = se;
  }
}

double ElectricalFit::Sse(double tn, double tr, double tq) const {
  return yy - 2 * (tn * b[0] + tr * b[1] + tq * b[2]) + tn * tn * a[0] + 2 * tn * tr * a[1] + 2 * tn * tq * a[2] +
         tr * tr * a[3] + 2 * tr * tq * a[4] + tq * tq * a[5];
}

bool ElectricalFit::FitOnColdMagnetBound() {
  // With y - (1 + s) P_r = rho (P_copper - s P_r) + q: u = (P_copper + c1 P_r, 1), y' = y - c0 P_r.
  const double s = magnet_per_resistance, c0 = 1.0 + s, c1 = -s;
  const double uu00 = a[3] + 2 * c1 * a[1] + c1 * c1 * a[0] + prior_W2 + prior_W2 * c1 * c1;
  const double uu01 = a[4] + c1 * a[2];
  const double uu11 = a[5] + constant_prior;
  const double uy0 = (b[1] - c0 * a[1]) + c1 * (b[0] - c0 * a[0]) + prior_W2 + prior_W2 * c1 * (1.0 - c0);
  const double uy1 = b[2] - c0 * a[2];
  double tr, tq, inv_rr, inv_qq;
  if (!Solve2(uu00, uu01, uu11, uy0, uy1, &tr, &tq, &inv_rr, &inv_qq)) return false;
  const double tn = c0 + c1 * tr;
  const double e = Sse(tn, tr, tq);
  const double sigma2 = std::max(0.0, e) / std::max(1.0, weight - 2.0);
  n = tn;
  rho = tr;
  constant_W = tq;
  rho_se = std::sqrt(sigma2 * std::max(0.0, inv_rr));
  sse = e;
  return true;
}

double ElectricalFit::WarmMagnetRejection(double rho_cap) const {
  ElectricalFit line = *this;
  if (!line.FitOnColdMagnetBound() || !(line.rho <= 1.0 + max_resistance_rise)) {
    return std::numeric_limits<double>::infinity();
  }
  if (line.rho > rho_cap) {  // the residual is quadratic along the line: its bound is the best
    const double tr = rho_cap, tn = 1.0 - magnet_per_resistance * (tr - 1.0);
    const double tq = (b[2] - tn * a[2] - tr * a[4]) / (a[5] + constant_prior);
    line.sse = Sse(tn, tr, tq);
  }
  const double sigma2 = std::max(0.0, sse) / std::max(1.0, weight - 3.0);
  if (!(sigma2 > 0)) return std::numeric_limits<double>::infinity();
  return std::max(0.0, line.sse - sse) / sigma2;
}

bool ElectricalFit::Fit(double n_prior) {
  std::array<double, 6> m = a;
  m[0] += n_prior;
  m[3] += prior_W2;
  m[5] += constant_prior;
  const std::array<double, 3> r = {b[0] + n_prior, b[1] + prior_W2, b[2]};
  std::array<double, 3> t, inv;
  if (!Solve3(m, r, &t, &inv)) return false;
  sse = Sse(t[0], t[1], t[2]);
  const double sigma2 = std::max(0.0, sse) / std::max(1.0, weight - 3.0);
  n = t[0];
  rho = t[1];
  constant_W = t[2];
  n_se = std::sqrt(sigma2 * inv[0]);
  rho_se = std::sqrt(sigma2 * inv[1]);
  return true;
}

void WindingThermometer::Update(const MonitorConfig& c, double fit_rho, double dt_s) {
  // While the fit converges (its first time constant of judged data) the reading is the fit's;
  // then it follows slowly, so that the jump an abrupt K_T loss puts into the fit for a few
  // seconds does not widen the K_T allowance.
  if (judged_s < c.winding_thermometer_time_constant_s) {
    rho = fit_rho;
  } else {
    rho += (fit_rho - rho) * dt_s / c.winding_thermometer_time_constant_s;
  }
  judged_s += dt_s;
  reading += (fit_rho - reading) * dt_s / std::min(c.winding_reading_time_constant_s, judged_s);
}

ElectricalEstimator::ElectricalEstimator(const MonitorConfig& c, double dt_s, double constant_sd_W)
    : fit(c, c.electrical_time_constant_s, dt_s, constant_sd_W), fast(c, c.balance_time_constant_s, dt_s, constant_sd_W) {}

void ElectricalEstimator::Add(const MonitorConfig& c, double y, double p_rotor, double p_copper, double dt_s) {
  fit.Add(y, p_rotor, p_copper);
  fast.Add(y, p_rotor, p_copper);
  excitation_rotor_J = fit.forget * excitation_rotor_J + std::fabs(p_rotor) * dt_s;
  excitation_copper_J = fit.forget * excitation_copper_J + p_copper * dt_s;
  if (excitation_copper_J >= c.min_copper_energy_J) winding.Update(c, fit.rho, dt_s);
}

}  // namespace armfault
