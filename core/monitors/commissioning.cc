// Commissioning: what the power-efficiency monitor learns about one robot unit from signals the
// unit gave while healthy, the way a drive is commissioned on the real machine. The monitor
// never sees the simulator's truth: only the recorded JointSignals.
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
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "core/monitors/power_monitor.h"

namespace armfault {

namespace {

// Ridge least squares: minimises |X θ − y|² / σ² + Σ ((θ − θ0) / sd)².
template <int N>
struct Ridge {
  Eigen::Matrix<double, N, N> a = Eigen::Matrix<double, N, N>::Zero();
  Eigen::Matrix<double, N, 1> b = Eigen::Matrix<double, N, 1>::Zero();
  double yy = 0;
  long rows = 0;
  void Add(const Eigen::Matrix<double, N, 1>& x, double y) {
    a.noalias() += x * x.transpose();
    b.noalias() += x * y;
    yy += y * y;
    ++rows;
  }
  // Returns θ; `rms` gets the data residual's root mean square.
  Eigen::Matrix<double, N, 1> Solve(double sigma, const Eigen::Matrix<double, N, 1>& theta0,
                                    const Eigen::Matrix<double, N, 1>& sd, double* rms) const {
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
};

// Plausible spread of the rotor inertia about its datasheet value (a machined part).
constexpr double kRotorInertiaSpread = 0.05;
// Usable ticks (moving one way) a joint needs before its torque balance is fitted.
constexpr long kMinBalanceTicks = 500;

bool AllFinite(const Eigen::VectorXd& v) { return v.allFinite(); }

}  // namespace

PowerMonitorModel CommissionMonitorModel(const PowerMonitorModel& nominal, const CommissioningData& recorded) {
  // Joints without a torque sensor read the model's torque, as in the monitor's runs.
  CommissioningData filled;
  if (nominal.virtual_sensor.any() && recorded.ok) {
    filled = recorded;
    const double period = recorded.control_dt_s > 0 ? recorded.control_dt_s : nominal.control_dt_s;
    for (size_t t = 0; t < filled.signals.size(); ++t) {
      nominal.virtual_sensor.Fill(filled.signals[t > 0 ? t - 1 : 0], t > 0 ? period : 0.0, &filled.signals[t]);
    }
  }
  const CommissioningData& data = nominal.virtual_sensor.any() && recorded.ok ? filled : recorded;
  PowerMonitorModel model = nominal;
  const int n = static_cast<int>(nominal.joints.size());
  if (!data.ok || data.signals.size() < 3 || data.signals[0].size() != static_cast<size_t>(n)) return model;
  const MonitorConfig& c = nominal.config;
  const double dt = data.control_dt_s > 0 ? data.control_dt_s : nominal.control_dt_s;
  const size_t ticks = data.signals.size();

  // Per-tick quantities as the monitor forms them (PowerEfficiencyMonitor::Observe).
  struct Tick {
    double i, dq, tau_mean, perceived;
  };
  auto tick_of = [&](size_t t, int j) {
    const JointSignals& now = data.signals[t][j];
    const JointSignals& prev = data.signals[t - 1][j];
    const JointKnowledge& k = nominal.joints[j];
    Tick x;
    x.i = prev.i_cmd_A;  // held over the period
    x.dq = now.q_meas_rad - prev.q_meas_rad;
    x.tau_mean = 0.5 * (now.tau_sensor_Nm + prev.tau_sensor_Nm);
    x.perceived = k.ratio * k.kt_Nm_per_A * x.i;
    return x;
  };

  // 1. Electrical balance.
  for (int j = 0; j < n; ++j) {
    Ridge<4> fit;
    for (size_t t = 1; t < ticks; ++t) {
      const Tick x = tick_of(t, j);
      const JointSignals& now = data.signals[t][j];
      fit.Add(Eigen::Vector4d(1.0, x.perceived * x.dq / dt, x.i * x.i, std::fabs(x.i)), now.v_bus_meas_V * now.i_supply_meas_A);
    }
    const ElectricalCalibration& e0 = nominal.joints[j].electrical;
    const Eigen::Vector4d theta0(e0.quiescent_W, e0.rotor_gain, e0.copper_W_per_A2 + e0.conduction_W_per_A2,
                                 e0.switching_W_per_A);
    const Eigen::Vector4d sd(std::max(0.5, 0.5 * e0.quiescent_W), 0.2, 0.5 * theta0(2),
                             std::max(0.1, 0.5 * e0.switching_W_per_A));
    double rms = 0;
    // Supply-sensor noise and period averaging make ~0.5 W per tick.
    const Eigen::Vector4d te = fit.Solve(0.5, theta0, sd, &rms);
    if (!AllFinite(te) || te(1) < 0.5 || te(1) > 1.5) continue;
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
    double sum = 0;
    long count = 0;
    for (size_t t = 0; t < ticks; ++t) {
      const double temp = data.signals[t][j].winding_temp_C;
      if (std::isfinite(temp)) sum += temp, ++count;
    }
    if (count > 0) model.joints[j].electrical.reference_temp_C = sum / count;
  }

  // 2. Torque balance with that gain: rotor inertia, mesh loss, friction curve, offset.
  std::vector<BalanceFilter> filters;
  for (const JointKnowledge& k : nominal.joints) {
    filters.emplace_back(c.balance_filter_s, dt, c.rest_velocity_rad_s, k.mechanical.stribeck_s2);
  }
  std::vector<Ridge<6>> fits(n);
  for (size_t t = 1; t < ticks; ++t) {
    for (int j = 0; j < n; ++j) {
      const JointKnowledge& k = model.joints[j];
      const Tick x = tick_of(t, j);
      const FilteredTerms& f = filters[j].Push(x.perceived, x.dq / dt, x.tau_mean);
      double coupling = 0;
      for (int l = 0; l < j; ++l) {
        if (k.coupling[l] != 0) coupling += k.coupling[l] * k.mechanical.rotor_coupling_kg_m2 * filters[l].terms().accel_rad_s2;
      }
      if (!f.usable) continue;
      Eigen::Matrix<double, 6, 1> row;
      row << -f.accel_rad_s2, -f.mesh_Nm, -f.viscous_rad_s, -f.coulomb, -f.stribeck, 1.0;
      fits[j].Add(row, f.sensor_Nm + coupling - k.mechanical.torque_gain * f.perceived_Nm);
    }
  }
  for (int j = 0; j < n; ++j) {
    if (fits[j].rows < kMinBalanceTicks) continue;  // the joint hardly moved: keep the datasheet
    JointKnowledge& k = model.joints[j];
    const MechanicalCalibration& m0 = nominal.joints[j].mechanical;
    Eigen::Matrix<double, 6, 1> theta0, sd;
    theta0 << m0.rotor_inertia_kg_m2, m0.mesh_loss_fraction, m0.viscous_Nm_s, m0.coulomb_Nm, m0.stribeck_Nm,
        m0.sensor_offset_Nm;
    sd << kRotorInertiaSpread * m0.rotor_inertia_kg_m2, std::max(0.1, 0.5 * m0.mesh_loss_fraction),
        0.5 * m0.viscous_Nm_s + 1e-3, 0.5 * m0.coulomb_Nm + 0.01, 0.5 * m0.stribeck_Nm + 0.01, 1.0;
    double rms = 0;
    // The filtered balance scatters ~0.1 N m per tick on a healthy unit.
    const Eigen::Matrix<double, 6, 1> tm = fits[j].Solve(0.1, theta0, sd, &rms);
    if (!AllFinite(tm) || tm(0) <= 0) continue;
    MechanicalCalibration& mc = k.mechanical;
    mc.rotor_inertia_kg_m2 = tm(0);
    mc.mesh_loss_fraction = std::max(0.0, tm(1));
    mc.viscous_Nm_s = std::max(0.0, tm(2));
    mc.coulomb_Nm = std::max(0.0, tm(3));
    mc.stribeck_Nm = std::max(0.0, tm(4));
    mc.sensor_offset_Nm = tm(5);
    k.balance_sigma_Nm = std::max(nominal.joints[j].balance_sigma_Nm, rms);
    k.commissioned = true;
  }
  return model;
}

}  // namespace armfault
