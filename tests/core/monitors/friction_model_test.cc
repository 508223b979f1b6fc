// The arm's friction model (core/monitors/friction_model.h): a reference that learns one
// lubricant's slopes from the arm's gears, leaves each joint's own blocks out of its own
// reference, and states its uncertainty.
#include "core/monitors/friction_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "core/monitors/monitor_config.h"

namespace armfault {
namespace {

constexpr double kDt = 0.001;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// An arm of `n` joints whose windings read `above_K` over commissioning (settled), and whose
// gears show friction factors from `friction(j)` in blocks of 1 s with viscous share `share`.
struct Arm {
  MonitorConfig c;
  std::vector<std::unique_ptr<FrictionReference>> friction;
  std::vector<std::unique_ptr<ElectricalEstimator>> electrical;
  std::vector<ArmJoint> joints;
  std::vector<double> sensor_K;
  ArmFrictionModel model;
  double t_s = 0;

  Arm(int n, double above_K) : sensor_K(static_cast<size_t>(n), kNaN), model(c, n) {
    c.friction_reference = kArmFrictionModel;
    for (int j = 0; j < n; ++j) {
      friction.push_back(std::make_unique<FrictionReference>(c, kDt));
      electrical.push_back(std::make_unique<ElectricalEstimator>(c, kDt, 0.1));
      electrical.back()->winding.judged_s = 60;
      electrical.back()->winding.reading = 1.0 + c.copper_resistance_per_K * above_K;
      joints.push_back({friction.back().get(), electrical.back().get()});
    }
  }
  // `seconds` of operation, a block per second on every joint, in joint order or reversed.
  template <class F>
  void Run(double seconds, F friction_of, double share = 0.5, bool reverse = false) {
    const int n = static_cast<int>(joints.size());
    for (int s = 0; s < static_cast<int>(seconds); ++s) {
      for (int i = 0; i < n; ++i) {
        const int j = reverse ? n - 1 - i : i;
        FrictionReference& f = *friction[static_cast<size_t>(j)];
        f.last_block_median = friction_of(j);
        f.last_block_share = share;
        f.last_block_log_se = 0.02;
        f.last_block_teaches = true;
        ++f.blocks;
      }
      model.Update(c, joints, sensor_K, t_s, 1.0);
      t_s += 1.0;
    }
  }
};

// A cold arm, 20 K under its commissioning, its lubricant steep: every gear shows 1.55x.
// One joint worn 1.5x on top. The worn joint's own blocks are not in its reference, so it is
// judged against what its arm-mates teach: its friction over its reference reads the wear.
TEST(ArmFrictionModel, AColdArmTeachesItsLubricantAndAWornJointIsJudgedAgainstTheOthers) {
  Arm arm(3, -20.0);
  const double cold = std::exp(0.022 * 20.0);
  arm.Run(120, [&](int j) { return j == 2 ? 1.5 * cold : cold; });
  const auto& worn = arm.model.joint[2];
  EXPECT_NEAR(worn.reference, cold, 0.05 * cold);
  EXPECT_NEAR(1.5 * cold / worn.reference, 1.5, 0.08);
  EXPECT_LT(worn.log_sd, 0.1);
  for (int j = 0; j < 2; ++j) {
    SCOPED_TRACE(j);
    // the others see the worn joint among their mates: their reference lies higher, never lower
    EXPECT_GE(arm.model.joint[j].reference, 0.97 * cold);
    EXPECT_LT(cold / arm.model.joint[j].reference - 1.0, 0.1);  // no alarm on a healthy joint
  }
}

// The same arm updated in reverse joint order within each tick gives the same references.
TEST(ArmFrictionModel, TheJointsOrderChangesNothing) {
  Arm forward(3, -12.0), reverse(3, -12.0);
  auto friction = [](int j) { return 1.2 + 0.05 * j; };
  forward.Run(40, friction, 0.4, false);
  reverse.Run(40, friction, 0.4, true);
  for (int j = 0; j < 3; ++j) {
    EXPECT_EQ(forward.model.joint[j].reference, reverse.model.joint[j].reference) << j;
    EXPECT_EQ(forward.model.joint[j].log_sd, reverse.model.joint[j].log_sd) << j;
  }
}

// A lone joint has no arm to learn from: its reference is the prior's, half the steepest
// catalogue slope, with the prior's uncertainty over the cold it reads.
TEST(ArmFrictionModel, ALoneJointKeepsThePriorsUncertainty) {
  Arm arm(1, -20.0);
  arm.Run(60, [](int) { return 1.4; });
  const double prior = 0.5 * arm.c.max_lubricant_slope_per_K;
  EXPECT_NEAR(arm.model.joint[0].reference, std::exp(prior * 20.0), 1e-9);
  // the slope at a viscous share of 0.5: 0.5 (β_v + β_d), each with the prior's sd
  EXPECT_GE(arm.model.joint[0].log_sd, 20.0 * arm.c.lubricant_slope_prior_sd_per_K * std::sqrt(0.5));
}

// Before any winding is read, the arm's temperature is unknown within the ambient's range, and
// the reference says so: its uncertainty is wide enough that a cold gear's friction is no alarm.
TEST(ArmFrictionModel, AnUnreadArmIsUnsure) {
  Arm arm(3, 0.0);
  for (auto& e : arm.electrical) e->winding.judged_s = 0;
  arm.Run(3, [](int) { return 1.6; });
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(arm.model.joint[j].reference, 1.0, 1e-12) << j;
    EXPECT_GT(arm.model.joint[j].log_sd, 0.2) << j;
  }
}

// A warm arm whose lubricant thins: the healthy gears show less friction than at
// commissioning, and wear on one of them from the start is judged against its arm-mates'
// thinning, not taken for the unit's own friction.
TEST(ArmFrictionModel, WearFromAWarmStartIsJudgedAgainstTheArmsThinning) {
  Arm arm(4, 25.0);
  const double warm = std::exp(-0.018 * 25.0);
  arm.Run(120, [&](int j) { return j == 1 ? 1.5 * warm : warm; });
  EXPECT_NEAR(1.5 * warm / arm.model.joint[1].reference, 1.5, 0.1);
  for (int j : {0, 2, 3}) EXPECT_LT(warm / arm.model.joint[j].reference - 1.0, 0.1) << j;
}

// The viscous share: the viscous term's magnitude over the three terms'.
TEST(ArmFrictionModel, TheViscousShareIsTheViscousTermsPart) {
  EXPECT_DOUBLE_EQ(ViscousShare(1.0, -2.0, 1.0), 0.25);
  EXPECT_DOUBLE_EQ(ViscousShare(0.0, 0.0, 0.0), 0.0);
}

}  // namespace
}  // namespace armfault
