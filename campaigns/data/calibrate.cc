#include "campaigns/data/calibrate.h"

#include <Eigen/Dense>
#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>

#include "campaigns/data/log_reference.h"
#include "core/base/json_input.h"
#include "core/base/rng.h"
#include "core/monitors/power_monitor.h"
#include "core/monitors/torque_balance.h"
#include "core/plant/robot/rigid_body_dynamics.h"
#include "core/plant/simulation.h"

namespace armfault {
namespace {

constexpr int kE = 4;  // electrical: P_0, k, 2(R + R_sw), c
constexpr int kM = 7;  // mechanical: s k, s I_r, μ, s γ b, s γ F_c, s γ F_s, d
using VecE = Eigen::Matrix<double, kE, 1>;
using MatE = Eigen::Matrix<double, kE, kE>;
using VecM = Eigen::Matrix<double, kM, 1>;
using MatM = Eigen::Matrix<double, kM, kM>;

// Normal equations of one bootstrap block of one joint.
struct BlockSums {
  MatE ea = MatE::Zero();
  VecE eb = VecE::Zero();
  double eyy = 0, bus_V = 0;
  long erows = 0;
  MatM ma = MatM::Zero();
  VecM mb = VecM::Zero();
  double myy = 0;
  long mrows = 0;
  void Add(const BlockSums& o) {
    ea += o.ea, eb += o.eb, eyy += o.eyy, bus_V += o.bus_V, erows += o.erows;
    ma += o.ma, mb += o.mb, myy += o.myy, mrows += o.mrows;
  }
};

// Least squares from normal equations; columns the data never excited (a zero diagonal) are
// held at 0 rather than made up. Returns NaNs if the system is singular otherwise.
template <int N>
Eigen::Matrix<double, N, 1> Solve(const Eigen::Matrix<double, N, N>& a, const Eigen::Matrix<double, N, 1>& b,
                                  double yy, long rows, double* rms) {
  Eigen::Matrix<double, N, N> m = a;
  Eigen::Matrix<double, N, 1> r = b;
  for (int c = 0; c < N; ++c) {
    if (!(m(c, c) > 0)) {
      m.row(c).setZero(), m.col(c).setZero(), m(c, c) = 1, r(c) = 0;
    }
  }
  // Scale to unit diagonal so that a tiny ridge is the same for every column.
  const Eigen::Matrix<double, N, 1> d = m.diagonal().cwiseSqrt().cwiseInverse();
  Eigen::Matrix<double, N, N> ms = d.asDiagonal() * m * d.asDiagonal();
  ms.diagonal().array() += 1e-12;
  const Eigen::Matrix<double, N, 1> theta = d.asDiagonal() * ms.ldlt().solve(d.asDiagonal() * r);
  if (rms) {
    const double sse = yy - 2 * theta.dot(b) + theta.dot(a * theta);
    *rms = rows > 0 ? std::sqrt(std::max(0.0, sse) / rows) : 0.0;
  }
  return theta;
}

struct ParameterSpec {
  const char* key;
  const char* unit;
};
// The calibrated parameters of a joint, in the order Derive returns them.
const std::vector<ParameterSpec>& Specs() {
  static const std::vector<ParameterSpec> specs = {
      {"motor/kt_Nm_per_A", "N m/A"},
      {"motor/phase_resistance_ohm", "ohm"},
      {"inverter/quiescent_power_W", "W"},
      {"motor/rotor_inertia_kg_m2", "kg m^2"},
      {"drive/mesh_loss_fraction", ""},
      {"friction/viscous_Nm_s_per_rad", "N m s/rad"},
      {"friction/coulomb_Nm", "N m"},
      {"friction/static_Nm", "N m"},
      {"torque_sensor/gain_error", ""},
      {"torque_sensor/offset_error_Nm", "N m"},
  };
  return specs;
}

double NominalOf(const ModuleParams& m, size_t index) {
  switch (index) {
    case 0: return m.motor.kt_Nm_per_A;
    case 1: return m.motor.phase_resistance_ohm;
    case 2: return m.inverter.quiescent_power_W;
    case 3: return m.motor.rotor_inertia_kg_m2;
    case 4: return m.drive.mesh_loss_fraction;
    case 5: return m.friction.viscous_Nm_s_per_rad;
    case 6: return m.friction.coulomb_Nm;
    case 7: return m.friction.static_Nm;
    case 8: return m.torque_sensor.gain_error;
    case 9: return m.torque_sensor.offset_error_Nm;
  }
  return 0;
}

void SetIn(ModuleParams* m, size_t index, double v) {
  switch (index) {
    case 0: m->motor.kt_Nm_per_A = v; break;
    case 1: m->motor.phase_resistance_ohm = v; break;
    case 2: m->inverter.quiescent_power_W = v; break;
    case 3: m->motor.rotor_inertia_kg_m2 = v; break;
    case 4: m->drive.mesh_loss_fraction = v; break;
    case 5: m->friction.viscous_Nm_s_per_rad = v; break;
    case 6: m->friction.coulomb_Nm = v; break;
    case 7: m->friction.static_Nm = v; break;
    case 8: m->torque_sensor.gain_error = v; break;
    case 9: m->torque_sensor.offset_error_Nm = v; break;
  }
}

// Plant values from the fitted coefficients (see the header's equations).
std::vector<double> Derive(const VecE& e, const VecM& m, const JointKnowledge& k, bool mechanical) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> v(Specs().size(), nan);
  const double kratio = e(1);
  v[0] = kratio * k.kt_Nm_per_A;
  v[1] = 0.5 * e(2) - k.switch_resistance_ohm;
  v[2] = e(0);
  if (!mechanical) return v;
  const double s = m(0) / kratio;
  const double g = k.ratio;
  v[3] = m(1) / s / (g * g);
  v[4] = m(2);
  v[5] = m(3) / (s * g);
  v[6] = m(4) / (s * g);
  v[7] = m(5) / (s * g);
  if (k.torque_sensor) {
    v[8] = s - 1.0;
    v[9] = m(6);
  }
  return v;
}

// Whether `v` is a value the plant accepts for parameter `index` (a twin must run).
bool Plausible(size_t index, double v) {
  if (!std::isfinite(v)) return false;
  switch (index) {
    case 0: case 1: case 3: return v > 0;
    case 2: case 5: case 6: case 7: return v >= 0;
    case 4: return v >= 0 && v <= 0.9;
    case 8: return v > -0.5 && v < 0.5;
  }
  return true;
}

// Standard deviation of the finite values (NaN if fewer than 2).
double StandardDeviation(const std::vector<double>& x) {
  double sum = 0, sq = 0;
  long count = 0;
  for (double a : x) {
    if (std::isfinite(a)) sum += a, sq += a * a, ++count;
  }
  if (count < 2) return std::numeric_limits<double>::quiet_NaN();
  const double mean = sum / count;
  return std::sqrt(std::max(0.0, (sq - count * mean * mean) / (count - 1)));
}

}  // namespace

const CalibratedParameter* FindParameter(const JointCalibration& joint, const std::string& key) {
  for (const CalibratedParameter& p : joint.parameters) {
    if (p.key == key) return &p;
  }
  return nullptr;
}

namespace {

// One fit of a log: per joint, the estimates (Specs() order), their bootstrap percentiles, the
// rows and residuals.
struct JointFit {
  std::vector<double> estimate, sd;  // sd: the bootstrap's standard deviation
  long electrical_rows = 0, balance_rows = 0;
  double power_rms_W = 0, current_rms_A = 0, torque_rms_Nm = 0, winding_temp_C = 0;
};
struct LogFit {
  std::vector<JointFit> joints;
  double payload_kg = std::numeric_limits<double>::quiet_NaN(), payload_sd_kg = std::numeric_limits<double>::quiet_NaN();
};

// Per joint with a torque sensor and block: the payload regression's sums, with x the torque a
// kilogram of payload adds (rigid-body model at the reference's q, q̇, q̈) and τ0 the model's
// torque without payload: Σx², Σx τ_s, Σx, Σx τ0.
struct PayloadSums {
  double xx = 0, xs = 0, x = 0, x0 = 0;
  void Add(const PayloadSums& o) { xx += o.xx, xs += o.xs, x += o.x, x0 += o.x0; }
};

LogFit FitLog(const RobotConfig& nominal, const PowerMonitorModel& model, double dt,
              const std::vector<std::vector<JointSignals>>& ticks, const CalibrationOptions& options, long block_ticks) {
  const RigidBodyModel without_payload = MakeRigidBodyModel(nominal, 0.0);
  const RigidBodyModel with_kg = MakeRigidBodyModel(nominal, 1.0);
  const size_t n = model.joints.size();
  const long total = static_cast<long>(ticks.size());
  const MonitorConfig& mc = model.config;
  std::vector<BalanceFilter> filters;
  for (const JointKnowledge& k : model.joints) filters.emplace_back(mc.balance_filter_s, dt, mc.rest_velocity_rad_s, k.mechanical.stribeck_s2);

  const long nblocks = (total - 1) / block_ticks;
  std::vector<std::vector<BlockSums>> blocks(n, std::vector<BlockSums>(nblocks));
  std::vector<std::vector<PayloadSums>> payload(n, std::vector<PayloadSums>(nblocks));
  std::vector<double> q(n), qd(n), qdd(n), tau0(n), tau1(n);
  std::vector<double> temp_sum(n, 0.0);
  std::vector<long> temp_count(n, 0);
  std::vector<JointSignals> prev = ticks[0], now;
  if (model.virtual_sensor.any()) model.virtual_sensor.Fill(ticks[0], 0.0, &prev);
  for (long t = 1; t < 1 + nblocks * block_ticks; ++t) {
    now = ticks[t];
    if (model.virtual_sensor.any()) model.virtual_sensor.Fill(prev, dt, &now);
    const long b = (t - 1) / block_ticks;
    // The payload's torques along the reference (the arm tracks it within a fraction of a
    // degree; the encoder's second difference would be noise).
    for (size_t j = 0; j < n; ++j) {
      q[j] = now[j].q_ref_rad, qd[j] = now[j].qd_ref_rad_s;
      const long next = std::min(t + 1, total - 1);
      qdd[j] = (ticks[next][j].qd_ref_rad_s - prev[j].qd_ref_rad_s) / (static_cast<double>(next - t + 1) * dt);
    }
    TransmittedTorques(without_payload, q.data(), qd.data(), qdd.data(), tau0.data());
    TransmittedTorques(with_kg, q.data(), qd.data(), qdd.data(), tau1.data());
    for (size_t j = 0; j < n; ++j) {
      if (!model.joints[j].torque_sensor) continue;
      const double x = tau1[j] - tau0[j];
      PayloadSums& ps = payload[j][b];
      ps.xx += x * x, ps.xs += x * now[j].tau_sensor_Nm, ps.x += x, ps.x0 += x * tau0[j];
    }
    for (size_t j = 0; j < n; ++j) {
      const JointKnowledge& k = model.joints[j];
      const JointSignals& a = prev[j];
      const JointSignals& z = now[j];
      if (std::isfinite(z.winding_temp_C)) temp_sum[j] += z.winding_temp_C, ++temp_count[j];
      BlockSums& s = blocks[j][b];
      const double i = a.i_cmd_A;  // held over the period
      const double qd = (z.q_meas_rad - a.q_meas_rad) / dt;
      const double perceived = k.ratio * k.kt_Nm_per_A * i;
      const VecE xe(1.0, perceived * qd, i * i, std::fabs(i));
      const double ye = z.v_bus_meas_V * z.i_supply_meas_A;
      s.ea.noalias() += xe * xe.transpose();
      s.eb.noalias() += xe * ye;
      s.eyy += ye * ye;
      s.bus_V += z.v_bus_meas_V;
      ++s.erows;
      const FilteredTerms& f = filters[j].Push(perceived, qd, 0.5 * (a.tau_sensor_Nm + z.tau_sensor_Nm));
      double coupling = 0;
      for (size_t l = 0; l < j; ++l) {
        if (k.coupling[l] != 0) coupling += k.coupling[l] * k.mechanical.rotor_coupling_kg_m2 * filters[l].terms().accel_rad_s2;
      }
      if (!f.usable) continue;
      VecM xm;
      xm << f.perceived_Nm, -f.accel_rad_s2, -f.mesh_Nm, -f.viscous_rad_s, -f.coulomb, -f.stribeck, 1.0;
      const double ym = f.sensor_Nm + coupling;
      s.ma.noalias() += xm * xm.transpose();
      s.mb.noalias() += xm * ym;
      s.myy += ym * ym;
      ++s.mrows;
    }
    prev.swap(now);
  }

  Rng rng(options.seed);
  // One set of block draws for every joint: the joints' errors are correlated through the arm.
  std::vector<std::vector<long>> draws(options.resamples, std::vector<long>(nblocks));
  for (auto& d : draws) {
    for (long& b : d) b = static_cast<long>(rng.Uniform() * static_cast<double>(nblocks));
  }
  LogFit out;
  std::vector<JointFit>& fits = out.joints;
  fits.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const JointKnowledge& k = model.joints[j];
    BlockSums all;
    for (const BlockSums& b : blocks[j]) all.Add(b);
    JointFit& fit = fits[j];
    fit.electrical_rows = all.erows;
    fit.balance_rows = all.mrows;
    fit.winding_temp_C = temp_count[j] > 0 ? temp_sum[j] / temp_count[j] : std::numeric_limits<double>::quiet_NaN();
    const bool mechanical = all.mrows >= block_ticks;  // one block's worth of one-way motion at least
    double erms = 0, mrms = 0;
    const VecE e = Solve<kE>(all.ea, all.eb, all.eyy, all.erows, &erms);
    const VecM mm = Solve<kM>(all.ma, all.mb, all.myy, all.mrows, &mrms);
    fit.power_rms_W = erms;
    fit.current_rms_A = all.erows > 0 && all.bus_V > 0 ? erms / (all.bus_V / all.erows) : 0.0;
    fit.torque_rms_Nm = mechanical ? mrms : 0.0;
    fit.estimate = Derive(e, mm, k, mechanical);
    std::vector<std::vector<double>> boot(Specs().size());
    for (const std::vector<long>& d : draws) {
      BlockSums s;
      for (long b : d) s.Add(blocks[j][b]);
      const std::vector<double> v = Derive(Solve<kE>(s.ea, s.eb, s.eyy, s.erows, nullptr),
                                           Solve<kM>(s.ma, s.mb, s.myy, s.mrows, nullptr), k, mechanical);
      for (size_t p = 0; p < v.size(); ++p) boot[p].push_back(v[p]);
    }
    for (size_t p = 0; p < Specs().size(); ++p) {
      fit.sd.push_back(StandardDeviation(boot[p]));
    }
  }
  // Payload: τ_s = s (τ0 + m x) + d on every joint with a sensor, with each joint's s and d as
  // just fitted (1 and 0 where the torque balance had too few rows).
  auto payload_of = [&](const std::vector<long>* draw) {
    double num = 0, den = 0;
    for (size_t j = 0; j < n; ++j) {
      if (!model.joints[j].torque_sensor) continue;
      double s = 1.0 + fits[j].estimate[8], d = fits[j].estimate[9];
      if (!std::isfinite(s) || !(s > 0.5)) s = 1.0;
      if (!std::isfinite(d)) d = 0.0;
      PayloadSums sum;
      if (draw) {
        for (long b : *draw) sum.Add(payload[j][b]);
      } else {
        for (const PayloadSums& ps : payload[j]) sum.Add(ps);
      }
      num += (sum.xs - d * sum.x) / s - sum.x0;
      den += sum.xx;
    }
    return den > 0 ? num / den : std::numeric_limits<double>::quiet_NaN();
  };
  out.payload_kg = payload_of(nullptr);
  std::vector<double> boot;
  for (const std::vector<long>& d : draws) boot.push_back(payload_of(&d));
  out.payload_sd_kg = StandardDeviation(boot);
  return out;
}

RobotConfig WithValues(const RobotConfig& nominal, const std::vector<std::vector<double>>& values) {
  RobotConfig twin = nominal;
  for (size_t j = 0; j < values.size(); ++j) {
    for (size_t p = 0; p < values[j].size(); ++p) {
      if (Plausible(p, values[j][p])) SetIn(&twin.modules[j], p, values[j][p]);
    }
  }
  return twin;
}

}  // namespace

UnitCalibration CalibrateUnit(const RobotConfig& nominal, double control_dt_s,
                              const std::vector<std::vector<JointSignals>>& ticks, const CalibrationOptions& options) {
  const PowerMonitorModel model = MakePowerMonitorModel(nominal, MonitorConfig{});
  const size_t n = model.joints.size();
  const double dt = control_dt_s;
  const long block_ticks = std::max(1L, std::lround(options.block_s / dt));
  const long total = static_cast<long>(ticks.size());
  if (total < 2 * block_ticks + 1) {
    throw InputError("calibrate", "",
                     "the log holds " + std::to_string(total) + " ticks (" + FormatNumber(total * dt) +
                         " s); calibration needs at least two bootstrap blocks of " + FormatNumber(options.block_s) + " s");
  }
  for (long t = 0; t < total; ++t) {
    if (ticks[t].size() != n) {
      throw InputError("calibrate", "", "tick " + std::to_string(t) + " holds " + std::to_string(ticks[t].size()) +
                                            " joints; the robot has " + std::to_string(n));
    }
  }
  const LogFit log_fit = FitLog(nominal, model, dt, ticks, options, block_ticks);
  const std::vector<JointFit>& fits = log_fit.joints;
  // The fit's own bias, measured on the model: the twin so far runs the log's motion, is fitted
  // the same way, and what the fit gets wrong about a unit it knows exactly is taken off.
  // Indirect inference: find the twin θ whose fit on its own run of the log's motion, g(θ),
  // equals the log's fit. Each round steps every parameter by the gap over g's slope in it
  // (a secant from the last two rounds, 1 at first); the twin's runs share one noise seed,
  // so that g is smooth in θ and the slope is not noise.
  std::vector<std::vector<double>> theta(n), prev_theta, prev_g;
  for (size_t j = 0; j < n; ++j) theta[j] = fits[j].estimate;
  std::vector<JointFit> on_twin;
  double payload = log_fit.payload_kg, prev_payload = 0, prev_payload_g = 0, payload_twin_sd = 0;
  auto secant = [](int iteration, double theta, double prev_theta, double g, double prev_g) {
    double slope = 1.0;
    if (iteration > 0) {
      const double dtheta = theta - prev_theta;
      if (std::fabs(dtheta) > 1e-9 * (std::fabs(theta) + 1e-12)) slope = std::clamp((g - prev_g) / dtheta, 0.2, 5.0);
      if (!std::isfinite(slope)) slope = 1.0;
    }
    return slope;
  };
  for (int iteration = 0; iteration < options.bias_iterations; ++iteration) {
    RobotConfig twin = WithValues(nominal, theta);
    if (std::isfinite(payload) && payload >= 0) twin.payload_kg = payload;
    const LogFit twin_fit = FitLog(nominal, model, dt, SimulateAlongLog(twin, dt, ticks, options.seed + 1, "calibrate"), options, block_ticks);
    on_twin = twin_fit.joints;
    if (std::isfinite(payload) && std::isfinite(twin_fit.payload_kg)) {
      const double slope = secant(iteration, payload, prev_payload, twin_fit.payload_kg, prev_payload_g);
      prev_payload = payload, prev_payload_g = twin_fit.payload_kg;
      payload += (log_fit.payload_kg - twin_fit.payload_kg) / slope;
      payload_twin_sd = twin_fit.payload_sd_kg;
    }
    std::vector<std::vector<double>> next = theta, g(n);
    for (size_t j = 0; j < n; ++j) {
      g[j] = on_twin[j].estimate;
      for (size_t p = 0; p < Specs().size(); ++p) {
        const double slope =
            iteration > 0 ? secant(iteration, theta[j][p], prev_theta[j][p], g[j][p], prev_g[j][p]) : 1.0;
        next[j][p] = theta[j][p] + (fits[j].estimate[p] - g[j][p]) / slope;
      }
    }
    prev_theta = theta, prev_g = g;
    theta = next;
  }
  const std::vector<std::vector<double>>& corrected = theta;
  std::vector<std::vector<double>> last_step(n, std::vector<double>(Specs().size(), 0.0));
  if (!prev_theta.empty()) {
    for (size_t j = 0; j < n; ++j) {
      for (size_t p = 0; p < Specs().size(); ++p) last_step[j][p] = theta[j][p] - prev_theta[j][p];
    }
  }
  const double blocks_n = static_cast<double>((total - 1) / block_ticks);
  const double t95 = boost::math::quantile(boost::math::students_t(blocks_n - 1), 0.975);

  UnitCalibration out;
  out.blocks = static_cast<int>((total - 1) / block_ticks);
  out.twin = nominal;
  for (size_t j = 0; j < n; ++j) {
    const JointKnowledge& k = model.joints[j];
    const ModuleParams& m0 = nominal.modules[j];
    const JointFit& fit = fits[j];
    JointCalibration jc;
    jc.joint = static_cast<int>(j) + 1;
    jc.electrical_rows = fit.electrical_rows;
    jc.balance_rows = fit.balance_rows;
    jc.winding_temp_C = fit.winding_temp_C;
    jc.power_rms_W = fit.power_rms_W;
    jc.current_rms_A = fit.current_rms_A;
    jc.torque_rms_Nm = fit.torque_rms_Nm;
    for (size_t p = 0; p < Specs().size(); ++p) {
      if (p >= 8 && !k.torque_sensor) continue;  // no sensor to calibrate
      CalibratedParameter cp;
      cp.key = Specs()[p].key;
      cp.unit = Specs()[p].unit;
      cp.nominal = NominalOf(m0, p);
      cp.estimate = corrected[j][p];
      // 95 %: the log's bootstrap spread and the twin fit's (its run has noise of its own), in
      // quadrature, as a Student t over the blocks (few blocks: the bootstrap's spread is short
      // by sqrt((B - 1) / B)), plus the last round's step (what the iteration still moved).
      double sd = fit.sd[p];
      if (!on_twin.empty()) sd = std::hypot(sd, on_twin[j].sd[p]);
      const double half = t95 * sd * std::sqrt(blocks_n / (blocks_n - 1)) + std::fabs(last_step[j][p]);
      cp.low = cp.estimate - half;
      cp.high = cp.estimate + half;
      // A sensor error's scale is the reading's (1 and the sensor's full scale), not its 0 nominal.
      double scale = std::fabs(cp.nominal);
      if (p == 8) scale = 0.1;
      if (p == 9) scale = 0.05 * m0.torque_sensor.full_scale_Nm;
      if (p == 4) scale = std::max(scale, 0.05);
      cp.identifiable = Plausible(p, cp.estimate) && std::isfinite(cp.low) && std::isfinite(cp.high) &&
                        0.5 * (cp.high - cp.low) <= options.identifiable_spread * scale;
      if (cp.identifiable) SetIn(&out.twin.modules[j], p, cp.estimate);
      jc.parameters.push_back(cp);
    }
    out.joints.push_back(std::move(jc));
  }
  // Payload: a point mass at the tool, from every sensor joint's torques.
  out.payload.key = "payload_kg";
  out.payload.unit = "kg";
  out.payload.nominal = nominal.payload_kg;
  out.payload.estimate = payload;
  const double payload_half =
      t95 * std::hypot(log_fit.payload_sd_kg, payload_twin_sd) * std::sqrt(blocks_n / (blocks_n - 1)) +
      std::fabs(payload - prev_payload) * (options.bias_iterations > 1 ? 1.0 : 0.0);
  out.payload.low = payload - payload_half;
  out.payload.high = payload + payload_half;
  out.payload.identifiable = std::isfinite(payload) && payload >= 0 && std::isfinite(payload_half) &&
                             payload_half <= options.identifiable_spread * std::max(std::fabs(nominal.payload_kg), 1.0);
  if (out.payload.identifiable) out.twin.payload_kg = payload;
  return out;
}

}  // namespace armfault
