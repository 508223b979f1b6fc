// The tick-rate torque balance of one joint module, as its monitor sees it: the rotor between
// the motor and the torque sensor (thesis eq 3-7, with the sensor's torque as the load):
//
//   a γ K_T i  =  I_r q̈  +  κ f_c(q̇)  +  μ |τ_s| sgn q̇  +  (τ_s − d)  +  I_m γ Σ_l c_l q̈_l     [N m, link side]
//
// i the commanded current (held over the control period), q̇ the encoder velocity over the
// period, τ_s the torque-sensor reading, I_r = I_m γ² the reflected rotor inertia, f_c the
// unit's friction curve (eq 3-8, link side), μ the harmonic drive's mesh-loss fraction, c_l
// the cosine between this axis and lower joint l's, d the sensor's offset. Healthy, a = κ = 1;
// a K_T loss lowers a, wear raises κ, a drifting sensor moves d.
//
// So that q̈ is never differentiated from a noisy velocity, every term passes through the same
// first-order low-pass F (time constant T_f): F[q̈] = dF[q̇]/dt exactly for the discrete filter.
// Ticks are used only while the joint has moved in one direction for 3 T_f (friction at rest
// is whatever stiction needs, not the curve).
//
// Inputs per tick: JointSignals of this joint (and the lower joints' filtered accelerations).
// Outputs: a BalanceRow, the filtered regressors of one tick, linear in (a, κ, d).
#pragma once

#include <array>
#include <cmath>

namespace armfault {

// What the monitor believes about one unit's rotor, friction and sensor (link side, N m).
// From the datasheet, or fitted on the unit by commissioning (core/monitors/commissioning.cc).
struct MechanicalCalibration {
  double torque_gain = 1.0;         // link torque per perceived rotor torque γ K_T i
  double rotor_inertia_kg_m2 = 0;   // I_r = I_m γ²
  double rotor_coupling_kg_m2 = 0;  // I_m γ: coupling to a parallel lower joint's acceleration
  double viscous_Nm_s = 0;          // γ b
  double coulomb_Nm = 0;            // γ F_c
  double stribeck_Nm = 0;           // γ F_s
  double stribeck_s2 = 15;          // F_t [s²/rad²]
  double mesh_loss_fraction = 0;    // μ
  // μ_b − μ: the extra load friction while the link drives the motor (τ_s q̇ < 0); a
  // strain-wave gear's load friction depends on the direction of power flow.
  double mesh_backdriven_extra = 0;
  double sensor_offset_Nm = 0;      // d
  // The friction curve f_c(q̇), signed with q̇.
  double FrictionNm(double qd) const {
    const double s = qd > 0 ? 1.0 : (qd < 0 ? -1.0 : 0.0);
    return viscous_Nm_s * qd + (coulomb_Nm + stribeck_Nm * std::exp(-stribeck_s2 * qd * qd)) * s;
  }
};

// One tick's filtered terms, each F[...] of its per-tick value.
struct FilteredTerms {
  double sensor_Nm = 0;      // F[τ_s]
  double accel_rad_s2 = 0;   // F[q̈] = dF[q̇]/dt
  double mesh_Nm = 0;        // F[|τ_s| sgn q̇]
  double mesh_back_Nm = 0;   // F[|τ_s| sgn q̇] of the ticks with τ_s q̇ < 0 (back-driven)
  double perceived_Nm = 0;   // F[γ K_T i], datasheet K_T
  double viscous_rad_s = 0;  // F[q̇]
  double coulomb = 0;        // F[sgn q̇]
  double stribeck = 0;       // F[exp(-F_t q̇²) sgn q̇]
  bool usable = false;       // moving in one direction long enough for the filter to hold no rest
};

// The balance's terms under a calibration. With y = sensor + inertia + mesh + coupling − d_cal,
//   y = a·torque − κ·friction + (d − d_cal).
struct BalanceRow {
  double y = 0;
  double torque = 0;    // F[torque_gain γ K_T i]
  double friction = 0;  // F[f_c(q̇)]
  bool usable = false;
};
BalanceRow RowOf(const MechanicalCalibration& cal, const FilteredTerms& f, double coupling_Nm);

class BalanceFilter {
 public:
  // `filter_s`: T_f; `dt_s`: control period; `min_speed_rad_s`: slower counts as at rest;
  // `stribeck_s2`: F_t of the friction curve's Stribeck term.
  BalanceFilter(double filter_s, double dt_s, double min_speed_rad_s, double stribeck_s2);
  // One control period: perceived rotor torque γ K_T i [N m] of the command held over it,
  // velocity dq/dt [rad/s] over it, mean torque reading [N m].
  const FilteredTerms& Push(double perceived_torque_Nm, double qd_rad_s, double tau_Nm);
  const FilteredTerms& terms() const { return f_; }

 private:
  double alpha_;     // per-tick filter gain dt / (T_f + dt)
  double dt_s_;
  double settle_s_;  // 3 T_f
  double min_speed_;
  double stribeck_s2_;
  double v_ = 0;
  int direction_ = 0;
  double moving_s_ = 0;
  FilteredTerms f_;
};

// Which of the balance's (a, κ, e) a fit estimates; the others it holds at the values given
// with each row.
struct BalanceParams {
  bool torque_gain = false;
  bool offset = false;  // κ is always estimated
};

// Least squares of (a, κ, e) (κ always; a and e where asked) over BalanceRows with exponential
// forgetting. Pulled weakly to the healthy (1, 1, 0) so the fit is defined without
// excitation; the offset's pull is stronger, so that where one direction of motion cannot tell
// friction from an offset, the residual is put on friction. Standard errors from the
// residuals, inflated for the filter's correlation between ticks.
class BalanceFit {
 public:
  // `time_constant_s` <= 0: no forgetting (a growing window). `min_sigma_Nm`: floor of the
  // residual scale (the sensor's own noise), so a fit on a few ticks is not overconfident.
  BalanceFit(BalanceParams params, double time_constant_s, double dt_s, double correlation_ticks, double min_sigma_Nm);
  // `torque_gain`, `offset_Nm`: a and e where they are held, not estimated.
  void Add(const BalanceRow& row, double torque_gain, double offset_Nm);
  void Reset();
  struct Estimate {
    double torque_gain = 1, friction_factor = 1, offset_Nm = 0;
    double torque_gain_se = 0, friction_factor_se = 0, offset_se = 0;
    double moving_s = 0;                    // weighted time of usable ticks in the fit
    double positive_s = 0, negative_s = 0;  // of which moving forward, backward
  };
  const Estimate& estimate() const { return est_; }

 private:
  void Solve();
  BalanceParams params_;
  double forget_;
  double dt_s_;
  double correlation_ticks_;
  double min_sigma2_;
  std::array<double, 6> a_{};  // information matrix of (a, κ, e), upper triangle: 00 01 02 11 12 22
  std::array<double, 3> b_{};
  double yy_ = 0, n_ = 0, n_pos_ = 0, n_neg_ = 0;
  Estimate est_;
};

}  // namespace armfault
