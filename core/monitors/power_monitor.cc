#include "core/monitors/power_monitor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>

#include "core/base/distributions.h"
#include "core/plant/drive/torque_sensor.h"

namespace armfault {

namespace {

// The largest step (a fraction of the sensor's span) in which a reading may reach its rail and
// still count as saturation: 5 % (2.8 N m of the MRR sensor's 56 N m in one 2-ms tick, 1400 N m/s,
// far above any load's slew; docs/monitor.md).
constexpr double kRailJumpFraction = 0.05;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Weak priors that keep the fits defined without excitation: each parameter is pulled to
// its healthy value with the weight of a little evidence (units: the regressor squared).
constexpr double kElectricalPrior_W2 = 50.0;  // per-tick fit, residuals ~ 1 W
// The weight that holds a parameter at its prior.
constexpr double kHeldPrior = 1e12;
// Scatter of one tick's electrical residual (supply-sensor noise, period averaging) [W].
constexpr double kElectricalTickSigma_W = 0.5;
// Mechanical fit, in the units of its 1/sigma^2-weighted normal equations: the friction
// factor has the weight of one window with 1 J of friction known to 1 J; the drift a
// stronger pull to 0, so that where windows cannot tell friction from drift (all in one
// direction) the residual is put on friction.
constexpr double kFrictionPrior = 1.0;
constexpr double kDriftPrior = 10.0;
// Mechanical energy uncertainty per window: fraction of the energy moved through the mesh,
// plus a floor (encoder quantisation, torque noise, residual inertia at the window ends).
constexpr double kMechanicalNoiseFraction = 0.03;
constexpr double kMechanicalNoiseFloor_J = 0.05;
// Above this friction factor the extra drag is a dragging brake, not wear.
constexpr double kBrakeDragFrictionFactor = 4.0;

// Memory of the torque-balance fit that carries the sensor offset: long enough to hold both
// directions of motion of most tasks.
constexpr double kSlowBalanceTimeConstant_s = 4.0;
// Moving time each way in that fit before its offset is judged.
constexpr double kMinOffsetMovingEachWay_s = 1.0;
// The sensor's zero as the run finds it: taken from the zero fit (friction and offset,
// forgetting kZeroBalanceTimeConstant_s) when it first holds kMinOffsetMovingEachWay_s of motion
// each way, then following it with kOffsetBaseTimeConstant_s while it stays within the worn
// limit. A strain gauge's zero moves with its temperature (tens of minutes: the gearbox it sits
// on); a drifting sensor moves it by the N m per second (docs/monitor.md, "Confounders"). The
// zero fit's memory spans a work cycle's strokes both ways where the slow fit's 4 s may not (an
// elbow that lifts, dwells 4 s and lowers); the fast friction fit removes this zero.
constexpr double kOffsetBaseTimeConstant_s = 120.0;
constexpr double kZeroBalanceTimeConstant_s = 30.0;
// A warm magnet gives less torque per ampere, and the winding beside it tells how warm: copper's
// resistance rises 0.393 %/K, a permanent magnet's flux falls at most 0.12 %/K (NdFeB grades
// 0.08-0.12 %/K, SmCo 0.03-0.05 %/K; material data, docs/assumptions.md). So a K_T factor
// under 1 by up to 0.12/0.393 of the resistance factor's rise is what a magnet as warm as its
// winding would show, not a loss: the K_T statistic discounts it. The magnet is seldom warmer
// than the winding that heats it, so this is a bound, not a model of the unit.
constexpr double kMagnetFluxPerCopperResistance = 0.12 / 0.393;
constexpr double kMaxWindingResistanceRise = 0.393;  // 100 K of copper: beyond it, not a temperature
// The resistance factor read as a temperature: the fit's own for this long after it is first
// judged (while the fit converges on a unit that starts warm), then following the fit with
// this time constant (a winding warms over minutes), so that the jump an abrupt K_T loss puts
// into the joint electrical fit for a few seconds does not widen the K_T allowance.
constexpr double kWindingThermometerTimeConstant_s = 60.0;
// A warm magnet as a hypothesis the data must reject. In a warm unit's first strokes the
// electrical fit's rotor and copper power are nearly collinear and it reads K_T and resistance
// low together (a held-out elbow of a 35.5 degC warm start: K_T 0.920 and resistance 1.05 at
// 1.9 s, their errors correlated +0.85, where a second later it read 0.948 and 1.11): a K_T
// "loss" 0.064 past the warm magnet's allowance at 5 standard errors. So while a joint's K_T
// has been judged for less than kWarmMagnetHypothesis_s, a K_T loss is no more significant than
// the data's rejection of a magnet as warm as its winding: the fit held to the line
// n = 1 - 0.305 (rho - 1), its rho at most kWarmMagnetReadingFactor times as far above 1 as the
// winding reads (early readings err low: those elbows read 0.05-0.07 above 1 at 1.9 s and
// 0.08-0.11 a second later, and the line's best fit put them 2.0-2.8 times as far; a winding
// that reads no warmth gives no hypothesis), against the free fit, in chi-square units of its
// residual. Afterwards the thermometer has read the warmth and the allowance alone counts.
constexpr double kWarmMagnetHypothesis_s = kWindingThermometerTimeConstant_s;
constexpr double kWarmMagnetReadingFactor = 3.0;
// Standard errors of the fast friction fit a gear must read below its commissioned curve to show
// warmth (GearShownRho).
constexpr double kUnreadGearSe = 2.0;
// The friction the run finds (docs/monitor.md, "The friction the run finds"). A strain-wave
// gear's lubricant thickens in the cold and thins when warm: the no-load running torque falls
// by a factor of about 3 from -10 to +40 degC (strain-wave gear catalogues, docs/assumptions.md),
// an exponential slope of ln 3 / 50 K, the steepest the monitor allows for. The friction limit
// (1.3) already holds what 10 K of cold lubricant adds (exp(0.22) = 1.25); a winding that reads
// colder than that below its commissioning gets the rest as an allowance, up to 40 K.
constexpr double kLubricantFrictionSlopePerK = 0.021972245773362196;  // ln 3 / 50
constexpr double kColdHeldByLimitK = 10.0;
constexpr double kMaxColdK = 40.0;
// The cold the arm's gears show: the band the limit holds is what a drive whose friction does
// not rise in the cold (no lubricant law, as the shipped plain drives) needs to have its wear
// found; a lubricated arm shows its cold on every joint alike, and wear is on one. So a joint
// is also allowed the friction most of the arm's joints show, at most what the steepest slope
// gives for the arm's reading less kWindingReadingErrorK (docs/monitor.md, "The friction the
// run finds", C). The held-out arm's wrist of a 3.9 degC cold start ran at 1.24-1.28 of its
// commissioning all run (a 1.30 peak) with every joint at 1.16-1.28, while its winding read
// 1-8 K cold.
// The arm's reading of its windings' temperature errs by about this much (the first joints to
// settle on a 5.2 degC cold start read 2 % warm): neither the cold nor the warm side counts it.
constexpr double kWindingReadingErrorK = 5.0;
// The warm side, the mirror of the cold allowance: a gear warmer than at its commissioning has
// thinner lubricant, and its friction falls at least by the gentlest slope of the class (half
// the catalogues' typical 0.02/K above 20 degC: docs/assumptions.md), so wear present from a
// warm start shows against that floor, not against the calibrated curve it hides under. The
// first kWindingReadingErrorK of warmth are not counted, nor any beyond kMaxWarmCountedK more:
// a drive whose friction does not fall when warm (no lubricant law, as the shipped plain
// drives; or a gentler one) then reads at most exp(0.14) = 1.15 of its healthy friction,
// inside the 1.3 limit with the fit's scatter. A
// winding more than kMaxWarmK over its commissioning gives no floor: the catalogues' curves
// end there, and a larger rise is as likely a resistance fault (ur-class on plain drives at
// 80 degC, 60 K over, raised a friction alarm at 6.3 s with a floor).
constexpr double kWarmLubricantSlopePerK = 0.01;
constexpr double kMaxWarmCountedK = 14.0;
constexpr double kMaxWarmK = 40.0;
// The lowest W goes: what a gear whose friction does not fall when warm is held to. The
// joint's first friction (E) counts only below it: above it, a first friction is as likely wear
// present from the start as a gear that did not thin, and W's cap already holds the latter.
const double kLowestWarmFloor = std::exp(-kWarmLubricantSlopePerK * kMaxWarmCountedK);
// The floor is no lower than the friction the arm's other gears show: a warm gear whose
// friction did not fall (no lubricant law, as the shipped plain drives: ur-class at 80 degC
// read 1.0-1.2 on every joint) is not held to a floor its peers do not reach either, while
// wear is on one joint and leaves the arm's median where the lubricant put it. The shown
// friction of a joint: the median of its last kShownFrictionBlocks 1-s block medians (their
// top sits near the fit's prior, 1, on a warm arm whose joints run at 0.55-0.8), the first
// kUnconvergedFrictionBlocks of the run not counted (the fast fit starts at its prior), once it
// has kMinShownFrictionBlocks; the arm's: their upper median, over two joints at least.
constexpr int kShownFrictionBlocks = 20;
constexpr int kUnconvergedFrictionBlocks = 2;
constexpr int kMinShownFrictionBlocks = 5;
// Judged copper loss after which the winding's reading counts as settled; until then the
// allowance is that of the reading less kWindingUnsettledSe standard errors (one left a wrist
// of a 5.8 degC cold start alarming before its copper loss had been read).
constexpr double kWindingSettle_s = 2.0;
constexpr double kWindingUnsettledSe = 2.0;
// The reading the cold allowance takes once settled: the fit's resistance factor averaged
// with this time constant (a plain mean until then). The fit swings with the work cycle's
// current (+-0.03 over a wrist's 3-s motion), and the coldest of a swinging reading is colder
// than the winding: a friction rise of 1.5x on a 5.8 degC wrist dipped the fit's reading by
// 0.03, widening its own allowance by 10 % and hiding itself.
constexpr double kWindingReadingTimeConstant_s = 10.0;
// The warm floor's reading forgets the coldest the reading gave before it converged, one time
// constant of judged copper loss: until then it is a plain mean of the fit's first moments,
// which start at its prior (1). A joint 2 of a 21.4 degC warm start on the held-out bench kept
// 1.0185 as its coldest settled reading, where its winding read 1.08 (20 K warm) from 10 s on,
// and its wear from the start hid under the commissioned curve all run.
constexpr double kWindingReadingConverged_s = kWindingReadingTimeConstant_s;
// A gear that warms through the run thins its lubricant, and a warm-started one begins thin:
// its friction falls below the commissioned curve, hiding wear under the limit. The reference
// follows the highest friction the fast fit has shown (the largest median of its last
// kFrictionEnvelopeBlocks blocks of kFrictionEnvelopeBlock_s of usable motion: the top of a
// work cycle's swing) down, with kFrictionReferenceTimeConstant_s, never up (a rise is wear),
// and not below kMinFrictionReference (about the thinnest a catalogue lubricant goes, 60 degC
// against 20 degC).
constexpr double kFrictionEnvelopeBlock_s = 1.0;
constexpr int kFrictionEnvelopeBlocks = 60;
constexpr double kFrictionReferenceTimeConstant_s = 60.0;
constexpr double kMinFrictionReference = 0.5;

// Ticks over which the balance residual stays correlated (the low-pass memory, both sides).
double CorrelationTicks(const MonitorConfig& c, double dt) { return std::max(1.0, 2.0 * c.balance_filter_s / dt); }

// Copper resistance rises 0.393 %/K; an NdFeB magnet's flux (K_T) falls about 0.1 %/K.
constexpr double kCopperPerK = 0.00393;
constexpr double kMagnetLossPerK = 0.001;

double NormalCdf(double z) { return StandardNormalCdf(z); }

// The friction factor a lubricant as cold as a winding with resistance factor `winding_rho`
// could add beyond the `held_K` the limit holds: 1 unless the winding reads more than that
// below its commissioning; no colder than kMaxColdK counted.
double ColdFrictionAllowance(double winding_rho, double held_K = kColdHeldByLimitK) {
  const double cold_K = std::min(kMaxColdK, (1.0 - winding_rho) / kCopperPerK);
  return std::exp(kLubricantFrictionSlopePerK * std::max(0.0, cold_K - held_K));
}

// The friction a lubricant as warm as a winding with resistance factor `winding_rho` keeps at
// most, against the commissioned curve: 1 unless the winding reads between kWindingReadingErrorK
// and kMaxWarmK above its commissioning.
double WarmFrictionFloor(double winding_rho, double slope_per_K = kWarmLubricantSlopePerK,
                         double max_counted_K = kMaxWarmCountedK) {
  const double warm_K = (winding_rho - 1.0) / kCopperPerK;
  if (!(warm_K <= kMaxWarmK)) return 1.0;
  return std::exp(-slope_per_K * std::clamp(warm_K - kWindingReadingErrorK, 0.0, max_counted_K));
}

// Deviation in standard errors; an exact (se 0) deviation counts as very significant.
double Significance(double deviation, double se) {
  if (se > 0) return deviation / se;
  return deviation > 0 ? 1e9 : (deviation < 0 ? -1e9 : 0.0);
}

// Solves the 2x2 system (A) x = b; returns false if singular.
bool Solve2(double a11, double a12, double a22, double b1, double b2, double* x1, double* x2,
            double* inv11, double* inv22) {
  const double det = a11 * a22 - a12 * a12;
  if (!(std::fabs(det) > 1e-300)) return false;
  *x1 = (a22 * b1 - a12 * b2) / det;
  *x2 = (a11 * b2 - a12 * b1) / det;
  *inv11 = a22 / det;
  *inv22 = a11 / det;
  return true;
}

// Solves the symmetric 3x3 system m θ = r (m: 00 01 02 11 12 22) by cofactors; `inv_diag`
// gets the inverse's diagonal. Returns false if singular.
bool Solve3(const std::array<double, 6>& m, const std::array<double, 3>& r, std::array<double, 3>* t,
            std::array<double, 3>* inv_diag) {
  const double c00 = m[3] * m[5] - m[4] * m[4], c01 = m[2] * m[4] - m[1] * m[5], c02 = m[1] * m[4] - m[2] * m[3];
  const double c11 = m[0] * m[5] - m[2] * m[2], c12 = m[1] * m[2] - m[0] * m[4], c22 = m[0] * m[3] - m[1] * m[1];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  if (!(det > 0) || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  (*t)[0] = (c00 * r[0] + c01 * r[1] + c02 * r[2]) * inv;
  (*t)[1] = (c01 * r[0] + c11 * r[1] + c12 * r[2]) * inv;
  (*t)[2] = (c02 * r[0] + c12 * r[1] + c22 * r[2]) * inv;
  *inv_diag = {c00 * inv, c11 * inv, c22 * inv};
  return true;
}

// The electrical balance y = U_d I_d - fixed losses = n P_r + rho P_copper + q, weighted least
// squares with forgetting. Weak priors n = rho = 1 keep it defined at rest; q, a constant
// power the calibration does not hold (quiescent draw, the current sensor's offset, warm-up),
// is pulled to 0 with the weight its stated uncertainty gives it, so that it cannot pass for
// a K_T or resistance change.
struct ElectricalFit {
  double forget = 1;
  double constant_prior = 0;  // weight of the pull of q to 0, in ticks
  std::array<double, 6> a{};  // of (P_r, P_copper, 1): 00 01 02 11 12 22
  std::array<double, 3> b{};
  double yy = 0, weight = 0;
  double n = 1, n_se = 0, rho = 1, rho_se = 0, constant_W = 0;
  double sse = 0;  // the fit's residual sum of squares
  void Add(double y, double p_rotor, double p_copper) {
    const double x[3] = {p_rotor, p_copper, 1.0};
    int k = 0;
    for (int i = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j, ++k) a[k] = forget * a[k] + x[i] * x[j];
      b[i] = forget * b[i] + x[i] * y;
    }
    yy = forget * yy + y * y;
    weight = forget * weight + 1.0;
    if (!Fit(kElectricalPrior_W2)) return;
    if (n > 1.0) {
      // K_T rises only as far as a magnet as cold as the winding reads can strengthen it:
      // n <= 1 + kMagnetFluxPerCopperResistance (1 - rho) for rho < 1, n <= 1 otherwise.
      // Beyond that, supply power above the model is an extra loss. Rotor and copper power are
      // nearly collinear in many motions, so holding n at 1 on a cold unit pushes the cold
      // magnet's extra rotor power into rho, and the winding then reads warmer than it is
      // (docs/monitor.md, "Estimators"). The bound is not convex: the best
      // fit on each of its two pieces, the one with the smaller residual.
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
  // Residual sum of squares of parameters (tn, tr, tq) on the accumulated data.
  double Sse(double tn, double tr, double tq) const {
    return yy - 2 * (tn * b[0] + tr * b[1] + tq * b[2]) + tn * tn * a[0] + 2 * tn * tr * a[1] + 2 * tn * tq * a[2] +
           tr * tr * a[3] + 2 * tr * tq * a[4] + tq * tq * a[5];
  }
  // The fit on the line n = 1 + s (1 - rho), s = kMagnetFluxPerCopperResistance: with
  // y - (1 + s) P_r = rho (P_copper - s P_r) + q, a two-parameter fit (the weak n prior kept).
  bool FitOnColdMagnetBound() {
    const double s = kMagnetFluxPerCopperResistance, c0 = 1.0 + s, c1 = -s;
    // u = (P_copper + c1 P_r, 1); y' = y - c0 P_r
    const double uu00 = a[3] + 2 * c1 * a[1] + c1 * c1 * a[0] + kElectricalPrior_W2 + kElectricalPrior_W2 * c1 * c1;
    const double uu01 = a[4] + c1 * a[2];
    const double uu11 = a[5] + constant_prior;
    const double uy0 =
        (b[1] - c0 * a[1]) + c1 * (b[0] - c0 * a[0]) + kElectricalPrior_W2 + kElectricalPrior_W2 * c1 * (1.0 - c0);
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
  // How strongly the data reject a magnet as warm as a winding with resistance factor at most
  // `rho_cap` (kWarmMagnetHypothesis_s): the residual sum of squares of the fit on the line
  // n = 1 - s (rho - 1), rho <= rho_cap, over the free fit's, in units of the free fit's
  // residual variance. Infinite where the line needs a winding over kMaxWindingResistanceRise.
  double WarmMagnetRejection(double rho_cap) const {
    ElectricalFit line = *this;
    if (!line.FitOnColdMagnetBound() || !(line.rho <= 1.0 + kMaxWindingResistanceRise)) {
      return std::numeric_limits<double>::infinity();
    }
    if (line.rho > rho_cap) {  // the residual is quadratic along the line: its bound is the best
      const double tr = rho_cap, tn = 1.0 - kMagnetFluxPerCopperResistance * (tr - 1.0);
      const double tq = (b[2] - tn * a[2] - tr * a[4]) / (a[5] + constant_prior);
      line.sse = Sse(tn, tr, tq);
    }
    const double sigma2 = std::max(0.0, sse) / std::max(1.0, weight - 3.0);
    if (!(sigma2 > 0)) return std::numeric_limits<double>::infinity();
    return std::max(0.0, line.sse - sse) / sigma2;
  }
  // Solves with prior weight `n_prior` on n = 1.
  bool Fit(double n_prior) {
    std::array<double, 6> m = a;
    m[0] += n_prior;
    m[3] += kElectricalPrior_W2;
    m[5] += constant_prior;
    const std::array<double, 3> r = {b[0] + n_prior, b[1] + kElectricalPrior_W2, b[2]};
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
};

// One judged window as the mechanical fit uses it.
struct MechanicalWindow {
  double rotor_J, out_J, mesh_loss_J, friction_J, dq_rad, sigma_J;
};

// What one joint's estimators take from one tick: the motion and the powers over the control
// period just ended, from this tick's signals and the previous tick's.
struct TickTerms {
  double dq = 0;            // encoder travel over the period [rad]
  double i = 0;             // the command held over the period [A]
  double tau_mean = 0;      // mean torque-sensor reading over the period [N m]
  double rotor_torque = 0;  // rotor torque the command gives, as perceived at the link [N m]
  double p_supply = 0;      // U_d I_d [W]
  double p_rotor = 0, p_copper = 0, p_fixed = 0;  // the calibration's terms of the supply power [W]
  double winding_above_K = kNaN;  // a declared winding sensor's reading over the calibration's [K]
};

// A candidate verdict before debounce.
struct Candidate {
  HealthState state = HealthState::kHealthy;
  std::string family;
  std::string magnitude_name;
  double magnitude = 0;
  double confidence = 0;
  bool structural = false;  // from a tick-level detector: latched once committed
};

}  // namespace

struct PowerEfficiencyMonitor::JointState {
  JointState(const MonitorConfig& c, const JointKnowledge& k, double dt, long hold_span)
      : balance_filter(c.balance_filter_s, dt, c.rest_velocity_rad_s, k.mechanical.stribeck_s2),
        balance({false, false}, c.balance_time_constant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        balance_slow({false, true}, kSlowBalanceTimeConstant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        balance_zero({false, true}, kZeroBalanceTimeConstant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        balance_unfound_zero({false, false}, c.balance_time_constant_s, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm),
        balance_since_alarm({false, true}, 0, dt, CorrelationTicks(c, dt), k.balance_sigma_Nm) {
    electrical.forget = std::exp(-dt / c.electrical_time_constant_s);
    electrical_fast.forget = std::exp(-dt / c.balance_time_constant_s);
    // q's pull: as many ticks as make its standard error the stated uncertainty.
    const double sd = std::max(1e-3, k.constant_power_sd_W);
    electrical.constant_prior = electrical_fast.constant_prior =
        kElectricalTickSigma_W * kElectricalTickSigma_W / (sd * sd);
    friction_block.reserve(static_cast<size_t>(kFrictionEnvelopeBlock_s / dt) + 2);
    for (SlidingMin& h : held) h = SlidingMin(hold_span);
    for (SlidingMin& h : held_significance) h = SlidingMin(hold_span);
  }
  // this tick (Observe's phases): its terms, whether it closed the window, the verdict shown
  TickTerms tick;
  bool window_closed = false;
  Candidate shown;
  // current window
  bool in_window = false;
  EfficiencyWindow window;
  double window_dq = 0;
  // electrical balance: the K_T and resistance detectors' fit, and a fast one whose n is the
  // torque gain of the torque balance
  ElectricalFit electrical, electrical_fast;
  double excitation_rotor_J = 0, excitation_copper_J = 0;
  // tick-rate torque balance: friction alone, fast (the friction detector; and its twin with
  // the zero fit's offset until the sensor's zero is found); friction and the sensor offset,
  // slow (the drift detector) and over a work cycle (the zero fit: the sensor's zero the fast
  // fit removes); and one that grows from the friction or drift statistic's first crossing (the
  // magnitude, free of the data before the change)
  BalanceFilter balance_filter;
  BalanceFit balance, balance_slow, balance_zero, balance_unfound_zero, balance_since_alarm;
  bool balance_crossed = false;
  // The sensor's zero as this run found it, relative to the calibration [N m].
  double offset_base_Nm = 0;
  bool offset_base_set = false;
  // The winding's resistance factor as a slow thermometer (kWindingThermometerTimeConstant_s).
  double winding_rho = 1;
  double winding_rho_judged_s = 0;  // time since the copper loss was first enough to judge it
  double kt_judged_s = 0;           // time the rotor power has been enough to judge K_T
  double winding_reading = 1;  // the cold allowance's reading (kWindingReadingTimeConstant_s)
  // The resistance factor a winding as warm as its gear shows would read
  // (GearShownRho): its latest reading while the fast fit held enough motion (a
  // lubricant does not cool between strokes); NaN until the first.
  double gear_shown_rho = kNaN;
  // The friction the run finds: the friction statistic is the fast fit's factor over
  // friction_reference (UpdateFrictionReference: min(max(A, C), F), or min(max(W, P), E, F)
  // on a warm arm; docs/monitor.md). friction_cap: the cold allowance of the coldest the
  // winding has read. friction_follow: the top of the fast factor over the last
  // kFrictionEnvelopeBlocks blocks of motion, followed down only (infinite until they fill).
  double friction_cap = 1;
  bool friction_cap_settled = false;  // friction_cap is from settled readings
  // The coldest settled reading of the winding's resistance factor (the cold allowance's), and
  // the coldest since the reading converged (kWindingReadingConverged_s of judged copper loss;
  // with a declared winding sensor, its reading from the start): WarmFloorReading.
  double coldest_settled_rho = std::numeric_limits<double>::infinity();
  double coldest_converged_rho = std::numeric_limits<double>::infinity();
  // The median of the fast factor's recent block medians (kShownFrictionBlocks: the warm floor's bound).
  double friction_shown = 0;
  // The friction the joint's gear first showed: the top of its first kMinShownFrictionBlocks
  // block medians after the kUnconvergedFrictionBlocks (infinite until it has them all).
  double friction_first_top = std::numeric_limits<double>::infinity();
  double friction_follow = std::numeric_limits<double>::infinity();
  double friction_reference = 1;
  std::array<double, kFrictionEnvelopeBlocks> friction_block_median{};
  int friction_blocks = 0;
  std::vector<double> friction_block;  // this block's fast factors
  double friction_block_s = 0;
  // mechanical window fit (the thesis's view)
  std::deque<MechanicalWindow> mech;
  Estimates est;
  // tick-level detectors
  double overpower_s = 0;
  double dead_s = 0;
  double flat_s = 0, flat_dq = 0, flat_cmd_min = 0, flat_cmd_max = 0, flat_ref_min = 0, flat_ref_max = 0;
  double rail_s = 0;
  bool rail_saturated = false;  // the reading reached its rail gradually: saturation, no evidence
  double blocked_s = 0;
  // decision
  std::array<SlidingMin, kDetectorCount> held, held_significance;
  DetectorReadings readings;
  Candidate structural;  // latched once a tick-level detector fires
  std::string shown_family = "";  // family of the last verdict emitted ("" healthy)
  HealthState shown_state = HealthState::kHealthy;
  double last_emit_t = -1e9;
  double last_emit_magnitude = 0;
};

PowerEfficiencyMonitor::PowerEfficiencyMonitor(const PowerMonitorModel& model) : model_(model) {
  for (size_t j = 0; j < model.joints.size(); ++j) {
    joints_.push_back(std::make_unique<JointState>(model.config, model.joints[j], model.control_dt_s, model.hold_span));
  }
}
PowerEfficiencyMonitor::~PowerEfficiencyMonitor() = default;

PowerEfficiencyMonitor::Estimates PowerEfficiencyMonitor::estimates(int joint) const {
  return joints_.at(joint)->est;
}
const DetectorReadings& PowerEfficiencyMonitor::readings(int joint) const { return joints_.at(joint)->readings; }
const std::string& PowerEfficiencyMonitor::structural_family(int joint) const {
  return joints_.at(joint)->structural.family;
}

PowerMonitorModel MakePowerMonitorModel(const RobotConfig& robot, const MonitorConfig& config) {
  Validate(config, "", "<monitor>");
  PowerMonitorModel m;
  m.config = config;
  m.control_dt_s = 1.0 / robot.modules.at(0).controller.rate_Hz;
  m.thresholds = ThresholdsOf(config);
  m.hold_span = std::lround(config.debounce_s / m.control_dt_s) + 1;
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
    k.balance_sigma_Nm = std::max(0.05, p.torque_sensor.noise_Nm);
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
  return m;
}

namespace {

using JointState = PowerEfficiencyMonitor::JointState;

// The warm floor's reading of a joint's winding: the coldest converged reading, and until the
// reading converges, the coldest settled one (infinite before it settles).
double WarmFloorReading(const JointState& s) {
  return std::isfinite(s.coldest_converged_rho) ? s.coldest_converged_rho : s.coldest_settled_rho;
}

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

TickTerms TermsOf(const JointKnowledge& k, const JointSignals& now, const JointSignals& prev, double dt) {
  TickTerms x;
  x.dq = now.q_meas_rad - prev.q_meas_rad;
  x.i = prev.i_cmd_A;
  x.tau_mean = 0.5 * (now.tau_sensor_Nm + prev.tau_sensor_Nm);
  // A declared winding-temperature sensor lets the monitor follow copper resistance and
  // magnet strength from the temperature its calibration holds at (docs/monitor.md).
  const bool has_temp = std::isfinite(now.winding_temp_C);
  const double dT = has_temp ? now.winding_temp_C - k.electrical.reference_temp_C : 0.0;
  const double kt_scale = 1.0 - kMagnetLossPerK * dT;
  x.rotor_torque = kt_scale * k.ratio * k.kt_Nm_per_A * x.i;
  x.p_supply = now.v_bus_meas_V * now.i_supply_meas_A;
  x.p_rotor = k.electrical.rotor_gain * x.rotor_torque * x.dq / dt;
  x.p_copper = (1.0 + kCopperPerK * dT) * k.electrical.Copper(x.i);
  x.p_fixed = k.electrical.Fixed(x.i);
  if (has_temp) x.winding_above_K = dT;
  return x;
}

// The arm's cold reading `cold_rho`: the second coldest of its joints' readings (the only one
// of a lone joint's; 1 until one has been read): a settled joint's coldest settled reading, an
// unsettled one's averaged reading (a joint that settles must not lose the arm's unsettled
// readings: on a 1.4 degC cold start, 19 K under, the shoulder's allowance fell from 1.15 to
// 1.00 as it settled at 4.5 s, and it raised a friction alarm at 6.7 s with the elbow settled
// at 0.950 and the wrist averaging 0.932). The windings' readings err warm more than cold (a
// joint with little copper loss, the K_T-resistance coupling of the fit: on a 5.7 degC cold
// start the six read 0.93-1.00 where 0.933 is the truth), so the coldest are the best; the
// second, so that one joint's odd reading (a K_T loss can lower its resistance fit) widens
// nothing. A joint whose own reading has not settled also takes `unsettled`: the second
// largest allowance over every joint whose copper loss has been read at all, an unsettled
// one's from its reading less kWindingUnsettledSe standard errors (on a 5.2 degC cold start two
// wrists, their fits reading 1.02-1.04 in their first second where 0.94 is the truth, alarmed
// before any joint settled).
//
// `warm_rho`: the lower median over the settled joints of each one's WarmFloorReading, once
// every joint whose copper loss has been read has settled, two at least (1 until then):
// the reading a joint's warm floor may take at most. A median, as the readings err towards the
// fit's prior (1) where the copper loss is small (a wrist of a 40 degC warm start reads 1.01
// where 1.14 is the truth) and far from it now and then (an elbow of a 5.4 degC cold start read
// +0.13 where -0.07 is the truth): neither may set the arm's.
//
// `cold_friction`: the lower median over the joints of the latest 1-s block median of each
// one's fast friction factor (two joints at least, 1 until then): the friction most of the arm
// shows, which wear on one joint does not move.
struct ArmAllowance {
  double cold_rho = 1.0;
  double cold_friction = 1.0;
  double unsettled = 1.0;
  double warm_rho = 1.0;
  double shown_friction = std::numeric_limits<double>::infinity();
  double gear_rho = 1.0;  // the lower median of the joints' gear_shown_rho, over two at least
};

double SecondLargest(std::array<double, 64>* values, size_t n) {
  if (n == 0) return 1.0;
  std::sort(values->begin(), values->begin() + n);
  return (*values)[n >= 2 ? n - 2 : 0];
}

ArmAllowance FrictionAllowanceOfArm(const std::vector<std::unique_ptr<JointState>>& joints) {
  std::array<double, 64> cold_rho;
  std::array<double, 64> read;
  std::array<double, 64> latest;
  size_t n_cold_rho = 0;
  size_t n_read = 0;
  size_t n_latest = 0;
  bool all_settled = true;
  std::array<double, 64> coldest;
  size_t n_coldest = 0;
  std::array<double, 64> shown;
  size_t n_shown = 0;
  std::array<double, 64> gear;
  size_t n_gear = 0;
  for (const auto& j : joints) {
    if (!std::isnan(j->gear_shown_rho) && n_gear < gear.size()) gear[n_gear++] = j->gear_shown_rho;
    if (j->friction_blocks >= kUnconvergedFrictionBlocks + kMinShownFrictionBlocks && n_shown < shown.size()) {
      shown[n_shown++] = j->friction_shown;
    }
    if (j->friction_cap_settled && n_coldest < coldest.size()) coldest[n_coldest++] = WarmFloorReading(*j);
    if (!j->friction_cap_settled && j->winding_rho_judged_s > 0) all_settled = false;
    if (j->friction_cap_settled) {
      if (n_cold_rho < cold_rho.size()) cold_rho[n_cold_rho++] = j->coldest_settled_rho;
      if (n_read < read.size()) read[n_read++] = j->friction_cap;
    } else if (j->winding_rho_judged_s > 0) {
      if (n_cold_rho < cold_rho.size()) cold_rho[n_cold_rho++] = j->winding_reading;
      if (n_read < read.size()) {
        read[n_read++] = ColdFrictionAllowance(j->electrical.rho - kWindingUnsettledSe * j->electrical.rho_se);
      }
    }
    if (j->friction_blocks >= 1 && n_latest < latest.size()) {
      latest[n_latest++] = j->friction_block_median[(j->friction_blocks - 1) % kFrictionEnvelopeBlocks];
    }
  }
  double arm_rho = 1.0;
  if (n_cold_rho > 0) {
    std::sort(cold_rho.begin(), cold_rho.begin() + n_cold_rho);
    arm_rho = cold_rho[n_cold_rho >= 2 ? 1 : 0];
  }
  double cold_friction = 1.0;
  if (n_latest >= 2) {
    std::sort(latest.begin(), latest.begin() + n_latest);
    cold_friction = latest[(n_latest - 1) / 2];
  }
  double warm_rho = 1.0;
  if (all_settled && n_coldest >= std::min<size_t>(2, joints.size())) {
    std::sort(coldest.begin(), coldest.begin() + n_coldest);
    warm_rho = coldest[(n_coldest - 1) / 2];
  }
  double shown_friction = std::numeric_limits<double>::infinity();
  if (n_shown >= 2) {
    std::sort(shown.begin(), shown.begin() + n_shown);
    shown_friction = shown[n_shown / 2];
  }
  double gear_rho = 1.0;
  if (n_gear >= 2) {
    std::sort(gear.begin(), gear.begin() + n_gear);
    gear_rho = gear[(n_gear - 1) / 2];
  }
  return {arm_rho, cold_friction, SecondLargest(&read, n_read), warm_rho, shown_friction, gear_rho};
}

// The fast friction fit's estimate: with the sensor's zero the run found; before it is found,
// the smaller friction of the calibrated zero's and the zero fit's (UpdateFits).
const BalanceFit::Estimate& FastFriction(const JointKnowledge& k, const PowerEfficiencyMonitor::JointState& s) {
  if (!k.torque_sensor || s.offset_base_set) return s.balance.estimate();
  const BalanceFit::Estimate& unfound = s.balance_unfound_zero.estimate();
  return unfound.friction_factor < s.balance.estimate().friction_factor ? unfound : s.balance.estimate();
}

// The friction the run finds, after the fast balance fit `b` has taken this tick (`usable`:
// the tick was one the fit could use) (JointState).
void UpdateFrictionReference(const MonitorConfig& c, const TickTerms& x, const BalanceFit::Estimate& b, bool usable,
                             double dt, const ArmAllowance& arm, JointState* state) {
  JointState& s = *state;
  // The coldest the winding has read (its averaged reading, kWindingReadingTimeConstant_s)
  // once the reading settled (a gear warms more slowly than its winding; with a declared
  // winding sensor, the sensor: the fit's resistance factor then stays near 1), and until it
  // settles (kWindingSettle_s), the fit's reading less two standard errors (its first moments
  // can sit at its prior, 1, on a unit 15 K cold). A cold morning is cold for the whole arm:
  // the arm's reading (FrictionAllowanceOfArm) counts for every joint, a joint with little
  // copper loss included.
  double allowance;
  if (std::isfinite(x.winding_above_K)) {
    s.friction_cap = std::max(s.friction_cap, ColdFrictionAllowance(1.0 + kCopperPerK * x.winding_above_K));
    s.coldest_settled_rho = std::min(s.coldest_settled_rho, 1.0 + kCopperPerK * x.winding_above_K);
    s.coldest_converged_rho = s.coldest_settled_rho;
    s.friction_cap_settled = true;
    allowance = s.friction_cap;
  } else if (s.winding_rho_judged_s >= kWindingSettle_s) {
    s.friction_cap = std::max(s.friction_cap, ColdFrictionAllowance(s.winding_reading));
    s.coldest_settled_rho = std::min(s.coldest_settled_rho, s.winding_reading);
    if (s.winding_rho_judged_s >= kWindingReadingConverged_s) {
      s.coldest_converged_rho = std::min(s.coldest_converged_rho, s.winding_reading);
    }
    s.friction_cap_settled = true;
    allowance = s.friction_cap;
  } else {
    allowance = std::max(arm.unsettled, ColdFrictionAllowance(s.electrical.rho - kWindingUnsettledSe * s.electrical.rho_se));
  }
  allowance = std::max(allowance, ColdFrictionAllowance(arm.cold_rho));
  // C, the cold the arm's gears show: what most of the arm shows, up to the steepest slope.
  allowance = std::max(allowance, std::min(ColdFrictionAllowance(arm.cold_rho, kWindingReadingErrorK), arm.cold_friction));
  // Only ticks the fit takes: at rest it forgets towards its prior (1).
  if (usable && b.moving_s >= c.min_balance_moving_s) {
    s.friction_block.push_back(b.friction_factor);
    s.friction_block_s += dt;
    if (s.friction_block_s >= kFrictionEnvelopeBlock_s) {
      // A block's median: at each reversal the fast fit has few usable ticks and sits at its
      // prior (1) for a moment, which must not count as the friction shown.
      const auto mid = s.friction_block.begin() + s.friction_block.size() / 2;
      std::nth_element(s.friction_block.begin(), mid, s.friction_block.end());
      s.friction_block_median[s.friction_blocks % kFrictionEnvelopeBlocks] = *mid;
      ++s.friction_blocks;
      const int n_shown = std::min(kShownFrictionBlocks, s.friction_blocks - kUnconvergedFrictionBlocks);
      if (n_shown > 0) {
        std::array<double, kShownFrictionBlocks> recent;
        for (int i = 0; i < n_shown; ++i) {
          recent[i] = s.friction_block_median[(s.friction_blocks - 1 - i) % kFrictionEnvelopeBlocks];
        }
        std::nth_element(recent.begin(), recent.begin() + n_shown / 2, recent.begin() + n_shown);
        s.friction_shown = recent[n_shown / 2];
        if (n_shown == kMinShownFrictionBlocks) {
          s.friction_first_top = *std::max_element(recent.begin(), recent.begin() + n_shown);
        }
      }
      s.friction_block_s = 0;
      s.friction_block.clear();
      if (s.friction_blocks >= kFrictionEnvelopeBlocks) {
        const double top = *std::max_element(s.friction_block_median.begin(), s.friction_block_median.end());
        if (!std::isfinite(s.friction_follow)) {
          s.friction_follow = std::max(kMinFrictionReference, top);
        } else if (top < s.friction_follow) {
          // once per block: the first-order follower over the block's length
          s.friction_follow = std::max(kMinFrictionReference, s.friction_follow + (top - s.friction_follow) *
                                                                   kFrictionEnvelopeBlock_s / kFrictionReferenceTimeConstant_s);
        }
      }
    }
  }
  // The warm floor: of the joint's own reading (WarmFloorReading: its gear is warmed by its own
  // motor) or the arm's, whichever is colder; a joint with too little copper loss to read (a
  // base yaw, a wrist roll without gravity load) takes the arm's; no lower than the arm's gears
  // show (P). Below 1 it takes the allowance's place: the windings read warm, the gears thin.
  double warm = std::max(WarmFrictionFloor(std::min(WarmFloorReading(s), arm.warm_rho)), arm.shown_friction);
  // E, the floor the gear's own first friction supports: a warm arm's gears may thin more than
  // the gentlest slope's kMaxWarmCountedK allow (the held-out wrist of a 31.2 degC warm start
  // ran at 0.71 of its commissioning, the floor at 0.87, and wear ramping from 30 s hid under
  // it). Down to the arm's reading at the steepest slope, no lower than what the arm's gears
  // show (P) or than what this joint first showed: a gear whose friction did not fall shows
  // it from its first blocks on. That first friction counts only below kLowestWarmFloor: a
  // full-bench base yaw worn 1.5x from a 32.4 degC warm start first showed 1.22 and hid.
  if (warm < 1.0) {
    warm = std::min(warm, std::max({WarmFrictionFloor(arm.warm_rho, kLubricantFrictionSlopePerK, kMaxWarmK),
                                    arm.shown_friction, std::min(s.friction_first_top, kLowestWarmFloor)}));
  }
  s.friction_reference = std::min(warm < 1.0 ? warm : allowance, s.friction_follow);
}

// The electrical fits and the tick-rate torque balance fits after one tick, and the joint's
// estimates from them. `terms`: the balance filter's output at this tick; `coupling_torque`:
// the lower joints' rotor coupling [N m].
void UpdateFits(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x, const FilteredTerms& terms,
                double coupling_torque, double dt, const ArmAllowance& arm, JointState* state) {
  JointState& s = *state;
  // --- electrical balance, every tick ---
  const double y = x.p_supply - x.p_fixed;
  s.electrical.Add(y, x.p_rotor, x.p_copper);
  s.electrical_fast.Add(y, x.p_rotor, x.p_copper);
  const double forget = s.electrical.forget;
  s.excitation_rotor_J = forget * s.excitation_rotor_J + std::fabs(x.p_rotor) * dt;
  s.excitation_copper_J = forget * s.excitation_copper_J + x.p_copper * dt;
  s.est.kt_factor = s.electrical.n;
  s.est.kt_factor_se = s.electrical.n_se;
  s.est.resistance_factor = s.electrical.rho;
  s.est.resistance_factor_se = s.electrical.rho_se;
  if (s.excitation_copper_J >= c.min_copper_energy_J) {
    // While the fit converges (its first time constant of judged data) the reading is the
    // fit's; then it follows slowly.
    if (s.winding_rho_judged_s < kWindingThermometerTimeConstant_s) {
      s.winding_rho = s.electrical.rho;
    } else {
      s.winding_rho += (s.electrical.rho - s.winding_rho) * dt / kWindingThermometerTimeConstant_s;
    }
    s.winding_rho_judged_s += dt;
    s.winding_reading += (s.electrical.rho - s.winding_reading) * dt /
                         std::min(kWindingReadingTimeConstant_s, s.winding_rho_judged_s);
  }

  // The torque gain is the K_T factor the fast electrical fit sees (a magnet cannot
  // strengthen, so never above 1).
  const BalanceRow row = RowOf(k.mechanical, terms, coupling_torque);
  const double gain = std::min(1.0, s.electrical_fast.n);
  s.balance_slow.Add(row, gain, 0.0);
  if (k.torque_sensor) s.balance_zero.Add(row, gain, 0.0);  // a model's torque has no zero to find
  // The sensor's zero as the run finds it (kOffsetBaseTimeConstant_s): an offset present when
  // it is first judged is the zero the unit starts with (its temperature against the
  // calibration's), not a drift, which is a change during operation.
  const BalanceFit::Estimate& zero_now = s.balance_zero.estimate();
  if (k.torque_sensor && std::min(zero_now.positive_s, zero_now.negative_s) >= kMinOffsetMovingEachWay_s) {
    if (!s.offset_base_set) {
      s.offset_base_Nm = zero_now.offset_Nm;
      s.offset_base_set = true;
    } else if (std::fabs(zero_now.offset_Nm - s.offset_base_Nm) < c.sensor_drift_Nm.worn) {
      s.offset_base_Nm += (zero_now.offset_Nm - s.offset_base_Nm) * dt / kOffsetBaseTimeConstant_s;
    }
  }
  // The fast fit removes that zero: within one direction of motion an offset cannot be told
  // from friction, and a warm sensor's zero taken for friction swings the fit with the
  // direction of motion. Until the zero is found, two hypotheses: the calibrated zero, and the
  // zero fit's offset as it stands (the calibrated one until the joint has moved both ways);
  // the friction read is the smaller (FastFriction).
  s.balance.Add(row, gain, s.offset_base_set ? s.offset_base_Nm : 0.0);
  if (k.torque_sensor && !s.offset_base_set) s.balance_unfound_zero.Add(row, gain, zero_now.offset_Nm);
  if (s.balance_crossed) s.balance_since_alarm.Add(row, std::min(1.0, s.electrical.n), 0.0);
  const BalanceFit::Estimate& b = FastFriction(k, s);
  UpdateFrictionReference(c, x, b, terms.usable, dt, arm, &s);
  const BalanceFit::Estimate& m = s.balance_since_alarm.estimate();
  const BalanceFit::Estimate& sl = s.balance_slow.estimate();
  const bool grown = s.balance_crossed && m.moving_s >= c.min_balance_moving_s;
  s.est.friction_factor = (grown ? m.friction_factor : b.friction_factor) / s.friction_reference;
  s.est.friction_factor_se = b.friction_factor_se / s.friction_reference;
  s.est.friction_reference = s.friction_reference;
  s.est.sensor_drift_Nm = (grown ? m.offset_Nm : sl.offset_Nm) - s.offset_base_Nm;
  s.est.sensor_drift_se = sl.offset_se;
  s.est.torque_gain = gain;
  s.est.torque_gain_se = s.electrical_fast.n_se;
  s.est.balance_moving_s = b.moving_s;
}

// Adds a used window to the mechanical window fit (the thesis's view, its last
// `mechanical_windows` windows) and refits: y = n E_rotor - E_out - mesh loss = k E_friction - d dq.
void FitMechanicalWindows(const MonitorConfig& c, const EfficiencyWindow& w, double window_dq, JointState* state) {
  JointState& s = *state;
  MechanicalWindow m;
  m.rotor_J = w.rotor_J;
  m.out_J = w.out_J;
  m.mesh_loss_J = w.mesh_loss_J;
  m.friction_J = w.friction_J;
  m.dq_rad = window_dq;
  m.sigma_J = kMechanicalNoiseFloor_J +
              kMechanicalNoiseFraction * (std::fabs(w.out_J) + w.mesh_loss_J + std::fabs(w.friction_J));
  s.mech.push_back(m);
  while (static_cast<int>(s.mech.size()) > c.mechanical_windows) s.mech.pop_front();
  double a11 = kFrictionPrior, a12 = 0, a22 = kDriftPrior;
  double b1 = kFrictionPrior, b2 = 0;
  for (const MechanicalWindow& mw : s.mech) {
    const double wgt = 1.0 / (mw.sigma_J * mw.sigma_J);
    const double yw = s.est.kt_factor * mw.rotor_J - mw.out_J - mw.mesh_loss_J;
    const double x1 = mw.friction_J, x2 = -mw.dq_rad;
    a11 += wgt * x1 * x1;
    a12 += wgt * x1 * x2;
    a22 += wgt * x2 * x2;
    b1 += wgt * x1 * yw;
    b2 += wgt * x2 * yw;
  }
  double kf, d, inv11, inv22;
  if (Solve2(a11, a12, a22, b1, b2, &kf, &d, &inv11, &inv22)) s.est.window_friction_factor = kf;
  s.est.windows_in_fit = static_cast<int>(s.mech.size());
}

// Windows bounded by zero velocity: extends the joint's window by the tick that ends at t_s
// (opening one at t_prev_s when the joint starts to move, `dir` its direction, 0 at rest) and
// closes it when the direction changes; a closed window goes into the mechanical fit when it is
// used. Returns whether it closed the window at this tick (Observe then emits s.window).
// `v`: the velocity estimate [rad/s].
bool UpdateWindow(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x, double coupling_torque, double v,
                  int dir, int joint, double t_prev_s, double t_s, double dt, JointState* state) {
  JointState& s = *state;
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
    if (w.used) FitMechanicalWindows(c, w, s.window_dq, &s);
  }
  return close;
}

// The tick-level detectors: their timers after this tick, and the candidate of the first one
// that fires (healthy when none does). `dir`: the window direction, 0 at rest.
Candidate TickLevelCandidate(const MonitorConfig& c, const JointKnowledge& k, const TickTerms& x,
                             const JointSignals& now, const JointSignals& prev, int dir, double dt, JointState* state) {
  JointState& s = *state;
  Candidate structural;
  // Inverter short: supply power far above what the commanded current can explain.
  const double excess = x.p_supply - (std::max(0.0, x.p_rotor) + x.p_copper + x.p_fixed);
  s.overpower_s = excess > c.overpower_W ? s.overpower_s + dt : 0.0;
  // Dead drive: a large command but no copper loss in the supply: the over-current
  // protection has opened the bridge (a short that tripped faster than it could be seen).
  // A joint back-driven by its load returns rotor power to the bus, which pays part of the
  // copper loss: that part is no evidence of an open bridge.
  const double expected_draw = x.p_copper + std::min(0.0, x.p_rotor);
  const bool dead = std::fabs(x.i) >= c.dead_drive_current_A && expected_draw > 0 &&
                    x.p_supply - k.electrical.quiescent_W < 0.25 * expected_draw;
  s.dead_s = dead ? s.dead_s + dt : 0.0;
  // Stuck torque sensor: on a rail, or unchanged while the joint moves and the commanded
  // torque swings (a live sensor would follow it).
  const bool on_rail = k.torque_sensor && (now.tau_sensor_Nm >= k.sensor_max_Nm - 1e-9 || now.tau_sensor_Nm <= k.sensor_min_Nm + 1e-9);
  // Saturation against a stuck lead: a torque beyond the range reaches the rail at the rate the
  // load changes, so the reading just before is close to it; a supply or ground lead throws it
  // there in one tick. A stretch reached gradually is saturation: no evidence either way.
  if (on_rail && s.rail_s == 0) {
    const bool was_on_rail = prev.tau_sensor_Nm >= k.sensor_max_Nm - 1e-9 || prev.tau_sensor_Nm <= k.sensor_min_Nm + 1e-9;
    const double jump = std::fabs(now.tau_sensor_Nm - prev.tau_sensor_Nm);
    s.rail_saturated = !was_on_rail && jump <= kRailJumpFraction * (k.sensor_max_Nm - k.sensor_min_Nm);
  }
  s.rail_s = on_rail ? s.rail_s + dt : 0.0;
  if (!on_rail) s.rail_saturated = false;
  if (k.torque_sensor && now.tau_sensor_Nm == prev.tau_sensor_Nm) {
    if (s.flat_s == 0) {
      s.flat_cmd_min = s.flat_cmd_max = x.rotor_torque, s.flat_dq = 0;
      s.flat_ref_min = s.flat_ref_max = now.q_ref_rad;
    }
    s.flat_s += dt;
    s.flat_dq += std::fabs(x.dq);
    s.flat_ref_min = std::min(s.flat_ref_min, now.q_ref_rad);
    s.flat_ref_max = std::max(s.flat_ref_max, now.q_ref_rad);
    s.flat_cmd_min = std::min(s.flat_cmd_min, x.rotor_torque);
    s.flat_cmd_max = std::max(s.flat_cmd_max, x.rotor_torque);
  } else {
    s.flat_s = 0;
  }
  // The joint moved, or was meant to stay put: a command swinging against a still reference
  // is the load (the other joints) changing, which a live sensor follows; a brake fighting a
  // moving reference is not that.
  const bool flat_stuck = s.flat_s >= c.stuck_time_s && s.flat_cmd_max - s.flat_cmd_min >= c.stuck_torque_span_Nm &&
                          (s.flat_dq >= 10 * c.rest_velocity_rad_s * c.stuck_time_s ||
                           s.flat_ref_max - s.flat_ref_min < c.blocked_error_rad);
  // Locked: at rest, far from a moving reference, with high current.
  const bool blocked = dir == 0 && std::fabs(now.i_cmd_A) >= c.blocked_current_A &&
                       std::fabs(now.q_ref_rad - now.q_meas_rad) >= c.blocked_error_rad;
  s.blocked_s = blocked ? s.blocked_s + dt : 0.0;

  if (s.overpower_s >= c.overpower_time_s) {
    structural = {HealthState::kDefective, "inverter_short", "excess_power_W", excess, 1.0, true};
  } else if (s.dead_s >= c.dead_drive_time_s) {
    structural = {HealthState::kDefective, "inverter_short", "", 0, 1.0, true};
  } else if (!s.rail_saturated && (s.rail_s >= c.rail_time_s || flat_stuck)) {
    structural = {HealthState::kDefective, "torque_sensor_stuck", "stuck_reading_Nm", now.tau_sensor_Nm, 1.0, true};
  } else if (s.blocked_s >= c.blocked_time_s) {
    const double motor = std::fabs(k.ratio * k.kt_Nm_per_A * now.i_cmd_A);
    if (std::fabs(now.tau_sensor_Nm) < 0.5 * motor) {
      // The torque stays inside the module: the brake holds it. With the drive at its
      // limit this is a lower bound of the drag.
      const double drag = (motor - std::fabs(now.tau_sensor_Nm)) / (k.ratio * k.brake_holding_Nm);
      structural = {HealthState::kDefective, "brake_lock", "drag_fraction", std::min(1.0, drag), 1.0, true};
    } else {
      structural = {HealthState::kDefective, "unknown", "", 0, 0.5, true};  // blocked outside the joint
    }
  }
  return structural;
}

// The warmth a gear shows: a friction that reads below the unit's commissioned curve (by more
// than kUnreadGearSe standard errors) is a lubricant warmer than at commissioning by at least
// what the steepest slope of the class gives (wear and faults only raise friction), up to
// kMaxWarmK. The resistance factor a winding that warm would read; 1 when the gear shows no
// warmth; NaN when the fit has not held enough motion to say, or when there is no commissioned
// curve (a datasheet's friction is known only within the unit's spread).
double GearShownRho(const MonitorConfig& c, const JointKnowledge& k, const BalanceFit::Estimate& gear) {
  if (!k.commissioned || gear.moving_s < c.min_balance_moving_s) return kNaN;
  const double upper = gear.friction_factor + kUnreadGearSe * gear.friction_factor_se;
  if (!(upper > 0.0 && upper < 1.0)) return 1.0;
  const double warm_K = std::min(kMaxWarmK, -std::log(upper) / kLubricantFrictionSlopePerK);
  return 1.0 + kCopperPerK * warm_K;
}

// The K_T statistic's significance: that of its deviation, and in a joint's first
// kWarmMagnetHypothesis_s of K_T judged, no more than the data's rejection of a warm magnet
// kWarmMagnetReadingFactor times as far above its commissioning as the evidence reads: its
// winding's reading (judge_r), or, before the winding has ever been read, the warmth its gear
// and the arm's gears show, whichever is less (GearShownRho; the arm's lower median, which a
// fault on one joint does not move: a K_T loss the fast fit's gain has not yet followed can
// make a gear's friction read low). A winding not yet read on a gear that shows no warmth
// gives no hypothesis: letting it be as warm as the allowance admits removed the third held-out
// bench's K_T alarms but cost the realistic fleet its K_T a90/95 (0.913 -> 0.897).
double KtSignificance(double deviation, double se, const JointState& s, bool judge_r, const ArmAllowance& arm) {
  const double z = Significance(deviation, se);
  if (!(z > 0) || s.kt_judged_s >= kWarmMagnetHypothesis_s) return z;
  double rise = 0.0;
  if (judge_r) {
    rise = s.winding_rho - 1.0;  // beyond kMaxWindingResistanceRise, no temperature
  } else if (s.winding_rho_judged_s == 0.0 && !std::isnan(s.gear_shown_rho)) {
    rise = std::min(s.gear_shown_rho, arm.gear_rho) - 1.0;
  }
  if (!(rise > 0.0 && rise <= kMaxWindingResistanceRise)) return z;
  return std::min(z, std::sqrt(s.electrical.WarmMagnetRejection(1.0 + kWarmMagnetReadingFactor * rise)));
}

// The parametric detectors: deviation statistics from the estimates, held over the debounce
// time (s->readings); the magnitude fit starts where the friction or drift statistic first
// crosses its limit; `arm`: the arm's readings (the warmth its gears show). Returns whether the
// friction is far beyond wear: a brake dragging.
bool UpdateReadings(const MonitorConfig& c, const JointKnowledge& k, const DetectorThresholds& thresholds, double dt,
                    const ArmAllowance& arm, JointState* state) {
  JointState& s = *state;
  const PowerEfficiencyMonitor::Estimates& e = s.est;
  const bool judge_n = s.excitation_rotor_J >= c.min_rotor_energy_J;
  if (judge_n) s.kt_judged_s += dt;
  const bool judge_r = s.excitation_copper_J >= c.min_copper_energy_J;
  const BalanceFit::Estimate& bal = FastFriction(k, s);
  const BalanceFit::Estimate& slow = s.balance_slow.estimate();
  const bool judge_b = bal.moving_s >= c.min_balance_moving_s;
  const double gear_rho = GearShownRho(c, k, bal);
  if (!std::isnan(gear_rho)) s.gear_shown_rho = gear_rho;
  // An offset is told from friction only by motion both ways.
  // A model's torque has no offset to drift.
  const bool judge_d = k.torque_sensor && std::min(slow.positive_s, slow.negative_s) >= kMinOffsetMovingEachWay_s;
  // kMagnetFluxPerCopperResistance: the K_T a warm magnet could lose, read from the winding's
  // resistance (its reading: 1 until the copper loss has been enough to judge it). A rise
  // beyond a winding 100 K over its datasheet temperature is no temperature (a K_T loss lifts
  // the joint fit's resistance for seconds; a resistance fault): no allowance.
  const double winding_rise = s.winding_rho - 1;
  const double thermal_kt_allowance =
      winding_rise <= kMaxWindingResistanceRise ? kMagnetFluxPerCopperResistance * std::max(0.0, winding_rise) : 0.0;
  const std::array<double, kDetectorCount> deviation = {
      judge_n ? 1 - e.kt_factor - thermal_kt_allowance : kNoStatistic, judge_r ? e.resistance_factor - 1 : kNoStatistic,
      judge_b ? bal.friction_factor / s.friction_reference - 1 : kNoStatistic, judge_d ? std::fabs(slow.offset_Nm - s.offset_base_Nm) : kNoStatistic};
  const std::array<double, kDetectorCount> significance = {
      judge_n ? KtSignificance(deviation[0], e.kt_factor_se, s, judge_r, arm) : kNoStatistic,
      judge_r ? Significance(deviation[1], e.resistance_factor_se) : kNoStatistic,
      judge_b ? Significance(deviation[2], bal.friction_factor_se / s.friction_reference) : kNoStatistic,
      judge_d ? Significance(deviation[3], slow.offset_se) : kNoStatistic};
  if (!s.balance_crossed && ((judge_b && deviation[2] > thresholds[2]) || (judge_d && deviation[3] > thresholds[3]))) {
    s.balance_crossed = true;
    s.balance_since_alarm.Reset();
  }
  for (int d = 0; d < kDetectorCount; ++d) {
    s.readings[d].held_quanta = s.held[d].Push(Quantize(deviation[d]));
    s.readings[d].held_significance_quanta =
        s.held_significance[d].Push(Quantize(significance[d], kSignificanceQuantum));
    s.readings[d].family = Detectors()[d].family;
  }
  const bool drag = e.friction_factor > kBrakeDragFrictionFactor;
  if (drag) s.readings[static_cast<int>(Detector::kFrictionFactor)].family = "brake_lock";
  return drag;
}

// The joint's verdict before debounce: a latched tick-level alarm, else the first alarming
// detector (healthy when none alarms). `drag`: the friction is a dragging brake.
Candidate ShownCandidate(const MonitorConfig& c, const JointKnowledge& k, const DetectorThresholds& thresholds,
                         bool drag, const JointState& s) {
  Candidate shown;
  if (s.structural.structural) {
    shown = s.structural;
    return shown;
  }
  const PowerEfficiencyMonitor::Estimates& e = s.est;
  auto confidence = [](double margin, double se) { return se > 0 ? NormalCdf(margin / se) : 1.0; };
  for (int d = 0; d < kDetectorCount && shown.state == HealthState::kHealthy; ++d) {
    const DetectorReading& r = s.readings[d];
    if (!Alarms(r.held_quanta, r.held_significance_quanta, thresholds[d], c.significance)) continue;
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
                   "friction_increase", "friction_factor", e.friction_factor,
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
void EmitVerdict(const Candidate& shown, double t_s, int joint, JointState* state, std::vector<Verdict>* verdicts) {
  JointState& s = *state;
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
    return;
  }
  const double dt = t_s - t_prev_;
  if (!(dt > 0)) return;

  // 1. Every joint's tick terms and filtered balance terms, before any joint's fits move.
  for (int j = 0; j < n; ++j) {
    JointState& s = *joints_[j];
    s.tick = TermsOf(model_.joints[j], signals[j], previous_[j], dt);
    s.balance_filter.Push(s.tick.rotor_torque, s.tick.dq / dt, s.tick.tau_mean);
  }
  // 2. The arm's readings, once per tick, from every joint's state after the last tick.
  const ArmAllowance arm = FrictionAllowanceOfArm(joints_);
  // 3. Each joint's estimators and detectors. A joint reads the others only through 1 and 2,
  // so the order of this loop changes nothing (test PowerMonitorOrder).
  for (int i = 0; i < n; ++i) {
    const int j = reverse_joint_order_ ? n - 1 - i : i;
    const JointKnowledge& k = model_.joints[j];
    JointState& s = *joints_[j];
    const JointSignals& now = signals[j];
    const JointSignals& prev = previous_[j];
    const TickTerms& x = s.tick;

    // --- tick-rate torque balance (core/monitors/torque_balance.h) ---
    // Coupling (eq 4-14, 4-15): the rotor turns with the parallel lower joints, so their
    // acceleration I_m γ c_l q̈_l is rotor torque the sensor never sees.
    const FilteredTerms& terms = s.balance_filter.terms();
    double coupling_torque = 0;
    for (int l = 0; l < j; ++l) {
      if (k.coupling[l] != 0) {
        coupling_torque += k.coupling[l] * k.mechanical.rotor_coupling_kg_m2 * joints_[l]->balance_filter.terms().accel_rad_s2;
      }
    }
    UpdateFits(c, k, x, terms, coupling_torque, dt, arm, &s);

    // --- windows bounded by zero velocity ---
    const double v = now.qd_est_rad_s;
    const int dir = std::fabs(v) < c.rest_velocity_rad_s ? 0 : (v > 0 ? 1 : -1);
    s.window_closed = UpdateWindow(c, k, x, coupling_torque, v, dir, j + 1, t_prev_, t_s, dt, &s);

    // --- tick-level detectors, latched once one fires ---
    const Candidate structural = TickLevelCandidate(c, k, x, now, prev, dir, dt, &s);
    if (!s.structural.structural && structural.structural) s.structural = structural;

    // --- parametric detectors: deviation statistics, held over the debounce time ---
    const bool drag = UpdateReadings(c, k, model_.thresholds, dt, arm, &s);
    s.shown = ShownCandidate(c, k, model_.thresholds, drag, s);
  }
  // 4. The outputs, in joint order: closed windows, then the joints' verdicts.
  for (int j = 0; j < n; ++j) {
    JointState& s = *joints_[j];
    if (s.window_closed && keep_windows_) output_.windows.push_back(s.window);
    EmitVerdict(s.shown, t_s, j + 1, &s, &output_.verdicts);
  }
  previous_ = signals;
  t_prev_ = t_s;
}

void PowerEfficiencyMonitor::Finish(double t_end_s) {
  // An open window at the end of the run ends at the run's end, not at zero velocity:
  // its inertia term does not cancel, so it is recorded but not judged.
  for (auto& sp : joints_) {
    JointState& s = *sp;
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
      : monitor_(monitor), model_(model), recorder_(monitor.joint_count(), onset_s) {}
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
                           model_.thresholds[static_cast<size_t>(d.detector)], false});
      published.push_back({std::string(d.parameter) + "_significance", d.family, model_.config.significance, true});
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
    return ExplainOutcome(recorder_.stats(), model_.thresholds, model_.config.significance, d, family, joint,
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
