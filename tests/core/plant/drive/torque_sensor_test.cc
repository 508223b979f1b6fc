#include "core/plant/drive/torque_sensor.h"

#include <gtest/gtest.h>

#include "core/plant/drive/encoder.h"

namespace armfault {
namespace {

const TorqueSensorParams kThesis;  // defaults: 28 N m over 1.5 V, offset 3.5077, 12 bits, 0..3 V

TEST(TorqueSensorTest, ReadingReproducesTorqueWithinOneAdcStep) {
  const double lsb_Nm = 28.0 / 1.5 * 3.0 / 4095;
  for (double tau : {-20.0, -1.0, 0.0, 0.37, 12.5, 30.0}) {
    const int code = TorqueSensorAdcCode(kThesis, TorqueSensorVoltage(kThesis, tau, 0.0));
    EXPECT_NEAR(TorqueFromAdcCode(kThesis, code), tau, 0.5 * lsb_Nm + 1e-12) << tau;
  }
}

TEST(TorqueSensorTest, ThesisMappingOfTheAdcVoltage) {
  // tau = 28 (V - 1.5)/1.5 + 3.5077 at the ends and the middle of the range.
  EXPECT_DOUBLE_EQ(TorqueFromAdcCode(kThesis, 4095), 28.0 + 3.5077);
  EXPECT_DOUBLE_EQ(TorqueFromAdcCode(kThesis, 0), -28.0 + 3.5077);
}

TEST(TorqueSensorTest, StuckLeadsReadTheRailMappedTorques) {
  EXPECT_NEAR(TorqueFromAdcCode(kThesis, TorqueSensorAdcCode(kThesis, StuckLeadVoltage(kThesis, SensorLead::kSupply))), 31.5077, 1e-9);
  EXPECT_NEAR(TorqueFromAdcCode(kThesis, TorqueSensorAdcCode(kThesis, StuckLeadVoltage(kThesis, SensorLead::kGround))), -24.4923, 1e-9);
}

TEST(TorqueSensorTest, OutOfRangeTorquesClipAtTheAdcLimits) {
  EXPECT_EQ(TorqueSensorAdcCode(kThesis, TorqueSensorVoltage(kThesis, 80.0, 0.0)), 4095);
  EXPECT_EQ(TorqueSensorAdcCode(kThesis, TorqueSensorVoltage(kThesis, -80.0, 0.0)), 0);
}

TEST(TorqueSensorTest, NoiseIsGivenInNewtonMetres) {
  const double v0 = TorqueSensorVoltage(kThesis, 1.0, 0.0);
  const double v1 = TorqueSensorVoltage(kThesis, 1.0, 1.0);
  EXPECT_NEAR((v1 - v0) * 28.0 / 1.5, kThesis.noise_Nm, 1e-12);
}

TEST(EncoderTest, CountsQuantiseTheMotorAngle) {
  const EncoderParams mrr2;  // 2540 counts per motor revolution (pi/1270 rad per count)
  EXPECT_DOUBLE_EQ(EncoderRadPerCount(mrr2), M_PI / 1270);
  EXPECT_EQ(EncoderCount(mrr2, 0.0), 0);
  EXPECT_EQ(EncoderCount(mrr2, 2 * M_PI), 2540);
  EXPECT_EQ(EncoderCount(mrr2, 0.99 * M_PI / 1270), 0);
  EXPECT_EQ(EncoderCount(mrr2, -0.5 * M_PI / 1270), -1);
}

}  // namespace
}  // namespace armfault
