// Commissioning: what the power-efficiency monitor learns about one robot unit from signals the
// unit gave while healthy, the way a drive is commissioned on the real machine. The monitor
// never sees the simulator's truth: only the JointSignals streamed to it tick by tick.
//
// Per joint, two least-squares fits, each pulled to the datasheet value of every coefficient
// with the weight of that value's plausible spread (ridge), so that a coefficient the motion
// does not excite stays at the datasheet:
//  - electrical balance (eq 4-4 ... 4-8), every tick:
//      U_d I_d = quiescent + rotor_gain P_r + (copper + conduction) i² + switching |i|
//    The fitted i² coefficient less the datasheet's switch conduction is the copper term the
//    resistance detector scales.
//  - torque balance (core/monitors/torque_balance.h), usable ticks, with the torque gain a = the
//    electrical fit's K_T ratio:
//      F[τ_s] + coupling − a F[γ K_T i] = − I_r F[q̈] − μ F[|τ_s| sgn q̇]
//                                         − γb F[q̇] − γF_c F[sgn q̇] − γF_s F[exp(−F_t q̇²) sgn q̇] + d
//    (F_t stays the datasheet's: the fit is linear in the rest).
// The healthy scatter of the torque balance's residual becomes the unit's residual floor.
//
// Streamed: the signals come tick by tick and are not kept. The electrical fit keeps its normal
// equations, the temperature its sum, the torque balance its filters and its XᵀX. The balance's
// target y = u − a p (u = F[τ_s] + coupling, p = F[γ K_T i]) needs the gain a, which the
// electrical fit gives only at the end; y is linear in a, so Xᵀu, Xᵀp, uᵀu, uᵀp and pᵀp are
// summed and combined at the end: nothing grows with the commissioning's length. (Forming y per
// tick in a second pass gave the same fit to ~1e-11 relative.)
#include "core/monitors/commissioning.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>

namespace armfault {

namespace {

// Plausible spread of the rotor inertia about its datasheet value (a machined part).
constexpr double kRotorInertiaSpread = 0.05;
// Usable ticks (moving one way) a joint needs before its torque balance is fitted.
constexpr long kMinBalanceTicks = 500;

// Ridge least squares from its normal equations: minimises |X θ − y|² / σ² + Σ ((θ − θ0) / sd)²
// given a = XᵀX, b = Xᵀy, yy = yᵀy over `rows` rows. Returns θ; `rms` gets the data residual's
// root mean square.
template <int N>
Eigen::Matrix<double, N, 1> SolveRidge(const Eigen::Matrix<double, N, N>& a, const Eigen::Matrix<double, N, 1>& b,
                                       double yy, long rows, double sigma, const Eigen::Matrix<double, N, 1>& theta0,
                                       const Eigen::Matrix<double, N, 1>& sd, double* rms) {
  Eigen::Matrix<double, N, N> m = a / (sigma * sigma);
  Eigen::Matrix<double, N, 1> r = b / (sigma * sigma);
  for (int k = 0; k < N; ++k) {
    m(k, k) += 1.0 / (sd(k) * sd(k));
    r(k) += theta0(k) / (sd(k) * sd(k));
  }
  const Eigen::Matrix<double, N, 1> theta = m.ldlt().solve(r);
  const double sse = yy - 2 * theta.dot(b) + theta.dot(a * theta);
  *rms = rows > 0 ? std::sqrt(std::max(0.0, sse) / rows) : 0.0;
  return theta;
}

}  // namespace

struct PowerMonitorCommissioning::Joint {
  // Electrical balance: rows (1, P_r, i², |i|), target U_d I_d.
  Eigen::Matrix4d e_a = Eigen::Matrix4d::Zero();
  Eigen::Vector4d e_b = Eigen::Vector4d::Zero();
  double e_yy = 0;
  long e_rows = 0;
  // Winding temperature seen (finite readings).
  double temp_sum_C = 0;
  long temp_count = 0;
  // Torque balance: XᵀX of the rows x and, since y = u − a p is linear in the gain a that only
  // the electrical fit gives at the end, Xᵀu, Xᵀp, uᵀu, uᵀp and pᵀp (see the top of this file):
  // a fixed size whatever the commissioning's length.
  Eigen::Matrix<double, 7, 7> m_a = Eigen::Matrix<double, 7, 7>::Zero();
  Eigen::Matrix<double, 7, 1> m_u = Eigen::Matrix<double, 7, 1>::Zero(), m_p = Eigen::Matrix<double, 7, 1>::Zero();
  double uu = 0, up = 0, pp = 0;
  long m_rows = 0;
};

PowerMonitorCommissioning::PowerMonitorCommissioning(const PowerMonitorModel& nominal, double control_dt_s)
    : nominal_(nominal), dt_s_(control_dt_s > 0 ? control_dt_s : nominal.control_dt_s), joints_(nominal.joints.size()) {
  const MonitorConfig& c = nominal.config;
  for (const JointKnowledge& k : nominal.joints) {
    filters_.emplace_back(c.balance_filter_s, dt_s_, c.rest_velocity_rad_s, k.mechanical.stribeck_s2);
  }
}

PowerMonitorCommissioning::~PowerMonitorCommissioning() = default;

void PowerMonitorCommissioning::Tick(const std::vector<JointSignals>& joints) {
  const size_t n = nominal_.joints.size();
  if (!valid_) return;
  if (joints.size() != n) {  // not this robot's signals: the unit keeps the datasheet
    valid_ = false;
    return;
  }
  now_ = joints;
  // Joints without a torque sensor read the model's torque, as in the monitor's runs (it needs
  // only the previous tick's velocity estimates).
  if (nominal_.virtual_sensor.any()) {
    if (ticks_ == 0) {
      nominal_.virtual_sensor.Fill(now_, 0.0, &now_);
    } else {
      nominal_.virtual_sensor.Fill(prev_, dt_s_, &now_);
    }
  }
  for (size_t j = 0; j < n; ++j) {
    const double temp = now_[j].winding_temp_C;
    if (std::isfinite(temp)) joints_[j].temp_sum_C += temp, ++joints_[j].temp_count;
  }
  if (ticks_ > 0) {
    // Per-tick quantities as the monitor forms them (PowerEfficiencyMonitor::Observe).
    for (size_t j = 0; j < n; ++j) {
      const JointSignals& now = now_[j];
      const JointSignals& prev = prev_[j];
      const JointKnowledge& k = nominal_.joints[j];
      Joint& acc = joints_[j];
      const double i = prev.i_cmd_A;  // held over the period
      const double dq = now.q_meas_rad - prev.q_meas_rad;
      const double tau_mean = 0.5 * (now.tau_sensor_Nm + prev.tau_sensor_Nm);
      const double perceived = k.ratio * k.kt_Nm_per_A * i;
      // Electrical balance.
      const Eigen::Vector4d x(1.0, perceived * dq / dt_s_, i * i, std::fabs(i));
      const double y = now.v_bus_meas_V * now.i_supply_meas_A;
      acc.e_a.noalias() += x * x.transpose();
      acc.e_b.noalias() += x * y;
      acc.e_yy += y * y;
      ++acc.e_rows;
      // Torque balance: the lower joints' filters have already taken this tick.
      const FilteredTerms& f = filters_[j].Push(perceived, dq / dt_s_, tau_mean);
      double coupling = 0;
      for (size_t l = 0; l < j; ++l) {
        if (k.coupling[l] != 0) coupling += k.coupling[l] * k.mechanical.rotor_coupling_kg_m2 * filters_[l].terms().accel_rad_s2;
      }
      if (!f.usable) continue;
      Eigen::Matrix<double, 7, 1> row;
      row << -f.accel_rad_s2, -f.mesh_Nm, -f.viscous_rad_s, -f.coulomb, -f.stribeck, 1.0, -f.mesh_back_Nm;
      const double u = f.sensor_Nm + coupling, p = f.perceived_Nm;
      acc.m_a.noalias() += row * row.transpose();
      acc.m_u.noalias() += row * u;
      acc.m_p.noalias() += row * p;
      acc.uu += u * u, acc.up += u * p, acc.pp += p * p;
      ++acc.m_rows;
    }
  }
  prev_.swap(now_);
  ++ticks_;
}

long PowerMonitorCommissioning::balance_rows() const {
  long rows = 0;
  for (const Joint& acc : joints_) rows += acc.m_rows;
  return rows;
}

PowerMonitorModel PowerMonitorCommissioning::End() const {
  PowerMonitorModel model = nominal_;
  const int n = static_cast<int>(nominal_.joints.size());
  if (!valid_ || ticks_ < 3) return model;

  // 1. Electrical balance.
  for (int j = 0; j < n; ++j) {
    const Joint& acc = joints_[j];
    const ElectricalCalibration& e0 = nominal_.joints[j].electrical;
    const Eigen::Vector4d theta0(e0.quiescent_W, e0.rotor_gain, e0.copper_W_per_A2 + e0.conduction_W_per_A2,
                                 e0.switching_W_per_A);
    const Eigen::Vector4d sd(std::max(0.5, 0.5 * e0.quiescent_W), 0.2, 0.5 * theta0(2),
                             std::max(0.1, 0.5 * e0.switching_W_per_A));
    double rms = 0;
    // Supply-sensor noise and period averaging make ~0.5 W per tick.
    const Eigen::Vector4d te = SolveRidge<4>(acc.e_a, acc.e_b, acc.e_yy, acc.e_rows, 0.5, theta0, sd, &rms);
    if (!te.allFinite() || te(1) < 0.5 || te(1) > 1.5) continue;
    ElectricalCalibration& e = model.joints[j].electrical;
    e.quiescent_W = te(0);
    e.rotor_gain = te(1);
    e.copper_W_per_A2 = std::max(0.25 * e0.copper_W_per_A2, te(2) - e0.conduction_W_per_A2);
    e.switching_W_per_A = std::max(0.0, te(3));
    // One K_T makes both the back-EMF and the torque: the torque balance takes the electrical
    // K_T ratio as its gain (off only by the sensors' gains). Fitted from the balance alone, a
    // pure inertia load could not tell torque gain from rotor inertia, nor a steady gravity
    // load gain from offset.
    model.joints[j].mechanical.torque_gain = te(1);
  }
  // With a winding-temperature sensor, the calibration holds at the mean temperature seen.
  for (int j = 0; j < n; ++j) {
    if (joints_[j].temp_count > 0) model.joints[j].electrical.reference_temp_C = joints_[j].temp_sum_C / joints_[j].temp_count;
  }

  // 2. Torque balance with that gain: rotor inertia, mesh loss, friction curve, offset.
  for (int j = 0; j < n; ++j) {
    const Joint& acc = joints_[j];
    const long rows = acc.m_rows;
    if (rows < kMinBalanceTicks) continue;  // the joint hardly moved: keep the datasheet
    JointKnowledge& k = model.joints[j];
    const double a = k.mechanical.torque_gain;
    const Eigen::Matrix<double, 7, 1> b = acc.m_u - a * acc.m_p;
    const double yy = acc.uu - 2 * a * acc.up + a * a * acc.pp;
    const MechanicalCalibration& m0 = nominal_.joints[j].mechanical;
    Eigen::Matrix<double, 7, 1> theta0, sd;
    theta0 << m0.rotor_inertia_kg_m2, m0.mesh_loss_fraction, m0.viscous_Nm_s, m0.coulomb_Nm, m0.stribeck_Nm,
        m0.sensor_offset_Nm, 0.0;
    sd << kRotorInertiaSpread * m0.rotor_inertia_kg_m2, std::max(0.1, 0.5 * m0.mesh_loss_fraction),
        0.5 * m0.viscous_Nm_s + 1e-3, 0.5 * m0.coulomb_Nm + 0.01, 0.5 * m0.stribeck_Nm + 0.01, 1.0, 0.1;
    double rms = 0;
    // The filtered balance scatters ~0.1 N m per tick on a healthy unit.
    const Eigen::Matrix<double, 7, 1> tm = SolveRidge<7>(acc.m_a, b, yy, rows, 0.1, theta0, sd, &rms);
    if (!tm.allFinite() || tm(0) <= 0) continue;
    MechanicalCalibration& mc = k.mechanical;
    mc.rotor_inertia_kg_m2 = tm(0);
    mc.mesh_loss_fraction = std::max(0.0, tm(1));
    mc.viscous_Nm_s = std::max(0.0, tm(2));
    mc.coulomb_Nm = std::max(0.0, tm(3));
    mc.stribeck_Nm = std::max(0.0, tm(4));
    mc.sensor_offset_Nm = tm(5);
    mc.mesh_backdriven_extra = std::max(-mc.mesh_loss_fraction, tm(6));
    k.balance_sigma_Nm = std::max(nominal_.joints[j].balance_sigma_Nm, rms);
    k.commissioned = true;
  }
  return model;
}

}  // namespace armfault
