#include "core/monitors/torque_balance.h"

#include <algorithm>

namespace armfault {

namespace {

// Weak pull to healthy (a, κ, e) = (1, 1, 0), in the units of the normal equations ((N m)²):
// the weight of about one tick of data, so a few hundred milliseconds of motion override it.
constexpr double kPrior = 1.0;
// The offset's pull: 0.2 s of data (100 ticks at 500 Hz, each of weight 1 per N m²).
constexpr double kOffsetPrior = 100.0;
// The weight that pins a held parameter.
constexpr double kHeld = 1e12;

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
  f_.mesh_back_Nm += alpha_ * ((tau * dir < 0 ? std::fabs(tau) * dir : 0.0) - f_.mesh_back_Nm);
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
  if (cal.mesh_backdriven_extra != 0) row.y += cal.mesh_backdriven_extra * f.mesh_back_Nm;
  row.torque = cal.torque_gain * f.perceived_Nm;
  row.friction = cal.viscous_Nm_s * f.viscous_rad_s + cal.coulomb_Nm * f.coulomb + cal.stribeck_Nm * f.stribeck;
  row.usable = f.usable;
  return row;
}

BalanceFit::BalanceFit(BalanceParams params, double time_constant_s, double dt_s, double correlation_ticks,
                       double min_sigma_Nm)
    : params_(params),
      forget_(time_constant_s > 0 ? std::exp(-dt_s / time_constant_s) : 1.0),
      dt_s_(dt_s),
      correlation_ticks_(correlation_ticks),
      min_sigma2_(min_sigma_Nm * min_sigma_Nm) {
  Solve();
}

void BalanceFit::Reset() {
  a_.fill(0);
  b_.fill(0);
  yy_ = n_ = n_pos_ = n_neg_ = 0;
  Solve();
}

void BalanceFit::Add(const BalanceRow& row, double torque_gain, double offset_Nm) {
  if (forget_ < 1.0) {
    for (double& x : a_) x *= forget_;
    for (double& x : b_) x *= forget_;
    yy_ *= forget_;
    n_ *= forget_;
    n_pos_ *= forget_;
    n_neg_ *= forget_;
  }
  if (row.usable) {
    // y = a torque - κ friction + e; a held term moves to the left.
    const double y = row.y - (params_.torque_gain ? 0.0 : torque_gain * row.torque) - (params_.offset ? 0.0 : offset_Nm);
    const double x[3] = {row.torque, -row.friction, 1.0};
    a_[0] += x[0] * x[0];
    a_[1] += x[0] * x[1];
    a_[2] += x[0] * x[2];
    a_[3] += x[1] * x[1];
    a_[4] += x[1] * x[2];
    a_[5] += x[2] * x[2];
    for (int k = 0; k < 3; ++k) b_[k] += x[k] * y;
    yy_ += y * y;
    n_ += 1;
    (row.friction > 0 ? n_pos_ : n_neg_) += 1;
  } else if (forget_ == 1.0) {
    return;
  }
  Solve();
}

void BalanceFit::Solve() {
  est_.moving_s = n_ * dt_s_;
  est_.positive_s = n_pos_ * dt_s_;
  est_.negative_s = n_neg_ * dt_s_;
  // (A + P) θ = b + P θ0. A held parameter has moved into y: it is pinned at 0 by a weight
  // that swamps any data.
  const double p0 = params_.torque_gain ? kPrior : kHeld, p1 = kPrior, p2 = params_.offset ? kOffsetPrior : kHeld;
  const double t00 = params_.torque_gain ? 1.0 : 0.0, t01 = 1.0;
  const double m00 = a_[0] + p0, m01 = a_[1], m02 = a_[2];
  const double m11 = a_[3] + p1, m12 = a_[4], m22 = a_[5] + p2;
  const double r0 = b_[0] + p0 * t00, r1 = b_[1] + p1 * t01, r2 = b_[2];
  const double c00 = m11 * m22 - m12 * m12, c01 = m02 * m12 - m01 * m22, c02 = m01 * m12 - m02 * m11;
  const double c11 = m00 * m22 - m02 * m02, c12 = m01 * m02 - m00 * m12, c22 = m00 * m11 - m01 * m01;
  const double det = m00 * c00 + m01 * c01 + m02 * c02;
  if (!(det > 0) || !std::isfinite(det)) return;
  const double inv = 1.0 / det;
  const double t0 = (c00 * r0 + c01 * r1 + c02 * r2) * inv;
  const double t1 = (c01 * r0 + c11 * r1 + c12 * r2) * inv;
  const double t2 = (c02 * r0 + c12 * r1 + c22 * r2) * inv;
  const double sse = yy_ - 2 * (t0 * b_[0] + t1 * b_[1] + t2 * b_[2]) + t0 * t0 * a_[0] + 2 * t0 * t1 * a_[1] +
                     2 * t0 * t2 * a_[2] + t1 * t1 * a_[3] + 2 * t1 * t2 * a_[4] + t2 * t2 * a_[5];
  const int fitted = 1 + params_.torque_gain + params_.offset;
  const double sigma2 = std::max(min_sigma2_, std::max(0.0, sse) / std::max(1.0, n_ - fitted)) * correlation_ticks_;
  est_.torque_gain = params_.torque_gain ? t0 : 1.0;
  est_.friction_factor = t1;
  est_.offset_Nm = params_.offset ? t2 : 0.0;
  est_.torque_gain_se = params_.torque_gain ? std::sqrt(sigma2 * c00 * inv) : 0.0;
  est_.friction_factor_se = std::sqrt(sigma2 * c11 * inv);
  est_.offset_se = params_.offset ? std::sqrt(sigma2 * c22 * inv) : 0.0;
}

}  // namespace armfault
