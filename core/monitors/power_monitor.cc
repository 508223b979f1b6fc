#include "core/monitors/power_monitor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>

#include "core/base/distributions.h"
#include "core/monitors/electrical_fit.h"
#include "core/monitors/friction_reference.h"
#include "core/monitors/linear_solve.h"
#include "core/monitors/sequential_test.h"
#include "core/monitors/tick_detectors.h"
#include "core/plant/drive/torque_sensor.h"

namespace armfault {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Ticks over which the balance residual stays correlated (the low-pass memory, both sides).
double CorrelationTicks(const MonitorConfig& c, double dt) { return std::max(1.0, 2.0 * c.balance_filter_s / dt); }

double NormalCdf(double z) { return StandardNormalCdf(z); }

// Deviation in standard errors; an exact (se 0) deviation counts as very significant.
double Significance(double deviation, double se) {
  if (se > 0) return deviation / se;
  return deviation > 0 ? 1e9 : (deviation < 0 ? -1e9 : 0.0);
}

// One judged window as the mechanical fit uses it.
struct MechanicalWindow {
  double rotor_J, out_J, mesh_loss_J, friction_J, dq_rad, sigma_J;
};

// The windows bounded by zero velocity of one joint, and the thesis-view mechanical fit over
// the last `mechanical_windows` used ones.
struct WindowState {
  bool in_window = false;
  EfficiencyWindow window;
  double window_dq = 0;
  std::deque<MechanicalWindow> mech;
  double friction_factor = 1;  // the window fit's
};

// One joint's tick-rate torque balance (core/monitors/torque_balance.h): friction alone, fast
// (the friction detector; and its twin with the zero fit's offset until the sensor's zero is
// found); friction and the sensor offset, slow (the drift detector) and over a work cycle (the
// zero fit: the sensor's zero the fast fit removes); and one that grows from the friction or
// drift statistic's first crossing (the magnitude, free of the data before the change).
struct TorqueBalance {
  TorqueBalance(const MonitorConfig& c, const JointKnowledge& k, double dt)
      : filter(c.balance_filter_s, dt, c.rest_velocity_rad_s, k.mechanical.stribeck_s2),
        fast({false, false}, c.balance_time_constant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        slow({false, true}, c.drift_balance_time_constant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        zero({false, true}, c.zero_balance_time_constant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        unfound_zero({false, false}, c.balance_time_constant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        since_alarm({false, true}, 0, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        fast_forget(std::exp(-dt / c.balance_time_constant_s)) {}
  BalanceFilter filter;
  BalanceFit fast, slow, zero, unfound_zero, since_alarm;
  bool crossed = false;
  // Σ f² and Σ f g of the usable rows, f the friction curve's term and g the gear's (mesh and
  // load friction), with the fast fit's forgetting and since the first crossing (since_alarm).
  double fast_ff = 0, fast_fg = 0, alarm_ff = 0, alarm_fg = 0;
  double fast_forget;  // the fast fit's per-tick forgetting
  // The sensor's zero as this run found it, relative to the calibration [N m].
  double offset_base_Nm = 0;
  bool offset_base_set = false;
};

// The decision of one joint: the swept detectors' held statistics and the verdicts emitted.
struct Decision {
  Decision(const MonitorConfig& c, long hold_span) {
    for (SlidingMin& h : held) h = SlidingMin(hold_span);
    for (SlidingMin& h : held_significance) h = SlidingMin(hold_span);
    const std::array<double, kDetectorCount> looks = SequentialLooks(c);
    const std::array<double, kDetectorCount> model_error = SequentialModelErrors(c);
    const std::array<double, kDetectorCount> se_scale = SequentialSeScales(c);
    const std::array<double, kDetectorCount> wander = SequentialWanders(c);
    for (int d = 0; d < kDetectorCount; ++d) {
      sequential[d] = SequentialTest(looks[d], c.sequential_allowance_sd, model_error[d], wander[d],
                                     c.sequential_settle_s, se_scale[d], d == static_cast<int>(Detector::kSensorDrift));
    }
  }
  std::array<SlidingMin, kDetectorCount> held, held_significance;
  // "sequential": a bias filter and CUSUM per detector (the drift's both ways)
  std::array<SequentialTest, kDetectorCount> sequential;
  DetectorReadings readings;
  Candidate structural;  // latched once a tick-level detector fires
  std::string shown_family = "";  // family of the last verdict emitted ("" healthy)
  HealthState shown_state = HealthState::kHealthy;
  double last_emit_t = -1e9;
  double last_emit_magnitude = 0;
};

}  // namespace

// One joint's run data: each estimator's own state.
struct PowerEfficiencyMonitor::JointState {
  JointState(const MonitorConfig& c, const JointKnowledge& k, double dt, long hold_span)
      : electrical(c, dt, k.constant_power_sd_W), balance(c, k, dt), friction(c, dt), decision(c, hold_span) {}
  // this tick (Observe's phases): its terms, whether it closed the window, the verdict shown
  TickTerms tick;
  bool window_closed = false;
  Candidate shown;
  ElectricalEstimator electrical;
  TorqueBalance balance;
  FrictionReference friction;  // the friction the run finds (the rules), and its blocks
  // The reference the friction statistic is judged against: the rules' (friction.reference),
  // or the arm's friction model's (friction_model.h) with the log-sd of its uncertainty.
  double reference = 1;
  double reference_log_sd = 0;
  WindowState windows;
  TickDetectors detectors;
  Decision decision;
  Estimates est;
};

PowerEfficiencyMonitor::PowerEfficiencyMonitor(const PowerMonitorModel& model)
    : model_(model),
      friction_model_(model.config, static_cast<int>(model.joints.size())),
      winding_above_K_(model.joints.size(), kNaN) {
  for (size_t j = 0; j < model.joints.size(); ++j) {
    joints_.push_back(std::make_unique<JointState>(model.config, model.joints[j], model.control_dt_s, model.hold_span));
    arm_joints_.push_back({&joints_.back()->friction, &joints_.back()->electrical});
  }
}
PowerEfficiencyMonitor::~PowerEfficiencyMonitor() = default;

PowerEfficiencyMonitor::Estimates PowerEfficiencyMonitor::estimates(int joint) const {
  return joints_.at(joint)->est;
}
const DetectorReadings& PowerEfficiencyMonitor::readings(int joint) const { return joints_.at(joint)->decision.readings; }
const std::string& PowerEfficiencyMonitor::structural_family(int joint) const {
  return joints_.at(joint)->decision.structural.family;
}

PowerMonitorModel MakePowerMonitorModel(const RobotConfig& robot, const MonitorConfig& config) {
  Validate(config, "", "<monitor>");
  PowerMonitorModel m;
  m.config = config;
  m.control_dt_s = 1.0 / robot.modules.at(0).controller.rate_Hz;
  ValidateDecisionRate(config, robot.modules.at(0).controller.rate_Hz, "", "<monitor>");
  m.thresholds = ThresholdsOf(config);
  m.sequential = config.decision == kSequentialDecision;
  // The CUSUM is its own memory: no debounce on top of it.
  m.hold_span = m.sequential ? 1 : std::lround(config.debounce_s / m.control_dt_s) + 1;
  m.decision_thresholds = m.thresholds;
  m.decision_significance = config.significance;
  std::vector<std::array<double, 3>> axes;
  for (size_t i = 0; i < robot.modules.size(); ++i) {
    const ModuleParams& p = robot.modules[i];
    JointKnowledge k;
    k.ratio = p.drive.ratio;
    k.kt_Nm_per_A = p.motor.kt_Nm_per_A;
    k.phase_resistance_ohm = p.motor.phase_resistance_ohm;
    k.switch_resistance_ohm = p.inverter.switch_resistance_ohm;
    k.switching_loss_W_per_A = p.inverter.bus_voltage_V * p.inverter.switching_time_s * p.inverter.pwm_frequency_Hz;
    k.quiescent_W = p.inverter.quiescent_power_W;
    k.mesh_loss_fraction = p.drive.mesh_loss_fraction;
    k.friction = p.friction;
    k.brake_holding_Nm = p.brake.holding_torque_Nm;
    k.rotor_inertia_link_kg_m2 = p.motor.rotor_inertia_kg_m2 * p.drive.ratio * p.drive.ratio;
    // Until commissioning, the unit is its datasheet.
    k.electrical.quiescent_W = k.quiescent_W;
    k.electrical.copper_W_per_A2 = 2.0 * k.phase_resistance_ohm;
    k.electrical.conduction_W_per_A2 = 2.0 * k.switch_resistance_ohm;
    k.electrical.switching_W_per_A = 2.0 * k.switching_loss_W_per_A;
    MechanicalCalibration& mc = k.mechanical;
    mc.rotor_inertia_kg_m2 = k.rotor_inertia_link_kg_m2;
    mc.rotor_coupling_kg_m2 = p.motor.rotor_inertia_kg_m2 * p.drive.ratio;
    mc.viscous_Nm_s = k.ratio * p.friction.viscous_Nm_s_per_rad;
    mc.coulomb_Nm = k.ratio * p.friction.coulomb_Nm;
    mc.stribeck_Nm = k.ratio * p.friction.static_Nm;
    mc.stribeck_s2 = p.friction.stribeck_s2_per_rad2;
    mc.mesh_loss_fraction = k.mesh_loss_fraction;
    k.balance_sigma_Nm = std::max(config.min_balance_sigma_Nm, p.torque_sensor.noise_Nm);
    k.constant_power_sd_W = config.constant_power_uncertainty_W;
    const std::array<double, 3> a = JointAxisOf(robot, static_cast<int>(i));
    const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (const auto& b : axes) {
      const double nb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
      k.coupling.push_back((a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (na * nb));
    }
    axes.push_back(a);
    const TorqueSensorParams& ts = p.torque_sensor;
    k.sensor_min_Nm = TorqueFromAdcCode(ts, 0);
    k.sensor_max_Nm = TorqueFromAdcCode(ts, static_cast<int>(std::lround(std::pow(2.0, ts.adc_bits))) - 1);
    k.torque_sensor = ts.present;
    m.joints.push_back(k);
  }
  m.virtual_sensor = MakeVirtualTorqueSensor(robot);
  if (m.sequential) {
    int sensed = 0;
    for (const JointKnowledge& k : m.joints) sensed += k.torque_sensor ? 1 : 0;
    m.sequential_tests = SequentialTestCount(static_cast<int>(m.joints.size()), sensed);
    m.decision_thresholds = SequentialThresholds(config, m.sequential_tests);
    m.decision_significance = kSequentialSignificance;
  }
  return m;
}

namespace {

using JointState = PowerEfficiencyMonitor::JointState;

void FinishWindow(EfficiencyWindow* w) {
  w->mesh_in_J = w->rotor_J - w->friction_J;
  w->eta = w->eta_m = w->eta_e = w->eta_expected = w->eta_m_expected = w->eta_e_expected = kNaN;
  if (w->out_J > 0 && w->mesh_in_J > 0) {
    w->flow = "forward";
    w->eta_m = w->out_J / w->mesh_in_J;
    if (w->supply_J > 0) {
      w->eta = w->out_J / w->supply_J;
      w->eta_e = w->rotor_J / w->supply_J;
    }
    // A healthy joint delivering the same output: mesh input = output + mesh loss, rotor
    // power = that + modelled friction, supply = rotor power + electrical losses.
    const double mesh_in_h = w->out_J + w->mesh_loss_J;
    const double rotor_h = mesh_in_h + w->friction_J;
    w->eta_m_expected = w->out_J / mesh_in_h;
    w->eta_e_expected = rotor_h / (rotor_h + w->electrical_loss_J);
    w->eta_expected = w->out_J / (rotor_h + w->electrical_loss_J);
  } else if (w->out_J < 0 && w->mesh_in_J < 0) {
    w->flow = "reverse";
    w->eta_m = w->mesh_in_J / w->out_J;
    const double mesh_in_h = w->out_J + w->mesh_loss_J;  // the load's power less the mesh loss
    w->eta_m_expected = mesh_in_h / w->out_J;
    const double rotor_h = mesh_in_h + w->friction_J;
    if (w->supply_J < 0 && w->rotor_J < 0) {
      w->eta_e = w->supply_J / w->rotor_J;
      w->eta = w->supply_J / w->out_J;
    }
    if (rotor_h < 0 && rotor_h + w->electrical_loss_J < 0) {
      w->eta_e_expected = (rotor_h + w->electrical_loss_J) / rotor_h;
      w->eta_expected = (rotor_h + w->electrical_loss_J) / w->out_J;
    }
  } else {
    w->flow = "mixed";
  }
}

// The fast friction fit's estimate: with the sensor's zero the run found; before it is found,
// the smaller friction of the calibrated zero's and the zero fit's (UpdateFits).
const BalanceFit::Estimate& FastFriction(const JointKnowledge& k, const TorqueBalance& tb) {
  if (!k.torque_sensor || tb.offset_base_set) return tb.fast.estimate();
  const BalanceFit::Estimate& unfound = tb.unfound_zero.estimate();
  return unfound.friction_factor < tb.fast.estimate().friction_factor ? unfound : tb.fast.estimate();
}

// The electrical fits and the tick-rate torque balance fits after one tick, and the joint's
// estimates from them. `terms`: the balance filter's output at this tick; `coupling_torque`:
// the lower joints' rotor coupling [N m].
void UpdateFits(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x, const FilteredTerms& terms,
                double coupling_torque, double dt, const ArmAllowance& arm, JointState* state) {
  JointState& s = *state;
  // --- electrical balance, every tick ---
  s.electrical.Add(c, x.p_supply - x.p_fixed, x.p_rotor, x.p_copper, dt);
  const ElectricalFit& fit = s.electrical.fit;
  s.est.kt_factor = fit.n;
  s.est.kt_factor_se = fit.n_se;
  s.est.resistance_factor = fit.rho;
  s.est.resistance_factor_se = fit.rho_se;

  // The torque gain is the K_T factor the fast electrical fit sees (a magnet cannot
  // strengthen, so never above 1).
  TorqueBalance& tb = s.balance;
  const BalanceRow row = RowOf(k.mechanical, terms, coupling_torque);
  const double gain = std::min(1.0, s.electrical.fast.n);
  tb.slow.Add(row, gain, 0.0);
  if (k.torque_sensor) tb.zero.Add(row, gain, 0.0);  // a model's torque has no zero to find
  // The sensor's zero as the run finds it (sensor_zero_time_constant_s): an offset present when
  // it is first judged is the zero the unit starts with (its temperature against the
  // calibration's), not a drift, which is a change during operation.
  const BalanceFit::Estimate& zero_now = tb.zero.estimate();
  if (k.torque_sensor && std::min(zero_now.positive_s, zero_now.negative_s) >= c.min_offset_moving_each_way_s) {
    if (!tb.offset_base_set) {
      tb.offset_base_Nm = zero_now.offset_Nm;
      tb.offset_base_set = true;
    } else if (std::fabs(zero_now.offset_Nm - tb.offset_base_Nm) < c.sensor_drift_Nm.worn) {
      tb.offset_base_Nm += (zero_now.offset_Nm - tb.offset_base_Nm) * dt / c.sensor_zero_time_constant_s;
    }
  }
  // The fast fit removes that zero: within one direction of motion an offset cannot be told
  // from friction, and a warm sensor's zero taken for friction swings the fit with the
  // direction of motion. Until the zero is found, two hypotheses: the calibrated zero, and the
  // zero fit's offset as it stands (the calibrated one until the joint has moved both ways);
  // the friction read is the smaller (FastFriction).
  tb.fast.Add(row, gain, tb.offset_base_set ? tb.offset_base_Nm : 0.0);
  if (k.torque_sensor && !tb.offset_base_set) tb.unfound_zero.Add(row, gain, zero_now.offset_Nm);
  if (tb.crossed) tb.since_alarm.Add(row, std::min(1.0, fit.n), 0.0);
  {
    tb.fast_ff *= tb.fast_forget;
    tb.fast_fg *= tb.fast_forget;
    if (row.usable) {
      const double f = row.friction;
      const double g = k.mechanical.mesh_loss_fraction * terms.mesh_Nm + k.mechanical.mesh_backdriven_extra * terms.mesh_back_Nm;
      tb.fast_ff += f * f;
      tb.fast_fg += f * g;
      if (tb.crossed) {
        tb.alarm_ff += f * f;
        tb.alarm_fg += f * g;
      }
    }
  }
  const BalanceFit::Estimate& b = FastFriction(k, tb);
  const MechanicalCalibration& cal = k.mechanical;
  s.friction.zero_found = !k.torque_sensor || tb.offset_base_set;
  s.friction.Update(c, x.winding_above_K, s.electrical, b, terms.usable,
                    ViscousShare(cal.viscous_Nm_s * terms.viscous_rad_s, cal.coulomb_Nm * terms.coulomb,
                                 cal.stribeck_Nm * terms.stribeck),
                    dt, arm);
  if (c.friction_reference != kArmFrictionModel) {
    s.reference = s.friction.reference;
    s.reference_log_sd = 0;
  }
  const double reference = s.reference;
  const BalanceFit::Estimate& m = tb.since_alarm.estimate();
  const BalanceFit::Estimate& sl = tb.slow.estimate();
  const bool grown = tb.crossed && m.moving_s >= c.min_balance_moving_s;
  s.est.friction_factor = (grown ? m.friction_factor : b.friction_factor) / reference;
  s.est.friction_factor_se = std::hypot(b.friction_factor_se, b.friction_factor * s.reference_log_sd) / reference;
  // Wear scales the gear's friction g with the curve's f, while the balance holds g at its
  // calibration: a joint worn k-fold fits κ = k r + (k − 1) ρ, ρ = Σ f g / Σ f², so its whole
  // friction against the healthy one is 1 + (κ / r − 1) r / (r + ρ) = k.
  const double ff = grown ? tb.alarm_ff : tb.fast_ff, fg = grown ? tb.alarm_fg : tb.fast_fg;
  s.est.friction_torque_factor =
      ff > 0 && fg >= 0 ? 1 + (s.est.friction_factor - 1) * reference / (reference + fg / ff) : s.est.friction_factor;
  s.est.friction_reference = reference;
  s.est.sensor_drift_Nm = (grown ? m.offset_Nm : sl.offset_Nm) - tb.offset_base_Nm;
  s.est.sensor_drift_se = sl.offset_se;
  s.est.torque_gain = gain;
  s.est.torque_gain_se = s.electrical.fast.n_se;
  s.est.balance_moving_s = b.moving_s;
}

// Adds a used window to the mechanical window fit (the thesis's view, its last
// `mechanical_windows` windows) and refits: y = n E_rotor - E_out - mesh loss = k E_friction - d dq.
void FitMechanicalWindows(const MonitorConfig& c, const EfficiencyWindow& w, double window_dq, double kt_factor,
                          WindowState* state) {
  WindowState& s = *state;
  MechanicalWindow m;
  m.rotor_J = w.rotor_J;
  m.out_J = w.out_J;
  m.mesh_loss_J = w.mesh_loss_J;
  m.friction_J = w.friction_J;
  m.dq_rad = window_dq;
  m.sigma_J = c.window_noise_floor_J +
              c.window_noise_fraction * (std::fabs(w.out_J) + w.mesh_loss_J + std::fabs(w.friction_J));
  s.mech.push_back(m);
  while (static_cast<int>(s.mech.size()) > c.mechanical_windows) s.mech.pop_front();
  double a11 = c.window_friction_prior, a12 = 0, a22 = c.window_drift_prior;
  double b1 = c.window_friction_prior, b2 = 0;
  for (const MechanicalWindow& mw : s.mech) {
    const double wgt = 1.0 / (mw.sigma_J * mw.sigma_J);
    const double yw = kt_factor * mw.rotor_J - mw.out_J - mw.mesh_loss_J;
    const double x1 = mw.friction_J, x2 = -mw.dq_rad;
    a11 += wgt * x1 * x1;
    a12 += wgt * x1 * x2;
    a22 += wgt * x2 * x2;
    b1 += wgt * x1 * yw;
    b2 += wgt * x2 * yw;
  }
  double kf, d, inv11, inv22;
  if (Solve2(a11, a12, a22, b1, b2, &kf, &d, &inv11, &inv22)) s.friction_factor = kf;
}

// Windows bounded by zero velocity: extends the joint's window by the tick that ends at t_s
// (opening one at t_prev_s when the joint starts to move, `dir` its direction, 0 at rest) and
// closes it when the direction changes; a closed window goes into the mechanical fit when it is
// used. Returns whether it closed the window at this tick (Observe then emits it).
// `v`: the velocity estimate [rad/s]; `kt_factor`: the electrical fit's.
bool UpdateWindow(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x, double coupling_torque, double v,
                  int dir, int joint, double t_prev_s, double t_s, double dt, double kt_factor, WindowState* state) {
  WindowState& s = *state;
  bool close = false;
  if (s.in_window || dir != 0) {
    if (!s.in_window) {
      s.in_window = true;
      s.window = EfficiencyWindow();
      s.window.joint = joint;
      s.window.t_start_s = t_prev_s;
      s.window.direction = dir;
      s.window_dq = 0;
    }
    EfficiencyWindow& w = s.window;
    w.out_J += (x.tau_mean + coupling_torque) * x.dq;
    w.rotor_J += x.rotor_torque * x.dq;
    w.friction_J += k.mechanical.FrictionNm(v) * x.dq;
    w.mesh_loss_J += k.mechanical.mesh_loss_fraction * std::fabs(x.tau_mean + coupling_torque) * std::fabs(x.dq);
    w.supply_J += x.p_supply * dt;
    w.electrical_loss_J += (x.p_copper + x.p_fixed) * dt;
    w.t_end_s = t_s;
    s.window_dq += x.dq;
    close = dir != w.direction;
  }
  if (close) {
    s.in_window = false;
    EfficiencyWindow& w = s.window;
    FinishWindow(&w);
    w.used = w.t_end_s - w.t_start_s >= c.min_window_s && std::fabs(w.out_J) >= c.min_window_energy_J &&
             std::fabs(w.mesh_in_J) >= c.min_window_energy_J && w.flow != "mixed";
    if (w.used) FitMechanicalWindows(c, w, s.window_dq, kt_factor, &s);
  }
  return close;
}

// The K_T statistic's significance: that of its deviation, and in a joint's first
// warm_magnet_hypothesis_s of K_T judged, no more than the data's rejection of a warm magnet
// warm_magnet_reading_factor times as far above its commissioning as the evidence reads: its
// winding's reading (judge_r), or, before the winding has ever been read, the warmth its gear
// and the arm's gears show, whichever is less (GearShownRho; the arm's lower median, which a
// fault on one joint does not move: a K_T loss the fast fit's gain has not yet followed can
// make a gear's friction read low). A winding not yet read on a gear that shows no warmth
// gives no hypothesis.
double KtSignificance(const MonitorConfig& c, double deviation, double se, const JointState& s, bool judge_r,
                      const ArmAllowance& arm) {
  const double z = Significance(deviation, se);
  if (!(z > 0) || s.electrical.kt_judged_s >= c.warm_magnet_hypothesis_s) return z;
  const WindingThermometer& winding = s.electrical.winding;
  double rise = 0.0;
  if (judge_r) {
    rise = winding.rho - 1.0;  // beyond the largest rise, no temperature
  } else if (winding.judged_s == 0.0 && !std::isnan(s.friction.gear_shown_rho)) {
    rise = std::min(s.friction.gear_shown_rho, arm.gear_rho) - 1.0;
  }
  if (!(rise > 0.0 && rise <= s.electrical.fit.max_resistance_rise)) return z;
  return std::min(z, std::sqrt(s.electrical.fit.WarmMagnetRejection(1.0 + c.warm_magnet_reading_factor * rise)));
}

// The parametric detectors: deviation statistics from the estimates, held over the debounce
// time (the decision's readings); the magnitude fit starts where the friction or drift statistic
// first crosses its limit; `arm`: the arm's readings (the warmth its gears show). Returns
// whether the friction is far beyond wear: a brake dragging.
bool UpdateReadings(const MonitorConfig& c, const JointKnowledge& k, const DetectorThresholds& thresholds, double dt,
                    const ArmAllowance& arm, JointState* state) {
  JointState& s = *state;
  const PowerEfficiencyMonitor::Estimates& e = s.est;
  const ElectricalEstimator& el = s.electrical;
  TorqueBalance& tb = s.balance;
  Decision& dec = s.decision;
  const bool judge_n = el.excitation_rotor_J >= c.min_rotor_energy_J;
  if (judge_n) s.electrical.kt_judged_s += dt;
  const bool judge_r = el.excitation_copper_J >= c.min_copper_energy_J;
  const BalanceFit::Estimate& bal = FastFriction(k, tb);
  const BalanceFit::Estimate& slow = tb.slow.estimate();
  const bool judge_b = bal.moving_s >= c.min_balance_moving_s;
  const double gear_rho = GearShownRho(c, k.commissioned, bal);
  if (!std::isnan(gear_rho)) s.friction.gear_shown_rho = gear_rho;
  // An offset is told from friction only by motion both ways. A model's torque has no offset to drift.
  const bool judge_d = k.torque_sensor && std::min(slow.positive_s, slow.negative_s) >= c.min_offset_moving_each_way_s;
  // The K_T a warm magnet could lose, read from the winding's resistance (its reading: 1 until
  // the copper loss has been enough to judge it). A rise beyond max_winding_rise_K is no
  // temperature (a K_T loss lifts the joint fit's resistance for seconds; a resistance fault):
  // no allowance.
  const double winding_rise = el.winding.rho - 1;
  const double thermal_kt_allowance = winding_rise <= el.fit.max_resistance_rise
                                          ? el.fit.magnet_per_resistance * std::max(0.0, winding_rise)
                                          : 0.0;
  const double reference = s.reference;
  // The friction statistic's standard error: the fit's, and the reference's own uncertainty.
  const double friction_se =
      std::hypot(bal.friction_factor_se, bal.friction_factor * s.reference_log_sd) / reference;
  const std::array<double, kDetectorCount> deviation = {
      judge_n ? 1 - e.kt_factor - thermal_kt_allowance : kNoStatistic, judge_r ? e.resistance_factor - 1 : kNoStatistic,
      judge_b ? bal.friction_factor / reference - 1 : kNoStatistic,
      judge_d ? std::fabs(slow.offset_Nm - tb.offset_base_Nm) : kNoStatistic};
  const std::array<double, kDetectorCount> significance = {
      judge_n ? KtSignificance(c, deviation[0], e.kt_factor_se, s, judge_r, arm) : kNoStatistic,
      judge_r ? Significance(deviation[1], e.resistance_factor_se) : kNoStatistic,
      judge_b ? Significance(deviation[2], friction_se) : kNoStatistic,
      judge_d ? Significance(deviation[3], slow.offset_se) : kNoStatistic};
  if (!tb.crossed && ((judge_b && deviation[2] > thresholds[2]) || (judge_d && deviation[3] > thresholds[3]))) {
    tb.crossed = true;
    tb.since_alarm.Reset();
  }
  if (c.decision == kSequentialDecision) {
    // The whitened innovations (sequential_test.h): each deviation against the healthy bias
    // its filter follows; the drift signed, both ways.
    const std::array<double, kDetectorCount> se = {e.kt_factor_se, e.resistance_factor_se, friction_se, slow.offset_se};
    const std::array<double, kDetectorCount> signed_deviation = {deviation[0], deviation[1], deviation[2],
                                                                 slow.offset_Nm - tb.offset_base_Nm};
    const auto whiten = [](double nu, double sd) { return Significance(nu, sd); };
    const auto whiten_kt = [&](double nu, double sd) { return KtSignificance(c, nu, sd, s, judge_r, arm); };
    for (int d = 0; d < kDetectorCount; ++d) {
      double statistic = kNoStatistic;
      if (deviation[d] != kNoStatistic) {
        statistic = d == static_cast<int>(Detector::kKtFactor)
                        ? dec.sequential[d].Tick(dt, signed_deviation[d], se[d], whiten_kt)
                        : dec.sequential[d].Tick(dt, signed_deviation[d], se[d], whiten);
      }
      dec.readings[d].held_quanta = Quantize(statistic);
      dec.readings[d].held_significance_quanta = statistic == kNoStatistic ? kNoStatistic : 0.0;
      dec.readings[d].family = Detectors()[d].family;
    }
  } else {
    for (int d = 0; d < kDetectorCount; ++d) {
      dec.readings[d].held_quanta = dec.held[d].Push(Quantize(deviation[d]));
      dec.readings[d].held_significance_quanta =
          dec.held_significance[d].Push(Quantize(significance[d], kSignificanceQuantum));
      dec.readings[d].family = Detectors()[d].family;
    }
  }
  // A dragging brake: the whole friction beyond what wear makes of it.
  const bool drag = e.friction_torque_factor > c.brake_drag_friction_factor;
  if (drag) dec.readings[static_cast<int>(Detector::kFrictionFactor)].family = "brake_lock";
  return drag;
}

// The joint's verdict before debounce: a latched tick-level alarm, else the first alarming
// detector (healthy when none alarms). `drag`: the friction is a dragging brake.
Candidate ShownCandidate(const MonitorConfig& c, const JointKnowledge& k, const DetectorThresholds& decision_thresholds,
                         double significance, bool drag, const JointState& s) {
  Candidate shown;
  if (s.decision.structural.structural) {
    shown = s.decision.structural;
    return shown;
  }
  const PowerEfficiencyMonitor::Estimates& e = s.est;
  auto confidence = [](double margin, double se) { return se > 0 ? NormalCdf(margin / se) : 1.0; };
  for (int d = 0; d < kDetectorCount && shown.state == HealthState::kHealthy; ++d) {
    const DetectorReading& r = s.decision.readings[d];
    if (!Alarms(r.held_quanta, r.held_significance_quanta, decision_thresholds[d], significance)) continue;
    switch (static_cast<Detector>(d)) {
      case Detector::kKtFactor:
        shown = {e.kt_factor < c.kt_factor.defective ? HealthState::kDefective : HealthState::kWorn, "kt_degradation",
                 "kt_factor", e.kt_factor, confidence(c.kt_factor.worn - e.kt_factor, e.kt_factor_se), false};
        break;
      case Detector::kResistanceFactor:
        shown = {e.resistance_factor > c.resistance_factor.defective ? HealthState::kDefective : HealthState::kWorn,
                 "winding_resistance", "resistance_factor", e.resistance_factor,
                 confidence(e.resistance_factor - c.resistance_factor.worn, e.resistance_factor_se), false};
        break;
      case Detector::kFrictionFactor:
        if (drag) {
          // Its torque ~ the extra Coulomb part.
          shown = {HealthState::kDefective, "brake_lock", "drag_fraction",
                   (e.friction_factor - 1) * (k.friction.coulomb_Nm + k.friction.static_Nm) / k.brake_holding_Nm, 1.0,
                   false};
        } else {
          shown = {e.friction_factor > c.friction_factor.defective ? HealthState::kDefective : HealthState::kWorn,
                   "friction_increase", "friction_factor", e.friction_torque_factor,
                   confidence(e.friction_factor - c.friction_factor.worn, e.friction_factor_se), false};
        }
        break;
      case Detector::kSensorDrift:
        shown = {std::fabs(e.sensor_drift_Nm) > c.sensor_drift_Nm.defective ? HealthState::kDefective : HealthState::kWorn,
                 "torque_sensor_drift", "drift_Nm", e.sensor_drift_Nm,
                 confidence(std::fabs(e.sensor_drift_Nm) - c.sensor_drift_Nm.worn, e.sensor_drift_se), false};
        break;
    }
  }
  return shown;
}

// Emits `shown` as the joint's verdict at t_s on a change of family or state, and now and then
// to refine a standing magnitude.
void EmitVerdict(const Candidate& shown, double t_s, int joint, Decision* state, std::vector<Verdict>* verdicts) {
  Decision& s = *state;
  const bool changed = shown.family != s.shown_family || shown.state != s.shown_state;
  const bool refine = !changed && !shown.structural && shown.state != HealthState::kHealthy &&
                      t_s - s.last_emit_t >= 0.5 &&
                      std::fabs(shown.magnitude - s.last_emit_magnitude) >
                          0.01 * std::max(1.0, std::fabs(s.last_emit_magnitude));
  if (!changed && !refine) return;
  Verdict out;
  out.t_s = t_s;
  out.joint = joint;
  out.state = shown.state;
  out.alarm = shown.state != HealthState::kHealthy;
  out.family = shown.family;
  out.magnitude_name = shown.magnitude_name;
  out.magnitude = shown.magnitude;
  out.confidence = shown.confidence;
  verdicts->push_back(out);
  s.shown_family = shown.family;
  s.shown_state = shown.state;
  s.last_emit_t = t_s;
  s.last_emit_magnitude = shown.magnitude;
}

}  // namespace

void PowerEfficiencyMonitor::Observe(double t_s, const std::vector<JointSignals>& raw) {
  const MonitorConfig& c = model_.config;
  const int n = static_cast<int>(model_.joints.size());
  if (static_cast<int>(raw.size()) != n) return;
  // Joints without a torque sensor read the model's torque (virtual_torque_sensor.h).
  const bool virtual_sensor = model_.virtual_sensor.any();
  if (virtual_sensor) {
    filled_ = raw;
    model_.virtual_sensor.Fill(ticks_ > 0 ? previous_ : raw, ticks_ > 0 ? t_s - t_prev_ : 0.0, &filled_);
  }
  const std::vector<JointSignals>& signals = virtual_sensor ? filled_ : raw;
  if (ticks_++ == 0) {
    previous_ = signals;
    t_prev_ = t_s;
    t_first_ = t_s;
    return;
  }
  const double dt = t_s - t_prev_;
  if (!(dt > 0)) return;

  // 1. Every joint's tick terms and filtered balance terms, before any joint's fits move.
  for (int j = 0; j < n; ++j) {
    JointState& s = *joints_[j];
    s.tick = TermsOf(c, model_.joints[j], signals[j], previous_[j], dt);
    s.balance.filter.Push(s.tick.rotor_torque, s.tick.dq / dt, s.tick.tau_mean);
  }
  // 2. The arm's readings, once per tick, from every joint's state after the last tick.
  const ArmAllowance arm = FrictionAllowanceOfArm(c, arm_joints_);
  const bool arm_model = c.friction_reference == kArmFrictionModel;
  if (arm_model) {
    for (int j = 0; j < n; ++j) winding_above_K_[j] = joints_[j]->tick.winding_above_K;
    friction_model_.Update(c, arm_joints_, winding_above_K_, t_prev_ - t_first_, dt);
  }
  // 3. Each joint's estimators and detectors. A joint reads the others only through 1 and 2,
  // so the order of this loop changes nothing (test PowerMonitorOrder).
  for (int i = 0; i < n; ++i) {
    const int j = reverse_joint_order_ ? n - 1 - i : i;
    const JointKnowledge& k = model_.joints[j];
    JointState& s = *joints_[j];
    const JointSignals& now = signals[j];
    const JointSignals& prev = previous_[j];
    const TickTerms& x = s.tick;
    if (arm_model) {
      s.reference = friction_model_.joint[j].reference;
      s.reference_log_sd = friction_model_.joint[j].log_sd;
    }

    // --- tick-rate torque balance (core/monitors/torque_balance.h) ---
    // Coupling (eq 4-14, 4-15): the rotor turns with the parallel lower joints, so their
    // acceleration I_m γ c_l q̈_l is rotor torque the sensor never sees.
    const FilteredTerms& terms = s.balance.filter.terms();
    double coupling_torque = 0;
    for (int l = 0; l < j; ++l) {
      if (k.coupling[l] != 0) {
        coupling_torque += k.coupling[l] * k.mechanical.rotor_coupling_kg_m2 * joints_[l]->balance.filter.terms().accel_rad_s2;
      }
    }
    UpdateFits(c, k, x, terms, coupling_torque, dt, arm, &s);

    // --- windows bounded by zero velocity ---
    const double v = now.qd_est_rad_s;
    const int dir = std::fabs(v) < c.rest_velocity_rad_s ? 0 : (v > 0 ? 1 : -1);
    s.window_closed = UpdateWindow(c, k, x, coupling_torque, v, dir, j + 1, t_prev_, t_s, dt, s.est.kt_factor, &s.windows);
    s.est.window_friction_factor = s.windows.friction_factor;
    s.est.windows_in_fit = static_cast<int>(s.windows.mech.size());

    // --- tick-level detectors, latched once one fires ---
    const Candidate structural = s.detectors.Update(c, k, x, now, prev, dir, dt);
    if (!s.decision.structural.structural && structural.structural) s.decision.structural = structural;

    // --- parametric detectors: deviation statistics, held over the debounce time ---
    const bool drag = UpdateReadings(c, k, model_.thresholds, dt, arm, &s);
    s.shown = ShownCandidate(c, k, model_.decision_thresholds, model_.decision_significance, drag, s);
  }
  // 4. The outputs, in joint order: closed windows, then the joints' verdicts.
  for (int j = 0; j < n; ++j) {
    JointState& s = *joints_[j];
    if (s.window_closed && keep_windows_) output_.windows.push_back(s.windows.window);
    EmitVerdict(s.shown, t_s, j + 1, &s.decision, &output_.verdicts);
  }
  previous_ = signals;
  t_prev_ = t_s;
}

void PowerEfficiencyMonitor::Finish(double t_end_s) {
  // An open window at the end of the run ends at the run's end, not at zero velocity:
  // its inertia term does not cancel, so it is recorded but not judged.
  for (auto& sp : joints_) {
    WindowState& s = sp->windows;
    if (!s.in_window) continue;
    s.in_window = false;
    s.window.t_end_s = t_end_s;
    FinishWindow(&s.window);
    s.window.used = false;
    if (keep_windows_) output_.windows.push_back(s.window);
  }
}

namespace {

// Records the detectors' held statistics after every tick (detector_statistics.h).
class PowerEfficiencyTap : public DecisionTap {
 public:
  PowerEfficiencyTap(const PowerEfficiencyMonitor& monitor, const PowerMonitorModel& model, double onset_s)
      : monitor_(monitor), model_(model), recorder_(monitor.joint_count(), onset_s) {
    recorder_.SetSequentialTests(model.sequential_tests);
  }
  void AfterObserve(double t_s) override {
    for (int j = 0; j < monitor_.joint_count(); ++j) {
      recorder_.Record(t_s, j, monitor_.readings(j), monitor_.structural_family(j));
    }
    if (observer_) ShowTick(t_s);
  }
  // Per detector (Detectors() order) two statistics, its held deviation "<parameter>_deviation"
  // (alarms while > the detector's threshold) and its held significance
  // "<parameter>_significance" (standard errors, and >= the monitor's significance): the
  // detector alarms while both pass (detector_statistics.h, Alarms). The tick-level detectors
  // (stuck sensor, brake, driver, ...) latch on events and publish no statistic.
  void ShowStatistics(StatisticsObserver* observer) override {
    observer_ = observer;
    if (!observer_) return;
    std::vector<PublishedStatistic> published;
    for (const DetectorInfo& d : Detectors()) {
      published.push_back({std::string(d.parameter) + "_deviation", d.family,
                           model_.decision_thresholds[static_cast<size_t>(d.detector)], false});
      published.push_back({std::string(d.parameter) + "_significance", d.family, model_.decision_significance, true});
    }
    values_.assign(published.size() * static_cast<size_t>(monitor_.joint_count()), 0.0);
    observer_->Declare(published, monitor_.joint_count());
  }
  nlohmann::json Statistics() const override { return ToJson(recorder_.stats()); }
  std::string Explain(const RunScore& score, const std::string& family, int joint) const override {
    DecisionOutcome d;
    d.alarm_before_onset = score.alarm_before_onset;
    d.detected = score.detected;
    d.detection_time_s = score.detection_time_s;
    d.joint = score.joint;
    d.family = score.family;
    return ExplainOutcome(recorder_.stats(), model_.decision_thresholds, model_.decision_significance, d, family, joint,
                          model_.config);
  }
  const DecisionStats& stats() const { return recorder_.stats(); }

 private:
  void ShowTick(double t_s) {
    const size_t per_joint = 2 * kDetectorCount;
    for (int j = 0; j < monitor_.joint_count(); ++j) {
      const DetectorReadings& r = monitor_.readings(j);
      for (size_t d = 0; d < r.size(); ++d) {
        double* v = values_.data() + static_cast<size_t>(j) * per_joint + 2 * d;
        v[0] = r[d].held_quanta == kNoStatistic ? std::nan("") : r[d].held_quanta * kStatisticQuantum;
        v[1] = r[d].held_significance_quanta == kNoStatistic ? std::nan("")
                                                             : r[d].held_significance_quanta * kSignificanceQuantum;
      }
    }
    observer_->Values(t_s, values_.data());
  }

  const PowerEfficiencyMonitor& monitor_;
  const PowerMonitorModel& model_;
  DecisionRecorder recorder_;
  StatisticsObserver* observer_ = nullptr;
  std::vector<double> values_;  // [joint][detector][deviation, significance]
};

}  // namespace

std::unique_ptr<DecisionTap> PowerEfficiencyMonitor::NewDecisionTap(double onset_s) const {
  return std::make_unique<PowerEfficiencyTap>(*this, model_, onset_s);
}

}  // namespace armfault
