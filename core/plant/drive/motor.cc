#include "core/plant/drive/motor.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace armfault {

namespace {

constexpr double kSixth = M_PI / 3.0;
constexpr double kTwelfth = M_PI / 6.0;

double WrapAngle(double theta) {
  double w = std::fmod(theta, 2.0 * M_PI);
  return w < 0 ? w + 2.0 * M_PI : w;
}

// Conducting pair for positive torque in each 60-degree sector starting at 30 deg:
// the phase on its +1 plateau is high, the one on its -1 plateau is low.
constexpr int kHigh[6] = {0, 0, 1, 1, 2, 2};
constexpr int kLow[6] = {1, 2, 2, 0, 0, 1};

// Shape and sector from an angle already wrapped to [0, 2 pi): the hot path avoids fmod.
double ShapeWrapped(double t) {
  if (t < kTwelfth) return t / kTwelfth;
  if (t <= 5 * kTwelfth) return 1.0;
  if (t < 7 * kTwelfth) return 1.0 - (t - 5 * kTwelfth) / kTwelfth;
  if (t <= 11 * kTwelfth) return -1.0;
  return -1.0 + (t - 11 * kTwelfth) / kTwelfth;
}

double ShiftWrapped(double t, double shift) {
  const double u = t - shift;
  return u < 0 ? u + 2.0 * M_PI : u;
}

int SectorWrapped(double t) {
  const double u = ShiftWrapped(t, kTwelfth);
  return std::min(5, static_cast<int>(u / kSixth));
}

// Exact RL response of the conducting legs over one span with the star point held:
// v_n keeps sum i = 0; legs not in `known` carry no current.
std::array<double, 3> Advance(const std::array<double, 3>& v, const std::array<double, 3>& emf,
                              const std::array<bool, 3>& known, const std::array<double, 3>& i, double r,
                              double decay) {
  std::array<double, 3> i_new = {0, 0, 0};
  int n_known = 0;
  double sum = 0;
  for (int x = 0; x < 3; ++x) {
    if (!known[x]) continue;
    ++n_known;
    sum += v[x] - r * i[x] - emf[x];
  }
  if (n_known < 2) return i_new;
  const double vn = sum / n_known;
  for (int x = 0; x < 3; ++x) {
    if (known[x]) i_new[x] = i[x] * decay + (v[x] - vn - emf[x]) * ((1.0 - decay) / r);
  }
  return i_new;
}

}  // namespace

double BackEmfShape(double theta_e) { return ShapeWrapped(WrapAngle(theta_e)); }

DriveConstants MakeDriveConstants(const ModuleParams& m, double substep_s) {
  DriveConstants c;
  c.substep_s = substep_s;
  c.kt_Nm_per_A = m.motor.kt_Nm_per_A;
  c.resistance_ohm = m.motor.phase_resistance_ohm;
  c.inductance_H = m.motor.phase_inductance_H;
  c.pole_pairs = m.motor.pole_pairs;
  c.decay = std::exp(-c.resistance_ohm * substep_s / c.inductance_H);
  const double wc = 2.0 * M_PI * m.inverter.current_loop_bandwidth_Hz;
  c.kp_V_per_A = 2.0 * c.inductance_H * wc;
  c.ki_V_per_A_s = 2.0 * c.resistance_ohm * wc;
  c.inverter = m.inverter;
  return c;
}

namespace {

enum class LegMode { kOff, kSwitched, kDiodeHigh, kDiodeLow };

using NetworkMatrix = Eigen::Matrix<double, 10, 10>;
using NetworkVector = Eigen::Matrix<double, 10, 1>;

// What stays fixed over one StepDriveNetwork call, for its sub-steps' solves.
struct NetworkRun {
  ShortKind short_kind;
  double ud, vd, ke, r, l_over_h, g_fault, omega;
};

// Solves one sub-step's network (backward Euler) from the phase currents i at its start and the
// back-EMF shapes: an off leg whose terminal leaves the rails conducts through its diode, a
// diode that would conduct backwards opens, and the network is solved again (8 tries at most).
// Updates the legs' modes; returns the unknowns v_a..v_c, v_n, i_a..i_c, g_a..g_c.
NetworkVector SolveNetwork(const NetworkRun& f, const std::array<double, 3>& shape,
                           const std::array<double, 3>& leg_voltage, const std::array<double, 3>& i,
                           std::array<LegMode, 3>* mode) {
  using Matrix = NetworkMatrix;
  using Vector = NetworkVector;
  const ShortKind short_kind = f.short_kind;
  const double ud = f.ud, vd = f.vd, ke = f.ke, r = f.r, l_over_h = f.l_over_h, g_fault = f.g_fault, omega = f.omega;
  std::array<LegMode, 3>& m = *mode;
  Vector x;
  for (int attempt = 0; attempt < 8; ++attempt) {
    Matrix a = Matrix::Zero();
    Vector b = Vector::Zero();
    for (int p = 0; p < 3; ++p) {
      // winding p: (L/h + R) i_p - v_p + v_n = (L/h) i_p,old - e_p
      a(p, 4 + p) = l_over_h + r;
      a(p, p) = -1.0;
      a(p, 3) = 1.0;
      b(p) = l_over_h * i[p] - ke * omega * shape[p];
    }
    a(3, 4) = a(3, 5) = a(3, 6) = 1.0;  // star point: sum of winding currents is zero
    // ... but for a 1 uS leakage to mid-bus, which fixes the potential of a motor whose
    // terminals all float (the matrix would be singular otherwise) where a symmetric
    // bridge leaves it, so that no diode conducts below the bus voltage.
    a(3, 3) = 1e-6;
    b(3) = 1e-6 * 0.5 * ud;
    for (int p = 0; p < 3; ++p) {
      const int row = 4 + p;
      a(row, 7 + p) = 1.0;
      a(row, 4 + p) = -1.0;
    }
    switch (short_kind) {
      case ShortKind::kPhasePhase:
        a(4, 0) -= g_fault;
        a(4, 1) += g_fault;
        a(5, 1) -= g_fault;
        a(5, 0) += g_fault;
        break;
      case ShortKind::kPhaseGround:
        a(4, 0) -= g_fault;
        break;
      case ShortKind::kSwitch:
        a(4, 0) -= g_fault;
        b(4) -= g_fault * ud;
        break;
      case ShortKind::kNone:
        break;
    }
    for (int p = 0; p < 3; ++p) {
      const int row = 7 + p;
      switch (m[p]) {
        case LegMode::kOff:
          a(row, 7 + p) = 1.0;  // no leg current
          break;
        case LegMode::kSwitched:
          a(row, p) = 1.0;
          b(row) = leg_voltage[p];
          break;
        case LegMode::kDiodeHigh:
          a(row, p) = 1.0;
          b(row) = ud + vd;
          break;
        case LegMode::kDiodeLow:
          a(row, p) = 1.0;
          b(row) = -vd;
          break;
      }
    }
    x = a.partialPivLu().solve(b);
    // Diodes: conduct only forward; an off leg whose terminal leaves the rails conducts.
    bool consistent = true;
    for (int p = 0; p < 3; ++p) {
      const double v = x(p), g = x(7 + p);
      LegMode next = m[p];
      if (m[p] == LegMode::kOff && v > ud + vd) next = LegMode::kDiodeHigh;
      else if (m[p] == LegMode::kOff && v < -vd) next = LegMode::kDiodeLow;
      else if (m[p] == LegMode::kDiodeHigh && g > 0) next = LegMode::kOff;
      else if (m[p] == LegMode::kDiodeLow && g < 0) next = LegMode::kOff;
      if (next != m[p]) {
        m[p] = next;
        consistent = false;
      }
    }
    if (consistent) break;
  }
  return x;
}

// The drive with a short in it (HardwareCondition::short_kind): a small nodal network per
// sub-step, integrated with backward Euler. Unknowns: terminal voltages v_a..v_c, star point
// v_n, winding currents i_a..i_c (end of sub-step) and leg currents g_a..g_c (into each
// terminal from its inverter leg). The fault resistor joins a-b (phase_phase), a-ground
// (phase_ground) or the positive rail-a (a shorted high-side switch). Legs that are off
// conduct through a diode when their terminal leaves the rails. A leg current above the
// trip level opens all switches (latched), as a driver's over-current protection does.
void StepDriveNetwork(const DriveConstants& c, const HardwareCondition& cond, const DriveInputs& in, int substeps,
                      DriveState* s, DriveOutputs* out) {
  const double h = c.substep_s;
  const double ud = c.inverter.bus_voltage_V;
  const double vd = c.inverter.diode_drop_V;
  const double ke = 0.5 * c.kt_Nm_per_A * cond.kt_factor;
  const double r = c.resistance_ohm * cond.resistance_factor;
  const double l_over_h = c.inductance_H / h;
  const double g_fault = 1.0 / cond.short_resistance_ohm;
  const double sw_loss_per_A = ud * c.inverter.switching_time_s * c.inverter.pwm_frequency_Hz;
  const double omega = in.motor_speed_rad_s;
  std::array<double, 3>& i = s->phase_current_A;
  const NetworkRun network{cond.short_kind, ud, vd, ke, r, l_over_h, g_fault, omega};

  double torque_sum = 0, p_bus = 0, p_inverter = 0, p_magnetic = 0, sq_sum = 0, peak = 0;
  std::array<LegMode, 3> mode = {LegMode::kOff, LegMode::kOff, LegMode::kOff};
  for (int k = 0; k < substeps; ++k) {
    const double theta = WrapAngle(c.pole_pairs * (in.motor_angle_rad + omega * (k + 0.5) * h));
    const std::array<double, 3> shape = {ShapeWrapped(theta), ShapeWrapped(ShiftWrapped(theta, 2.0 * M_PI / 3.0)),
                                         ShapeWrapped(ShiftWrapped(theta, 4.0 * M_PI / 3.0))};
    const bool driving = in.enabled && !s->tripped;
    std::array<double, 3> leg_voltage{};
    for (int x = 0; x < 3; ++x) {
      if (mode[x] == LegMode::kSwitched) mode[x] = LegMode::kOff;
    }
    if (driving) {
      int high = kHigh[SectorWrapped(theta)], low = kLow[SectorWrapped(theta)];
      const double error = in.current_command_A - i[high];
      const double u = std::clamp(c.kp_V_per_A * error + s->pi_integral_V, -ud, ud);
      s->pi_integral_V = std::clamp(s->pi_integral_V + c.ki_V_per_A_s * error * h, -ud, ud);
      mode[high] = mode[low] = LegMode::kSwitched;
      leg_voltage[high] = 0.5 * (ud + u);
      leg_voltage[low] = 0.5 * (ud - u);
    } else {
      s->pi_integral_V = 0.0;
    }

    const NetworkVector x = SolveNetwork(network, shape, leg_voltage, i, &mode);

    const std::array<double, 3> i_new = {x(4), x(5), x(6)};
    for (int p = 0; p < 3; ++p) {
      const double g = x(7 + p);
      torque_sum += shape[p] * i_new[p];
      sq_sum += i_new[p] * i_new[p];
      p_magnetic += c.inductance_H * (i_new[p] - i[p]) * i_new[p] / h;
      switch (mode[p]) {
        case LegMode::kSwitched:
          p_bus += x(p) * g;
          p_inverter += c.inverter.switch_resistance_ohm * g * g + sw_loss_per_A * std::fabs(g);
          p_bus += c.inverter.switch_resistance_ohm * g * g + sw_loss_per_A * std::fabs(g);
          if (std::fabs(g) > c.inverter.overcurrent_trip_A) s->tripped = true;
          break;
        case LegMode::kDiodeHigh:
          p_bus += ud * g;
          p_inverter += vd * std::fabs(g);
          break;
        case LegMode::kDiodeLow:
          p_inverter += vd * std::fabs(g);
          break;
        case LegMode::kOff:
          break;
      }
      peak = std::max(peak, std::fabs(i_new[p]));
    }
    switch (cond.short_kind) {
      case ShortKind::kPhasePhase:
        p_inverter += g_fault * (x(0) - x(1)) * (x(0) - x(1));
        break;
      case ShortKind::kPhaseGround:
        p_inverter += g_fault * x(0) * x(0);
        break;
      case ShortKind::kSwitch:
        p_inverter += g_fault * (ud - x(0)) * (ud - x(0));
        p_bus += ud * g_fault * (ud - x(0));
        break;
      case ShortKind::kNone:
        break;
    }
    i = i_new;
  }
  const double inv_n = 1.0 / substeps;
  out->torque_Nm = ke * torque_sum * inv_n;
  out->p_copper_W = r * sq_sum * inv_n;
  out->current_sq_A2 = sq_sum * inv_n;
  out->p_emf_W = out->torque_Nm * omega;
  // Backward Euler: L (i' - i) i' / h is the stored-energy rate plus the method's own small
  // dissipation; booked here so that the books close exactly.
  out->p_magnetic_W = p_magnetic * inv_n;
  out->p_inverter_W = p_inverter * inv_n;
  out->p_quiescent_W = c.inverter.quiescent_power_W;
  out->p_supply_W = p_bus * inv_n + out->p_quiescent_W;
  out->supply_current_A = out->p_supply_W / ud;
  out->peak_phase_current_A = peak;
  out->phase_current_A = i;
}

}  // namespace

namespace {

// The fast path's sums over a step (see StepDrive).
struct FastSums {
  double torque = 0, rail = 0, copper = 0, switching = 0, peak = 0;
};
// What stays fixed over a run of fast sub-steps.
struct FastRun {
  const DriveConstants& c;
  double reference, ud, h, decay, gain_per_ohm, e_pair, sw_loss_per_A;
  int substeps;
  double step_e;
  int sector;
};

// The fast sub-steps from *k on while the electrical angle stays in the run's sector (and
// needs no wrapping), with the state in registers: a function of its own so that the general
// path's many values do not push these sums out to memory. Leaves *k and *theta at the last
// sub-step it ran. The same operations, in the same order, as one sub-step at a time.
[[gnu::noinline]] void RunSector(const FastRun& f, int* k_io, double* theta_io, double* ih_io, double* integral_io,
                                 FastSums* sums) {
  const DriveConstants& c = f.c;
  double ih = *ih_io, integral = *integral_io, theta = *theta_io;
  double torque = sums->torque, rail = sums->rail, copper = sums->copper, switching = sums->switching;
  double peak = sums->peak;
  int k = *k_io;
  for (;;) {
    const double error = f.reference - ih;
    const double u = std::clamp(c.kp_V_per_A * error + integral, -f.ud, f.ud);
    integral = std::clamp(integral + c.ki_V_per_A_s * error * f.h, -f.ud, f.ud);
    const double ih_new = ih * f.decay + 0.5 * (u - f.e_pair) * f.gain_per_ohm;
    const double i_mid = 0.5 * (ih + ih_new);
    const double i_sq = (ih * ih + ih * ih_new + ih_new * ih_new) * (1.0 / 3.0);
    torque += 2.0 * i_mid;
    copper += 2.0 * i_sq;
    rail += u * i_mid;
    switching += 2.0 * (c.inverter.switch_resistance_ohm * i_sq + f.sw_loss_per_A * std::fabs(i_mid));
    peak = std::max(peak, std::fabs(ih_new));
    ih = ih_new;
    if (k + 1 == f.substeps) break;
    const double next = theta + f.step_e;
    if (next >= 2.0 * M_PI || next < 0 || SectorWrapped(next) != f.sector) break;
    ++k;
    theta = next;
  }
  *ih_io = ih;
  *integral_io = integral;
  *theta_io = theta;
  *k_io = k;
  sums->torque = torque;
  sums->rail = rail;
  sums->copper = copper;
  sums->switching = switching;
  sums->peak = peak;
}

// What stays fixed over one StepDrive call, for its general sub-steps.
struct GeneralRun {
  const DriveConstants& c;
  double h, ud, vd, ke, r, decay, sw_loss_per_A, omega;
};

// One general sub-step at the electrical angle theta: any legs conducting (after a commutation
// the leg just switched off freewheels through a diode until its current dies out). When
// `driving`, the pair high/low is switched with the PI output u. Advances the phase currents
// and adds to the sums (*p_diode: |current| through the diodes).
void GeneralSubstep(const GeneralRun& f, double theta, bool driving, int high, int low, double u,
                    std::array<double, 3>* current, FastSums* sums, double* p_diode) {
  const DriveConstants& c = f.c;
  const double h = f.h, ud = f.ud, vd = f.vd, ke = f.ke, r = f.r, decay = f.decay;
  const double sw_loss_per_A = f.sw_loss_per_A, omega = f.omega;
  std::array<double, 3>& i = *current;
  double& torque_sum = sums->torque;
  double& p_rail = sums->rail;
  double& p_copper = sums->copper;
  double& p_switch = sums->switching;
  double& peak = sums->peak;
  const double phase_angle[3] = {theta, ShiftWrapped(theta, 2.0 * M_PI / 3.0), ShiftWrapped(theta, 4.0 * M_PI / 3.0)};
  const std::array<double, 3> shape = {ShapeWrapped(phase_angle[0]), ShapeWrapped(phase_angle[1]),
                                       ShapeWrapped(phase_angle[2])};
  std::array<double, 3> emf;
  for (int x = 0; x < 3; ++x) emf[x] = ke * omega * shape[x];

  // Leg voltages (relative to the negative rail) and which legs conduct.
  std::array<double, 3> v{};      // terminal voltage
  std::array<double, 3> rail{};   // the rail voltage the leg current is exchanged with
  std::array<bool, 3> known{};    // terminal voltage is imposed (switch or diode conducting)
  std::array<bool, 3> switched{};
  if (driving) {
    v[high] = rail[high] = 0.5 * (ud + u);
    v[low] = rail[low] = 0.5 * (ud - u);
    known[high] = known[low] = switched[high] = switched[low] = true;
  }
  for (int x = 0; x < 3; ++x) {
    if (switched[x] || i[x] == 0.0) continue;
    // Off leg still carrying current: a freewheeling diode conducts.
    known[x] = true;
    if (i[x] > 0) {  // current into the motor comes up through the low-side diode
      v[x] = -vd;
      rail[x] = 0.0;
    } else {  // current out of the motor returns to the bus through the high-side diode
      v[x] = ud + vd;
      rail[x] = ud;
    }
  }

  // Integrate the sub-step; a freewheeling current that would reverse stops at zero (its
  // diode blocks), so the sub-step is split there and the leg opens for the rest of it.
  double remaining = h;
  while (remaining > 0) {
    const double leg_decay = remaining == h ? decay : std::exp(-r * remaining / c.inductance_H);
    std::array<double, 3> i_new = Advance(v, emf, known, i, r, leg_decay);
    int turning_off = -1;
    double fraction = 1.0;
    for (int x = 0; x < 3; ++x) {
      if (known[x] && !switched[x] && i_new[x] * i[x] < 0) {
        const double f = i[x] / (i[x] - i_new[x]);
        if (f < fraction) {
          fraction = f;
          turning_off = x;
        }
      }
    }
    double span = remaining;
    if (turning_off >= 0) {
      span = remaining * fraction;
      i_new = Advance(v, emf, known, i, r, std::exp(-r * span / c.inductance_H));
      // What is left of the current (second order in the split) goes to the driven legs.
      double residual = i_new[turning_off];
      i_new[turning_off] = 0.0;
      known[turning_off] = false;
      int n_known = 0;
      for (int x = 0; x < 3; ++x) n_known += known[x];
      for (int x = 0; x < 3; ++x) {
        if (known[x]) i_new[x] += residual / std::max(1, n_known);
      }
    }
    const double w = span / h;
    double torque_part = 0, sq_part = 0, rail_part = 0, switch_part = 0, diode_part = 0;
    for (int x = 0; x < 3; ++x) {
      const double i_mid = 0.5 * (i[x] + i_new[x]);
      const double i_sq = (i[x] * i[x] + i[x] * i_new[x] + i_new[x] * i_new[x]) * (1.0 / 3.0);
      torque_part += shape[x] * i_mid;
      sq_part += i_sq;
      rail_part += rail[x] * i_mid;
      if (switched[x]) {
        switch_part += c.inverter.switch_resistance_ohm * i_sq + sw_loss_per_A * std::fabs(i_mid);
      } else {
        diode_part += std::fabs(i_mid);
      }
      peak = std::max(peak, std::fabs(i_new[x]));
    }
    torque_sum += w * torque_part;
    p_copper += w * sq_part;
    p_rail += w * rail_part;
    p_switch += w * switch_part;
    *p_diode += w * diode_part;
    i = i_new;
    remaining -= span;
    if (turning_off < 0) break;
  }
}

}  // namespace

void StepDrive(const DriveConstants& c, const HardwareCondition& cond, const DriveInputs& in,
               int substeps, DriveState* s, DriveOutputs* out) {
  if (cond.short_kind != ShortKind::kNone) {
    StepDriveNetwork(c, cond, in, substeps, s, out);
    return;
  }
  const double h = c.substep_s;
  const double ud = c.inverter.bus_voltage_V;
  const double vd = c.inverter.diode_drop_V;
  const double ke = 0.5 * c.kt_Nm_per_A * cond.kt_factor;  // per-phase back-EMF constant
  const double r = c.resistance_ohm * cond.resistance_factor;
  const double decay = cond.resistance_factor == 1.0 ? c.decay : std::exp(-r * h / c.inductance_H);
  const double gain_per_ohm = (1.0 - decay) / r;  // exact RL step: i' = i decay + (v/R)(1 - decay)
  const double sw_loss_per_A = ud * c.inverter.switching_time_s * c.inverter.pwm_frequency_Hz;
  const double omega = in.motor_speed_rad_s;
  const bool driving = in.enabled && !s->tripped;
  // Signed current loop on the sector's fixed pair: a negative command drives a negative
  // current through the same pair, so the PI integral (which holds the back-EMF voltage)
  // stays continuous when the command changes sign.
  const double reference = driving ? in.current_command_A : 0.0;
  if (!driving) s->pi_integral_V = 0.0;

  FastSums sums;  // the fast path's running sums; the general path adds to them too
  double& torque_sum = sums.torque;
  double& p_rail = sums.rail;
  double& p_copper = sums.copper;
  double& p_switch = sums.switching;
  double& peak = sums.peak;
  double p_diode = 0;
  std::array<double, 3>& i = s->phase_current_A;
  const double stored0 = i[0] * i[0] + i[1] * i[1] + i[2] * i[2];

  // Electrical angle at the middle of each sub-step, kept wrapped to [0, 2 pi).
  const double step_e = c.pole_pairs * omega * h;
  double theta = WrapAngle(c.pole_pairs * in.motor_angle_rad + 0.5 * step_e);
  // The fast path's back-EMF across the conducting pair: within its sector the high phase is on
  // its +1 plateau and the low phase on its -1 plateau, so e_high - e_low = 2 ke omega.
  const double e_pair = ke * omega * 2.0;
  const GeneralRun general{c, h, ud, vd, ke, r, decay, sw_loss_per_A, omega};
  for (int k = 0; k < substeps; ++k, theta += step_e) {
    if (theta >= 2.0 * M_PI || theta < 0) theta = WrapAngle(theta);
    int high = -1, low = -1, off = -1;
    double u = 0;
    if (driving) {
      const int sector = SectorWrapped(theta);
      high = kHigh[sector];
      low = kLow[sector];
      off = 3 - high - low;
      if (i[off] == 0.0) {
        // Fast path, almost every sub-step: one current I through the conducting pair in series,
        // 2L dI/dt = u - 2R I - (e_high - e_low); the same equations as the general path below.
        FastRun run{c, reference, ud, h, decay, gain_per_ohm, e_pair, sw_loss_per_A, substeps, step_e, sector};
        double ih = i[high], integral = s->pi_integral_V;
        RunSector(run, &k, &theta, &ih, &integral, &sums);
        i[high] = ih;
        i[low] = -ih;
        s->pi_integral_V = integral;
        continue;
      }
      const double error = reference - i[high];
      u = std::clamp(c.kp_V_per_A * error + s->pi_integral_V, -ud, ud);
      s->pi_integral_V = std::clamp(s->pi_integral_V + c.ki_V_per_A_s * error * h, -ud, ud);
    }
    GeneralSubstep(general, theta, driving, high, low, u, &i, &sums, &p_diode);
  }

  const double inv_n = 1.0 / substeps;
  const double stored1 = i[0] * i[0] + i[1] * i[1] + i[2] * i[2];
  // Sums above are of shape x current and current squared; the constants come in here.
  // The back-EMF power is e . i = torque x omega exactly, so it is not summed separately.
  out->torque_Nm = ke * torque_sum * inv_n;
  out->p_copper_W = r * p_copper * inv_n;
  out->current_sq_A2 = p_copper * inv_n;
  out->p_emf_W = out->torque_Nm * omega;
  p_diode *= vd;
  out->p_magnetic_W = 0.5 * c.inductance_H * (stored1 - stored0) / (substeps * h);
  out->p_inverter_W = (p_switch + p_diode) * inv_n;
  out->p_quiescent_W = c.inverter.quiescent_power_W;
  // Bus side: the averaged legs exchange rail voltage x current with the bus; switch losses
  // come on top (the averaged leg voltage is ideal). Diode drops are paid by the motor side
  // (the terminal sits beyond the rail), so they are inside the rail power already.
  out->p_supply_W = (p_rail + p_switch) * inv_n + out->p_quiescent_W;
  out->peak_phase_current_A = peak;
  out->phase_current_A = i;
  out->supply_current_A = out->p_supply_W / ud;
}

}  // namespace armfault
