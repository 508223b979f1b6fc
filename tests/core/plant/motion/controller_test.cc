// The thesis controller: constants from appendix C, DAC limits, velocity estimate, and the
// model-based current for a known motion.
#include "core/plant/motion/controller.h"

#include <gtest/gtest.h>

#include <cmath>

namespace armfault {
namespace {

TEST(ControllerTest, TorqueFilterHasTheThesisCoefficients) {
  const ControllerConstants c = MakeControllerConstants(ModuleParams{});
  EXPECT_NEAR(c.filter_b0, 0.04762, 5e-5);
  EXPECT_NEAR(c.filter_a1, 0.9048, 5e-5);
  EXPECT_DOUBLE_EQ(c.dt_s, 0.002);
}

TEST(ControllerTest, DacClipsTheCommandAtSixAmperes) {
  const ControllerConstants c = MakeControllerConstants(ModuleParams{});
  ControllerState s;
  ControllerInputs in;
  in.reference.q_rad = 0.5;  // far behind the reference: a large positive request
  ControllerOutputs out;
  StepController(c, in, &s, &out);
  EXPECT_GT(out.current_request_A, 6.0);
  EXPECT_NEAR(out.current_command_A, 6.0, 1e-12);
  in.reference.q_rad = -0.5;
  StepController(c, in, &s, &out);
  EXPECT_NEAR(out.current_command_A, -6.0, 1e-12);
}

TEST(ControllerTest, VelocityEstimateIsExactOnAConstantSpeedRamp) {
  const ControllerConstants c = MakeControllerConstants(ModuleParams{});
  ControllerState s;
  ControllerOutputs out;
  const int counts_per_tick = 13;
  for (int k = 0; k < 40; ++k) {
    ControllerInputs in;
    in.encoder_count = k * counts_per_tick;
    StepController(c, in, &s, &out);
  }
  EXPECT_NEAR(out.velocity_rad_s, counts_per_tick * c.link_rad_per_count / c.dt_s, 1e-12);
}

TEST(ControllerTest, AtRestOnTargetTheCommandCompensatesTheMeasuredLoad) {
  // No error, no motion: only the filtered torque feedback tau/(ratio K_T) remains (after the
  // filter settles), e.g. holding a link against gravity.
  const ControllerConstants c = MakeControllerConstants(ModuleParams{});
  ControllerState s;
  ControllerInputs in;
  in.torque_reading_Nm = 5.0;
  ControllerOutputs out;
  for (int k = 0; k < 500; ++k) StepController(c, in, &s, &out);
  EXPECT_NEAR(out.current_request_A, 5.0 / (101 * 0.167), 1e-6);
  EXPECT_NEAR(out.current_command_A, out.current_request_A, 4 * 3.0 / 4095);  // DAC step
}

}  // namespace
}  // namespace armfault
