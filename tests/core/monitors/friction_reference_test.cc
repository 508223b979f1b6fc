// The friction the run finds: the lubricant's allowances from the winding's reading, the
// warmth a gear shows, and the arm's readings, which no joint order and no one worn joint move.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/monitors/friction_reference.h"
#include "core/monitors/monitor_config.h"

namespace armfault {
namespace {

// The resistance factor of a winding `dT_K` over its commissioning.
double RhoAt(const MonitorConfig& c, double dT_K) { return 1.0 + c.copper_resistance_per_K * dT_K; }

TEST(FrictionReference, AColdWindingAllowsTheSteepestLubricantBeyondWhatTheLimitHolds) {
  const MonitorConfig c;
  const double beta = std::log(3.0) / 50.0;
  EXPECT_NEAR(ColdFrictionAllowance(c, RhoAt(c, -20)), std::exp(beta * 10), 1e-12);
  EXPECT_EQ(ColdFrictionAllowance(c, RhoAt(c, -8)), 1.0);  // inside the limit's 10 K
  EXPECT_NEAR(ColdFrictionAllowance(c, RhoAt(c, -60)), std::exp(beta * 30), 1e-12);  // no colder than 40 K
  MonitorConfig flat = c;
  flat.max_lubricant_slope_per_K = 0;  // a grease that does not thicken: no allowance
  EXPECT_EQ(ColdFrictionAllowance(flat, RhoAt(c, -30)), 1.0);
}

TEST(FrictionReference, AWarmWindingLowersTheFloorByTheGentlestSlope) {
  const MonitorConfig c;
  EXPECT_NEAR(WarmFrictionFloor(c, RhoAt(c, 12), 0.01, 14), std::exp(-0.01 * 7), 1e-12);  // 12 K less the 5 K error
  EXPECT_NEAR(WarmFrictionFloor(c, RhoAt(c, 30), 0.01, 14), std::exp(-0.01 * 14), 1e-12);  // counted up to 14 K
  EXPECT_EQ(WarmFrictionFloor(c, RhoAt(c, 3), 0.01, 14), 1.0);   // within the reading's error
  EXPECT_EQ(WarmFrictionFloor(c, RhoAt(c, 50), 0.01, 14), 1.0);  // beyond 40 K: no temperature, no floor
}

TEST(FrictionReference, AGearBelowItsCommissionedCurveShowsWarmth) {
  const MonitorConfig c;
  BalanceFit::Estimate gear;
  gear.friction_factor = 0.80;
  gear.friction_factor_se = 0.01;
  gear.moving_s = 1.0;
  EXPECT_TRUE(std::isnan(GearShownRho(c, false, gear)));  // a datasheet curve shows nothing
  const double warm_K = -std::log(0.82) / c.max_lubricant_slope_per_K;  // its upper bound at 2 se
  EXPECT_NEAR(GearShownRho(c, true, gear), RhoAt(c, warm_K), 1e-12);
  gear.friction_factor = 1.1;  // wear raises friction: no warmth shown
  EXPECT_EQ(GearShownRho(c, true, gear), 1.0);
  gear.moving_s = 0.1;  // too little motion to say
  EXPECT_TRUE(std::isnan(GearShownRho(c, true, gear)));
}

// A joint whose blocks all read `factor`, with a settled winding reading `rho`.
struct JointFixture {
  JointFixture(const MonitorConfig& c, double factor, double rho) : friction(c, 0.002), electrical(c, 0.002, 0.1) {
    friction.blocks = c.unconverged_friction_blocks + c.min_shown_friction_blocks;
    std::fill(friction.block_median.begin(), friction.block_median.end(), factor);
    friction.shown = factor;
    friction.cap_settled = true;
    friction.coldest_settled_rho = friction.coldest_converged_rho = rho;
    friction.cap = ColdFrictionAllowance(c, rho);
    friction.gear_shown_rho = rho;
    electrical.winding.judged_s = 30;
    electrical.winding.reading = rho;
  }
  FrictionReference friction;
  ElectricalEstimator electrical;
};

bool SameAllowance(const ArmAllowance& a, const ArmAllowance& b) {
  return a.cold_rho == b.cold_rho && a.cold_friction == b.cold_friction && a.unsettled == b.unsettled &&
         a.warm_rho == b.warm_rho && a.shown_friction == b.shown_friction && a.gear_rho == b.gear_rho;
}

TEST(FrictionReference, TheArmsReadingsAreTheSameInAnyJointOrderAndOneWornJointMovesNone) {
  const MonitorConfig c;
  std::vector<JointFixture> joints;
  joints.emplace_back(c, 1.10, 0.93);
  joints.emplace_back(c, 1.12, 0.95);
  joints.emplace_back(c, 1.08, 0.92);
  joints.emplace_back(c, 1.11, 0.96);
  std::vector<ArmJoint> view, reversed;
  for (auto& j : joints) view.push_back({&j.friction, &j.electrical});
  reversed.assign(view.rbegin(), view.rend());
  const ArmAllowance arm = FrictionAllowanceOfArm(c, view);
  EXPECT_TRUE(SameAllowance(arm, FrictionAllowanceOfArm(c, reversed)));
  EXPECT_EQ(arm.cold_rho, 0.93);         // the second coldest reading
  EXPECT_EQ(arm.cold_friction, 1.10);    // the lower median of the latest blocks
  // Wear 1.5x on one joint: the arm's cold friction is still what the others show.
  std::fill(joints[1].friction.block_median.begin(), joints[1].friction.block_median.end(), 1.5 * 1.12);
  EXPECT_EQ(FrictionAllowanceOfArm(c, view).cold_friction, 1.10);
}

}  // namespace
}  // namespace armfault
