#include "core/monitors/friction_reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "core/monitors/monitor_config.h"

namespace armfault {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double SecondLargest(std::array<double, 64>* values, size_t n) {
  if (n == 0) return 1.0;
  std::sort(values->begin(), values->begin() + n);
  return (*values)[n >= 2 ? n - 2 : 0];
}

}  // namespace

ArmAllowance::ArmAllowance() : shown_friction(kInf) {}

FrictionReference::FrictionReference(const MonitorConfig& c, double dt_s)
    : coldest_settled_rho(kInf),
      coldest_converged_rho(kInf),
      first_top(kInf),
      follow(kInf),
      block_median(static_cast<size_t>(c.friction_envelope_blocks), 0.0),
      gear_shown_rho(kNaN) {
  block.reserve(static_cast<size_t>(c.friction_block_s / dt_s) + 2);
  recent_.reserve(static_cast<size_t>(c.shown_friction_blocks));
}

double FrictionReference::WarmFloorReading() const {
  return std::isfinite(coldest_converged_rho) ? coldest_converged_rho : coldest_settled_rho;
}

double ColdFrictionAllowance(const MonitorConfig& c, double winding_rho, double held_K) {
  const double cold_K = std::min(c.max_cold_K, (1.0 - winding_rho) / c.copper_resistance_per_K);
  return std::exp(c.max_lubricant_slope_per_K * std::max(0.0, cold_K - held_K));
}
double ColdFrictionAllowance(const MonitorConfig& c, double winding_rho) {
  return ColdFrictionAllowance(c, winding_rho, c.cold_held_by_limit_K);
}

double WarmFrictionFloor(const MonitorConfig& c, double winding_rho, double slope_per_K, double max_counted_K) {
  const double warm_K = (winding_rho - 1.0) / c.copper_resistance_per_K;
  if (!(warm_K <= c.max_warm_K)) return 1.0;
  return std::exp(-slope_per_K * std::clamp(warm_K - c.winding_reading_error_K, 0.0, max_counted_K));
}

double GearShownRho(const MonitorConfig& c, bool commissioned, const BalanceFit::Estimate& gear) {
  if (!commissioned || gear.moving_s < c.min_balance_moving_s) return kNaN;
  const double upper = gear.friction_factor + c.gear_warmth_se * gear.friction_factor_se;
  if (!(upper > 0.0 && upper < 1.0)) return 1.0;
  const double warm_K = std::min(c.max_warm_K, -std::log(upper) / c.max_lubricant_slope_per_K);
  return 1.0 + c.copper_resistance_per_K * warm_K;
}

// `cold_rho`: the second coldest of the joints' readings (the only one of a lone joint's; 1
// until one has been read): a settled joint's coldest settled reading, an unsettled one's
// averaged reading (a joint that settles must not lose the arm's unsettled readings: on a
// 1.4 degC cold start, 19 K under, the shoulder's allowance fell from 1.15 to 1.00 as it settled
// at 4.5 s, and it raised a friction alarm at 6.7 s with the elbow settled at 0.950 and the
// wrist averaging 0.932). The windings' readings err warm more than cold (a joint with little
// copper loss, the K_T-resistance coupling of the fit), so the coldest are the best; the second,
// so that one joint's odd reading (a K_T loss can lower its resistance fit) widens nothing.
// `unsettled`: the second largest allowance over every joint whose copper loss has been read at
// all, an unsettled one's from its reading less winding_unsettled_se standard errors.
// `warm_rho`: the lower median over the settled joints of each one's WarmFloorReading, once
// every joint whose copper loss has been read has settled, two at least (1 until then): the
// readings err towards the fit's prior (1) where the copper loss is small, and far from it now
// and then: neither may set the arm's.
// `cold_friction`: the lower median over the joints of each one's latest block median (two at
// least, 1 until then): the friction most of the arm shows, which wear on one joint does not move.
ArmAllowance FrictionAllowanceOfArm(const MonitorConfig& c, const std::vector<ArmJoint>& joints) {
  std::array<double, 64> cold_rho, read, latest, coldest, shown, gear;
  size_t n_cold_rho = 0, n_read = 0, n_latest = 0, n_coldest = 0, n_shown = 0, n_gear = 0;
  bool all_settled = true;
  for (const ArmJoint& joint : joints) {
    const FrictionReference& f = *joint.friction;
    const ElectricalEstimator& e = *joint.electrical;
    if (!std::isnan(f.gear_shown_rho) && n_gear < gear.size()) gear[n_gear++] = f.gear_shown_rho;
    if (f.blocks >= c.unconverged_friction_blocks + c.min_shown_friction_blocks && n_shown < shown.size()) {
      shown[n_shown++] = f.shown;
    }
    if (f.cap_settled && n_coldest < coldest.size()) coldest[n_coldest++] = f.WarmFloorReading();
    if (!f.cap_settled && e.winding.judged_s > 0) all_settled = false;
    if (f.cap_settled) {
      if (n_cold_rho < cold_rho.size()) cold_rho[n_cold_rho++] = f.coldest_settled_rho;
      if (n_read < read.size()) read[n_read++] = f.cap;
    } else if (e.winding.judged_s > 0) {
      if (n_cold_rho < cold_rho.size()) cold_rho[n_cold_rho++] = e.winding.reading;
      if (n_read < read.size()) {
        read[n_read++] = ColdFrictionAllowance(c, e.fit.rho - c.winding_unsettled_se * e.fit.rho_se);
      }
    }
    if (f.blocks >= 1 && n_latest < latest.size()) {
      latest[n_latest++] = f.block_median[static_cast<size_t>((f.blocks - 1) % c.friction_envelope_blocks)];
    }
  }
  ArmAllowance arm;
  if (n_cold_rho > 0) {
    std::sort(cold_rho.begin(), cold_rho.begin() + n_cold_rho);
    arm.cold_rho = cold_rho[n_cold_rho >= 2 ? 1 : 0];
  }
  if (n_latest >= 2) {
    std::sort(latest.begin(), latest.begin() + n_latest);
    arm.cold_friction = latest[(n_latest - 1) / 2];
  }
  arm.unsettled = SecondLargest(&read, n_read);
  if (all_settled && n_coldest >= std::min<size_t>(2, joints.size())) {
    std::sort(coldest.begin(), coldest.begin() + n_coldest);
    arm.warm_rho = coldest[(n_coldest - 1) / 2];
  }
  if (n_shown >= 2) {
    std::sort(shown.begin(), shown.begin() + n_shown);
    arm.shown_friction = shown[n_shown / 2];
  }
  if (n_gear >= 2) {
    std::sort(gear.begin(), gear.begin() + n_gear);
    arm.gear_rho = gear[(n_gear - 1) / 2];
  }
  return arm;
}

void FrictionReference::Update(const MonitorConfig& c, double winding_above_K, const ElectricalEstimator& electrical,
                               const BalanceFit::Estimate& b, bool usable, double viscous_share, double dt_s,
                               const ArmAllowance& arm) {
  const WindingThermometer& winding = electrical.winding;
  // The coldest the winding has read (its averaged reading) once the reading settled (a gear
  // warms more slowly than its winding; with a declared winding sensor, the sensor: the fit's
  // resistance factor then stays near 1), and until it settles, the fit's reading less
  // winding_unsettled_se standard errors (its first moments can sit at its prior, 1, on a unit
  // 15 K cold). A cold morning is cold for the whole arm: the arm's reading counts for every
  // joint, a joint with little copper loss included.
  double allowance;
  if (std::isfinite(winding_above_K)) {
    const double sensed_rho = 1.0 + c.copper_resistance_per_K * winding_above_K;
    cap = std::max(cap, ColdFrictionAllowance(c, sensed_rho));
    coldest_settled_rho = std::min(coldest_settled_rho, sensed_rho);
    coldest_converged_rho = coldest_settled_rho;
    cap_settled = true;
    allowance = cap;
  } else if (winding.judged_s >= c.winding_settle_s) {
    cap = std::max(cap, ColdFrictionAllowance(c, winding.reading));
    coldest_settled_rho = std::min(coldest_settled_rho, winding.reading);
    if (winding.judged_s >= c.winding_reading_converged_s) {
      coldest_converged_rho = std::min(coldest_converged_rho, winding.reading);
    }
    cap_settled = true;
    allowance = cap;
  } else {
    allowance = std::max(arm.unsettled,
                         ColdFrictionAllowance(c, electrical.fit.rho - c.winding_unsettled_se * electrical.fit.rho_se));
  }
  allowance = std::max(allowance, ColdFrictionAllowance(c, arm.cold_rho));
  // C, the cold the arm's gears show: what most of the arm shows, up to the steepest slope.
  allowance = std::max(allowance, std::min(ColdFrictionAllowance(c, arm.cold_rho, c.winding_reading_error_K), arm.cold_friction));
  // Only ticks the fit takes: at rest it forgets towards its prior (1).
  if (usable && b.moving_s >= c.min_balance_moving_s) {
    block.push_back(b.friction_factor);
    block_s += dt_s;
    block_share_sum += viscous_share;
    block_zero_found = block_zero_found && zero_found;
    if (block_s >= c.friction_block_s) {
      // A block's median: at each reversal the fast fit has few usable ticks and sits at its
      // prior (1) for a moment, which must not count as the friction shown.
      const auto mid = block.begin() + block.size() / 2;
      std::nth_element(block.begin(), mid, block.end());
      const int ring = c.friction_envelope_blocks;
      block_median[static_cast<size_t>(blocks % ring)] = *mid;
      last_block_median = *mid;
      last_block_share = block_share_sum / static_cast<double>(block.size());
      last_block_log_se = b.friction_factor > 0 ? b.friction_factor_se / b.friction_factor : 1.0;
      last_block_teaches = block_zero_found;
      ++blocks;
      const int n_shown = std::min(c.shown_friction_blocks, blocks - c.unconverged_friction_blocks);
      if (n_shown > 0) {
        recent_.clear();
        for (int i = 0; i < n_shown; ++i) recent_.push_back(block_median[static_cast<size_t>((blocks - 1 - i) % ring)]);
        std::nth_element(recent_.begin(), recent_.begin() + n_shown / 2, recent_.end());
        shown = recent_[static_cast<size_t>(n_shown / 2)];
        if (n_shown == c.min_shown_friction_blocks) first_top = *std::max_element(recent_.begin(), recent_.end());
      }
      block_s = 0;
      block_share_sum = 0;
      block_zero_found = true;
      block.clear();
      if (blocks >= ring) {
        const double top = *std::max_element(block_median.begin(), block_median.end());
        if (!std::isfinite(follow)) {
          follow = std::max(c.min_friction_reference, top);
        } else if (top < follow) {
          // once per block: the first-order follower over the block's length
          follow = std::max(c.min_friction_reference,
                            follow + (top - follow) * c.friction_block_s / c.friction_reference_time_constant_s);
        }
      }
    }
  }
  // The warm floor W: of the joint's own reading (its gear is warmed by its own motor) or the
  // arm's, whichever is colder; a joint with too little copper loss to read takes the arm's; no
  // lower than the arm's gears show (P). Below 1 it takes the allowance's place: the windings
  // read warm, the gears thin.
  double warm = std::max(WarmFrictionFloor(c, std::min(WarmFloorReading(), arm.warm_rho), c.min_lubricant_slope_per_K,
                                           c.max_warm_counted_K),
                         arm.shown_friction);
  // E, the floor the gear's own first friction supports: a warm arm's gears may thin more than
  // the gentlest slope's max_warm_counted_K allow. Down to the arm's reading at the steepest
  // slope, no lower than what the arm's gears show (P) or than what this joint first showed: a
  // gear whose friction did not fall shows it from its first blocks on. That first friction
  // counts only below the lowest W (a first friction above it is as likely wear present from
  // the start).
  if (warm < 1.0) {
    const double lowest_warm_floor = std::exp(-c.min_lubricant_slope_per_K * c.max_warm_counted_K);
    warm = std::min(warm, std::max({WarmFrictionFloor(c, arm.warm_rho, c.max_lubricant_slope_per_K, c.max_warm_K),
                                    arm.shown_friction, std::min(first_top, lowest_warm_floor)}));
  }
  reference = std::min(warm < 1.0 ? warm : allowance, follow);
}

}  // namespace armfault
