// A trajectory must be a motion its joint's hardware can follow (core/run_config.h).
#include "core/run_config.h"

#include "core/base/json_input.h"
#include "tests/core/test_support.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace armfault {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing_support::ErrorOf;

InputError RunError(const json& joints) {
  InputContext ctx;
  ctx.source = "run.json";
  return ErrorOf([&] { RunConfigFromJson({{"duration_s", 4}, {"joints", joints}}, "", ctx); });
}

bool Accepted(const json& joints) {
  InputContext ctx;
  try {
    RunConfigFromJson({{"duration_s", 4}, {"joints", joints}}, "", ctx);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

json Sine(double amplitude_deg, double omega_rad_s) {
  return {{"type", "sine_pair"}, {"amplitude_deg", amplitude_deg}, {"omega_rad_s", omega_rad_s}};
}

TEST(MotionLimits, FollowFromTheDatasheet) {
  // MRR2 (thesis table 5-1): 70 V bus, K_T 0.165 N m/A, ratio 101, 6 A, rotor 3.46e-5 kg m^2, 500 Hz.
  const JointMotionLimits limits = MotionLimitsOf(RobotPreset("mrr-config1").modules[2]);
  EXPECT_DOUBLE_EQ(limits.control_period_s, 1.0 / 500);
  EXPECT_DOUBLE_EQ(limits.max_speed_rad_s, 70.0 / (0.165 * 101.0));
  EXPECT_DOUBLE_EQ(limits.max_acceleration_rad_s2, 0.165 * 6.0 / (3.46e-5 * 101.0));
}

TEST(MotionLimits, APeriodShorterThanTenControlStepsIsRejected) {
  // sine_pair's fastest component is sin(2 w t), period pi / w; 10 control periods = 0.02 s.
  for (const double omega : {1e300, 1e6, M_PI / 0.0199}) {
    const InputError e = RunError({{"3", Sine(1, omega)}});
    EXPECT_EQ(e.source(), "run.json");
    EXPECT_EQ(e.pointer(), "/joints/3") << omega;
    EXPECT_THAT(e.message(), HasSubstr("s in the motion is shorter than 10 control periods of joint 3 (0.02 s at 500 Hz)"))
        << omega;
  }
  // A cosine_ramp's period is its own; the smallest double gives an infinite frequency.
  for (const double period : {1e-12, 5e-324, 0.0199}) {
    const InputError e = RunError({{"3", {{"type", "cosine_ramp"}, {"amplitude_deg", 1}, {"period_s", period}}}});
    EXPECT_EQ(e.message(), "a period of " + FormatNumber(period) +
                               " s in the motion is shorter than 10 control periods of joint 3 (0.02 s at 500 Hz)");
  }
  EXPECT_TRUE(Accepted({{"3", {{"type", "cosine_ramp"}, {"amplitude_deg", 0.001}, {"period_s", 0.02}}}}));
}

TEST(MotionLimits, SpeedBeyondTheNoLoadSpeedIsRejected) {
  // min_jerk peaks at 1.875 delta / h: 40 deg in 0.3 s = 4.36 rad/s > 4.2 rad/s; in 0.4 s, 3.27.
  const json fast = {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {0.3, 40}}}};
  const InputError e = RunError({{"3", fast}});
  EXPECT_EQ(e.pointer(), "/joints/3");
  EXPECT_THAT(e.message(), HasSubstr("beyond joint 3's no-load speed of 4.200420042 rad/s (bus voltage / (K_T x gear ratio))"));
  EXPECT_TRUE(Accepted({{"3", {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {0.4, 40}}}}}}));
  // The limit is the joint's own: a higher bus voltage lets the same motion through.
  json robot = {{"modules", {json::object()}}, {"links", {json::object()}}};
  robot["modules"][0]["inverter"] = {{"bus_voltage_V", 140}};
  InputContext ctx;
  EXPECT_NO_THROW(RunConfigFromJson({{"robot", robot}, {"duration_s", 4}, {"joints", {{"1", fast}}}}, "", ctx));
}

TEST(MotionLimits, AccelerationBeyondWhatTheMotorGivesItsRotorIsRejected) {
  // Limit 283.3 rad/s^2. A 0.2 deg min_jerk step (peak acceleration 5.77 delta / h^2, sampled
  // every 1 ms) in 0.021 s: about 46 rad/s^2, fine; in 0.0081 s: about 300 rad/s^2, beyond.
  EXPECT_TRUE(Accepted({{"3", {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {0.021, 0.2}}}}}}));
  const InputError e = RunError({{"3", {{"type", "min_jerk"}, {"waypoints", {{0, 0}, {0.0081, 0.2}}}}}});
  EXPECT_EQ(e.pointer(), "/joints/3");
  EXPECT_THAT(e.message(), HasSubstr("rad/s^2, beyond what joint 3's motor can give its own rotor, 283.294225376 rad/s^2"));
}

TEST(SampleMotion, FlagsNonFiniteSamplesAndFindsPeaks) {
  InputContext ctx;
  const auto ramp = MakeTrajectory({{"type", "cosine_ramp"}, {"amplitude_deg", 10}, {"period_s", 2}}, "", ctx);
  const MotionEnvelope e = SampleMotion(*ramp, 2.0);
  EXPECT_TRUE(e.finite);
  const double a = 10 * M_PI / 180, w = M_PI;
  EXPECT_NEAR(e.peak_speed_rad_s, a * w, 1e-12);            // at t = 0.5 s, a 1 ms sample
  EXPECT_NEAR(e.peak_acceleration_rad_s2, a * w * w, 1e-12);  // at t = 0
  const auto nan = MakeTrajectory({{"type", "cosine_ramp"}, {"amplitude_deg", 10}, {"period_s", 5e-324}}, "", ctx);
  EXPECT_FALSE(SampleMotion(*nan, 1.0).finite);
}

TEST(JointRange, AJointWithoutTrajectoryMustRestInsideItsRange) {
  json robot = {{"modules", {{{"type", "MRR2"}}, {{"type", "MRR2"}, {"min_angle_deg", 10}, {"max_angle_deg", 90}}}},
                {"links", {json::object(), json::object()}}};
  InputContext ctx;
  ctx.source = "run.json";
  const json hold = {{"type", "hold"}, {"angle_deg", 45}};
  const InputError e =
      ErrorOf([&] { RunConfigFromJson({{"robot", robot}, {"duration_s", 2}, {"joints", {{"1", hold}}}}, "", ctx); });
  EXPECT_EQ(e.pointer(), "/joints");
  EXPECT_EQ(e.message(), "joint 2 has no trajectory and would rest at 0 deg, outside its range [10, 90] deg: "
                         "give it one (a \"hold\" inside the range)");
  EXPECT_NO_THROW(RunConfigFromJson({{"robot", robot}, {"duration_s", 2}, {"joints", {{"2", hold}}}}, "", ctx));
}

}  // namespace
}  // namespace armfault
