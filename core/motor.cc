#include "core/motor.h"

#include <algorithm>
#include <cmath>

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

void StepDrive(const DriveConstants& c, const HardwareCondition& cond, const DriveInputs& in,
               int substeps, DriveState* s, DriveOutputs* out) {
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
  const double command = driving ? in.current_command_A : 0.0;
  const double reference = std::fabs(command);
  if (!driving) s->pi_integral_V = 0.0;

  double torque_sum = 0, p_rail = 0, p_copper = 0, p_switch = 0, p_diode = 0;
  double peak = 0;
  std::array<double, 3>& i = s->phase_current_A;
  const double stored0 = i[0] * i[0] + i[1] * i[1] + i[2] * i[2];

  // Electrical angle at the middle of each sub-step, kept wrapped to [0, 2 pi).
  const double step_e = c.pole_pairs * omega * h;
  double theta = WrapAngle(c.pole_pairs * in.motor_angle_rad + 0.5 * step_e);
  for (int k = 0; k < substeps; ++k, theta += step_e) {
    if (theta >= 2.0 * M_PI || theta < 0) theta = WrapAngle(theta);
    int high = -1, low = -1, off = -1;
    double u = 0;
    if (driving) {
      const int sector = SectorWrapped(theta);
      high = kHigh[sector];
      low = kLow[sector];
      if (command < 0) std::swap(high, low);
      off = 3 - high - low;
      const double error = reference - i[high];
      u = std::clamp(c.kp_V_per_A * error + s->pi_integral_V, -ud, ud);
      s->pi_integral_V = std::clamp(s->pi_integral_V + c.ki_V_per_A_s * error * h, -ud, ud);
    }
    const double phase_angle[3] = {theta, ShiftWrapped(theta, 2.0 * M_PI / 3.0), ShiftWrapped(theta, 4.0 * M_PI / 3.0)};
    if (driving && i[off] == 0.0) {
      // Fast path, almost every sub-step: one current I through the conducting pair in series,
      // 2L dI/dt = u - 2R I - (e_high - e_low); the same equations as the general path below.
      const double shape_diff = ShapeWrapped(phase_angle[high]) - ShapeWrapped(phase_angle[low]);
      const double ih = i[high];
      const double ih_new = ih * decay + 0.5 * (u - ke * omega * shape_diff) * gain_per_ohm;
      const double i_mid = 0.5 * (ih + ih_new);
      const double i_sq = (ih * ih + ih * ih_new + ih_new * ih_new) * (1.0 / 3.0);
      torque_sum += shape_diff * i_mid;
      p_copper += 2.0 * i_sq;
      p_rail += u * i_mid;
      p_switch += 2.0 * (c.inverter.switch_resistance_ohm * i_sq + sw_loss_per_A * std::fabs(i_mid));
      peak = std::max(peak, std::fabs(ih_new));
      i[high] = ih_new;
      i[low] = -ih_new;
      continue;
    }
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
      p_diode += w * diode_part;
      i = i_new;
      remaining -= span;
      if (turning_off < 0) break;
    }
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
