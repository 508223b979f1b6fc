#include "core/torque_balance.h"

#include <algorithm>

namespace armfault {

namespace {

// Weak pull to healthy (a, κ, e) = (1, 1, 0), in the units of the normal equations ((N m)²):
// the weight of about one tick of data, so a few hundred milliseconds of motion override it.
constexpr double kPrior = 1.0;
// The offset's pull: 0.2 s of data (100 ticks at 500 Hz, each of weight 1 per N m²).
constexpr double kOffsetPrior = 100.0;

}  // namespace

BalanceFilter::BalanceFilter(double filter_s, double dt_s, double min_speed_rad_s, double stribeck_s2)
    : alpha_(dt_s / (filter_s + dt_s)),
      dt_s_(dt_s),
      settle_s_(3 * filter_s),
      min_speed_(min_speed_rad_s),
      stribeck_s2_(stribeck_s2) {}

const FilteredTerms& BalanceFilter::Push(double perceived_torque_Nm, double qd, double tau) {
  const int dir = std::fabs(qd) < min_speed_ ? 0 : (qd > 0 ? 1 : -1);
  moving_s_ = dir == 0 ? 0.0 : (dir == direction_ ? moving_s_ + dt_s_ : dt_s_);
  direction_ = dir;
  const double v_new = v_ + alpha_ * (qd - v_);
  f_.accel_rad_s2 = (v_new - v_) / dt_s_;
  v_ = v_new;
  const double s = qd > 0 ? 1.0 : (qd < 0 ? -1.0 : 0.0);
  f_.sensor_Nm += alpha_ * (tau - f_.sensor_Nm);
  f_.mesh_Nm += alpha_ * (std::fabs(tau) * dir - f_.mesh_Nm);
  f_.perceived_Nm += alpha_ * (perceived_torque_Nm - f_.perceived_Nm);
  f_.viscous_rad_s = v_;
  f_.coulomb += alpha_ * (s - f_.coulomb);
  f_.stribeck += alpha_ * (std::exp(-stribeck_s2_ * qd * qd) * s - f_.stribeck);
  f_.usable = moving_s_ >= settle_s_;
  return f_;
}

BalanceRow RowOf(const MechanicalCalibration& cal, const FilteredTerms& f, double coupling_Nm) {
  BalanceRow row;
  row.y = f.sensor_Nm + cal.rotor_inertia_kg_m2 * f.accel_rad_s2 + cal.mesh_loss_fraction * f.mesh_Nm + coupling_Nm -
          cal.sensor_offset_Nm;
  row.torque = cal.torque_gain * f.perceived_Nm;
  row.friction = cal.viscous_Nm_s * f.viscous_rad_s + cal.coulomb_Nm * f.coulomb + cal.stribeck_Nm * f.stribeck;
  row.usable = f.usable;
  return row;
}

BalanceFit::BalanceFit(bool fit_offset, double time_constant_s, double dt_s, double correlation_ticks,
                       double min_sigma_Nm)
    : fit_offset_(fit_offset),
      forget_(time_constant_s > 0 ? std::exp(-dt_s / time_constant_s) : 1.0),
      dt_s_(dt_s),
      correlation_ticks_(correlation_ticks),
      min_sigma2_(min_sigma_Nm * min_sigma_Nm) {
  Solve();
}

void BalanceFit::Reset() {
  a00_ = a01_ = a11_ = b0_ = b1_ = yy_ = n_ = n_pos_ = n_neg_ = 0;
  Solve();
}

void BalanceFit::Add(const BalanceRow& row, double torque_gain, double offset_Nm) {
  if (forget_ < 1.0) {
    a00_ *= forget_;
    a01_ *= forget_;
    a11_ *= forget_;
    b0_ *= forget_;
    b1_ *= forget_;
    yy_ *= forget_;
    n_ *= forget_;
    n_pos_ *= forget_;
    n_neg_ *= forget_;
  }
  if (row.usable) {
    // y - a torque (- e) = -κ friction (+ e)
    const double y = row.y - torque_gain * row.torque - (fit_offset_ ? 0.0 : offset_Nm);
    const double x0 = -row.friction;
    a00_ += x0 * x0;
    a01_ += x0;
    a11_ += 1.0;
    b0_ += x0 * y;
    b1_ += y;
    yy_ += y * y;
    n_ += 1;
    (row.friction > 0 ? n_pos_ : n_neg_) += 1;
  } else if (forget_ == 1.0) {
    return;
  }
  Solve();
}

void BalanceFit::Solve() {
  const double p0 = kPrior, p1 = fit_offset_ ? kOffsetPrior : 0.0;
  est_.moving_s = n_ * dt_s_;
  est_.positive_s = n_pos_ * dt_s_;
  est_.negative_s = n_neg_ * dt_s_;
  if (!fit_offset_) {
    const double m = a00_ + p0;
    const double k = (b0_ + p0) / m;
    const double sse = yy_ - 2 * k * b0_ + k * k * a00_;
    const double sigma2 = std::max(min_sigma2_, std::max(0.0, sse) / std::max(1.0, n_ - 1.0)) * correlation_ticks_;
    est_.friction_factor = k;
    est_.friction_factor_se = std::sqrt(sigma2 / m);
    est_.offset_Nm = 0;
    est_.offset_se = 0;
    return;
  }
  const double m00 = a00_ + p0, m01 = a01_, m11 = a11_ + p1;
  const double det = m00 * m11 - m01 * m01;
  if (!(det > 1e-300)) return;
  const double k = (m11 * (b0_ + p0) - m01 * b1_) / det;
  const double e = (m00 * b1_ - m01 * (b0_ + p0)) / det;
  const double sse = yy_ - 2 * (k * b0_ + e * b1_) + k * k * a00_ + 2 * k * e * a01_ + e * e * a11_;
  const double sigma2 = std::max(min_sigma2_, std::max(0.0, sse) / std::max(1.0, n_ - 2.0)) * correlation_ticks_;
  est_.friction_factor = k;
  est_.offset_Nm = e;
  est_.friction_factor_se = std::sqrt(sigma2 * m11 / det);
  est_.offset_se = std::sqrt(sigma2 * m00 / det);
}

}  // namespace armfault
