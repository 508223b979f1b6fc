// The friction the run finds: what a joint's fast friction factor is judged against
// (docs/monitor.md, "The friction the run finds"). A strain-wave gear's lubricant thickens in
// the cold and thins when warm, so a healthy gear's friction moves with its temperature; the
// monitor reads that temperature from the windings' resistance (WindingThermometer) and from
// the friction the arm's gears show, and bounds the lubricant's slope by catalogue data.
//
// Inputs per tick and joint: the fast torque-balance fit's estimate, whether the tick was one
// the fit could use, the joint's electrical estimator, a declared winding sensor's reading
// [K over the calibration's], and the arm's readings (ArmAllowance, once per tick for the whole
// arm from every joint's state after the last tick).
// Output: FrictionReference::reference, the friction factor a healthy gear may show:
//   cold:  A = max(own cold allowance, arm's, C)      A = exp(s_max max(0, cold_K - held_K))
//   warm:  min(max(W, P), E)                          W = exp(-s_min clamp(warm_K - err_K, 0, counted_K))
//   both:  min(…, F), F the envelope of the fit's block medians, followed down only.
#pragma once

#include <vector>

#include "core/monitors/electrical_fit.h"
#include "core/monitors/torque_balance.h"

namespace armfault {

struct MonitorConfig;

// The arm's readings (FrictionAllowanceOfArm), computed once per tick.
struct ArmAllowance {
  double cold_rho = 1.0;       // the arm's cold reading: the second coldest of its joints' readings
  double cold_friction = 1.0;  // the lower median of the joints' latest block medians (C)
  double unsettled = 1.0;      // what a joint whose reading has not settled also takes
  double warm_rho = 1.0;       // the lower median of the settled joints' warm-floor readings
  double shown_friction;       // the upper median of the joints' shown friction (P); infinite until two
  double gear_rho = 1.0;       // the lower median of the joints' gear_shown_rho, over two at least
  ArmAllowance();
};

// One joint's friction reference and the statistics of the fast fit it keeps.
struct FrictionReference {
  explicit FrictionReference(const MonitorConfig& c, double dt_s);
  // After the fast balance fit `b` has taken this tick (`usable`: one the fit could use).
  // `winding_above_K`: a declared winding sensor's reading over the calibration's (NaN without).
  // `viscous_share`: the viscous part's share of the calibrated curve at this tick (ViscousShare,
  // friction_model.h), averaged over each block for the arm's friction model.
  void Update(const MonitorConfig& c, double winding_above_K, const ElectricalEstimator& electrical,
              const BalanceFit::Estimate& b, bool usable, double viscous_share, double dt_s, const ArmAllowance& arm);
  // The warm floor's reading: the coldest converged reading, and until the reading converges,
  // the coldest settled one (infinite before it settles).
  double WarmFloorReading() const;

  double reference = 1;     // the friction a healthy gear may show, against its calibration
  double cap = 1;           // the cold allowance of the coldest the winding has read
  bool cap_settled = false; // cap is from settled readings
  double coldest_settled_rho;    // the coldest settled reading of the winding (the cold allowance's)
  double coldest_converged_rho;  // ... since the reading converged (winding_reading_converged_s)
  double shown = 0;         // the median of the fit's recent block medians (shown_friction_blocks)
  double first_top;         // the top of its first min_shown_friction_blocks block medians (infinite until then)
  double follow;            // the envelope F, followed down only (infinite until the blocks fill)
  std::vector<double> block_median;  // ring of friction_envelope_blocks block medians
  int blocks = 0;           // blocks completed
  std::vector<double> block;   // this block's fast factors
  double block_s = 0;
  double block_share_sum = 0;  // this block's viscous shares, summed over its ticks
  // The latest completed block, as the arm's friction model takes it (friction_model.h).
  double last_block_median = 1;
  double last_block_share = 0.5;   // its mean viscous share
  double last_block_log_se = 0;    // the fast fit's relative standard error at its end
  bool last_block_teaches = false; // the sensor's zero was found through all of it
  bool zero_found = true;          // set by the caller each tick: the sensor's zero is found (or none)
  bool block_zero_found = true;    // ... through this block so far
  // The resistance factor a winding as warm as its gear shows would read (GearShownRho): its
  // latest reading while the fast fit held enough motion; NaN until the first.
  double gear_shown_rho;

 private:
  std::vector<double> recent_;  // scratch: the last blocks' medians
};

// The friction factor a lubricant as cold as a winding with resistance factor `winding_rho`
// could add beyond the `held_K` the limit holds: 1 unless the winding reads more than that
// below its commissioning; no colder than max_cold_K counted.
double ColdFrictionAllowance(const MonitorConfig& c, double winding_rho, double held_K);
double ColdFrictionAllowance(const MonitorConfig& c, double winding_rho);  // held_K: cold_held_by_limit_K

// The friction a lubricant as warm as a winding with resistance factor `winding_rho` keeps at
// most, against the commissioned curve, falling at `slope_per_K` over at most `max_counted_K`
// beyond the reading's error: 1 unless the winding reads between winding_reading_error_K and
// max_warm_K above its commissioning.
double WarmFrictionFloor(const MonitorConfig& c, double winding_rho, double slope_per_K, double max_counted_K);

// The warmth a gear shows: a friction that reads below the unit's commissioned curve (by more
// than gear_warmth_se standard errors) is a lubricant warmer than at commissioning by at least
// what the steepest slope gives (wear and faults only raise friction), up to max_warm_K. The
// resistance factor a winding that warm would read; 1 when the gear shows no warmth; NaN when
// the fit has not held enough motion to say, or without a commissioned curve.
double GearShownRho(const MonitorConfig& c, bool commissioned, const BalanceFit::Estimate& gear);

// One joint as the arm's readings see it.
struct ArmJoint {
  const FrictionReference* friction;
  const ElectricalEstimator* electrical;
};
ArmAllowance FrictionAllowanceOfArm(const MonitorConfig& c, const std::vector<ArmJoint>& joints);

}  // namespace armfault
