// Why a run was scored wrong: the one line ExplainOutcome writes into each record.
#include "core/monitors/detector_statistics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/monitors/power_monitor.h"

namespace armfault {
namespace {

using testing::HasSubstr;

constexpr int kFriction = static_cast<int>(Detector::kFrictionFactor);

DecisionStats::Trace Trace(int joint, Detector d, std::vector<DecisionStats::Rise> rise) {
  DecisionStats::Trace t;
  t.joint = joint;
  t.detector = d;
  t.rise = std::move(rise);
  return t;
}

DecisionStats::Rise Rise(double t_s, long quanta, long significance_quanta) {
  DecisionStats::Rise r;
  r.t_s = t_s;
  r.held = {quanta, significance_quanta};
  return r;
}

struct Fixture {
  MonitorConfig config;
  DetectorThresholds h = ThresholdsOf(config);
  double z = config.significance;
};

TEST(ExplainOutcomeTest, AMissNamesTheClosestStatisticAndHowFarItStayedBelow) {
  Fixture f;
  DecisionStats s;
  s.onset_s = 1.0;
  // Friction 0.6 of its threshold, then higher but not significant enough.
  const long near = std::lround(0.6 * f.h[kFriction] / kStatisticQuantum);
  s.traces.push_back(Trace(2, Detector::kFrictionFactor, {Rise(1.5, near, 2000), Rise(2.0, 2 * near, 100)}));
  const DecisionOutcome d = Decide(s, f.h, f.z);
  ASSERT_FALSE(d.detected);
  const std::string why = ExplainOutcome(s, f.h, f.z, d, "friction_increase", 2, f.config);
  EXPECT_THAT(why, HasSubstr("no alarm; closest on joint 2: friction_factor deviated "));
  EXPECT_THAT(why, HasSubstr("60 %) with significance 20 (needs 3)"));  // min(0.6, 20/3) beats min(1.2, 1/3)
}

TEST(ExplainOutcomeTest, ADetectorThatNeverJudgedNamesItsGate) {
  Fixture f;
  DecisionStats s;
  s.onset_s = 1.0;
  const DecisionOutcome d = Decide(s, f.h, f.z);
  const std::string why = ExplainOutcome(s, f.h, f.z, d, "kt_degradation", 3, f.config);
  EXPECT_EQ(why, "no alarm; kt_factor on joint 3 was never judged after the onset (output energy below "
                 "min_rotor_energy_J = 2 J); no statistic on joint 3 was judged after the onset");
  EXPECT_EQ(ExplainOutcome(s, f.h, f.z, d, "inverter_short", 3, f.config),
            "no alarm; the tick-level inverter_short detector never latched on joint 3");
}

TEST(ExplainOutcomeTest, AWrongFamilyOrJointSaysWhatWonAndAHealthyAlarmWhatAlarmed) {
  Fixture f;
  DecisionStats s;
  s.onset_s = 2.0;
  s.first_tick_s = 2.0;
  s.traces.push_back(Trace(2, Detector::kFrictionFactor, {Rise(2.5, 100000, 10000)}));
  const DecisionOutcome d = Decide(s, f.h, f.z);
  ASSERT_TRUE(d.detected);
  EXPECT_THAT(ExplainOutcome(s, f.h, f.z, d, "kt_degradation", 2, f.config),
              HasSubstr("named friction_increase on joint 2 at 2.5 s instead of kt_degradation on joint 2; kt_factor "
                        "on joint 2 was never judged after the onset"));
  EXPECT_EQ(ExplainOutcome(s, f.h, f.z, d, "friction_increase", 2, f.config), "");  // right: nothing to explain
  DecisionStats healthy = s;
  healthy.onset_s = 0;
  EXPECT_EQ(ExplainOutcome(healthy, f.h, f.z, Decide(healthy, f.h, f.z), "", 0, f.config),
            "alarm: friction_increase on joint 2 at 2.5 s");
}

}  // namespace
}  // namespace armfault
