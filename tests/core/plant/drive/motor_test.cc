// Brushless motor and inverter: back-EMF shape, stall torque K_T x I, current loop, and the
// drive's own power balance.
#include "core/plant/drive/motor.h"

#include <gtest/gtest.h>

#include <cmath>

namespace armfault {
namespace {

constexpr double kSubstep = 1e-3 / 20;

TEST(BackEmfTest, TrapezoidHasFlatTopsOf120DegreesAndIsContinuous) {
  auto deg = [](double d) { return d * M_PI / 180; };
  EXPECT_DOUBLE_EQ(BackEmfShape(deg(0)), 0.0);
  EXPECT_DOUBLE_EQ(BackEmfShape(deg(15)), 0.5);
  for (double d : {30.0, 90.0, 150.0}) EXPECT_NEAR(BackEmfShape(deg(d)), 1.0, 1e-12);
  for (double d : {210.0, 270.0, 330.0}) EXPECT_NEAR(BackEmfShape(deg(d)), -1.0, 1e-12);
  EXPECT_NEAR(BackEmfShape(deg(180)), 0.0, 1e-12);
  EXPECT_NEAR(BackEmfShape(deg(360 + 90)), 1.0, 1e-12);
  EXPECT_NEAR(BackEmfShape(deg(-90)), -1.0, 1e-12);
}

ModuleParams Mrr2() { return ModuleParams{}; }

TEST(StallTorqueTest, TorqueIsKtTimesCurrentAtAnyRotorAngle) {
  const DriveConstants c = MakeDriveConstants(Mrr2(), kSubstep);
  for (double angle = 0.0; angle < 2 * M_PI; angle += 0.37) {
    for (double amps : {-3.0, 0.5, 2.0}) {
      DriveState state;
      DriveInputs in;
      in.current_command_A = amps;
      in.motor_angle_rad = angle;
      DriveOutputs out;
      for (int step = 0; step < 10; ++step) StepDrive(c, HardwareCondition{}, in, 20, &state, &out);
      EXPECT_NEAR(out.torque_Nm, 0.165 * amps, 0.002 * std::fabs(amps)) << "angle " << angle << " current " << amps;
    }
  }
}

TEST(CurrentLoopTest, FollowsTheCommandAgainstBackEmf) {
  const DriveConstants c = MakeDriveConstants(Mrr2(), kSubstep);
  DriveState state;
  DriveInputs in;
  in.current_command_A = 4.0;
  in.motor_angle_rad = 0.3;
  in.motor_speed_rad_s = 200;  // back-EMF about 33 V line to line
  DriveOutputs out;
  StepDrive(c, HardwareCondition{}, in, 40, &state, &out);  // 2 ms to settle
  // Over the next 10 ms, through several commutations, the mean current is on target.
  double torque = 0;
  for (int step = 0; step < 10; ++step) {
    in.motor_angle_rad = 0.3 + 200 * (2e-3 + step * 1e-3);
    StepDrive(c, HardwareCondition{}, in, 20, &state, &out);
    torque += out.torque_Nm / 10;
  }
  EXPECT_NEAR(torque / 0.165, 4.0, 0.1);
}

TEST(DrivePowerTest, SupplyEqualsCopperEmfMagneticInverterAndQuiescent) {
  const DriveConstants c = MakeDriveConstants(Mrr2(), kSubstep);
  DriveState state;
  DriveInputs in;
  double supply = 0, parts = 0, emf = 0;
  // A spinning rotor with commutations and a reversing command: diodes freewheel too.
  for (int step = 0; step < 500; ++step) {
    in.current_command_A = 3.0 * std::sin(step * 0.02);
    in.motor_speed_rad_s = 150;
    in.motor_angle_rad = 150 * step * 1e-3;
    DriveOutputs out;
    StepDrive(c, HardwareCondition{}, in, 20, &state, &out);
    supply += out.p_supply_W;
    parts += out.p_copper_W + out.p_emf_W + out.p_magnetic_W + out.p_inverter_W + out.p_quiescent_W;
    emf += out.p_emf_W;
    EXPECT_NEAR(out.p_emf_W, out.torque_Nm * in.motor_speed_rad_s, 1e-9 + 1e-9 * std::fabs(out.p_emf_W));
  }
  EXPECT_NEAR(supply, parts, 1e-3 * std::fabs(supply));
  EXPECT_GT(std::fabs(emf), 0.0);
}

TEST(DriveTest, DisabledDriverWithSlowRotorDrawsOnlyQuiescentPower) {
  const DriveConstants c = MakeDriveConstants(Mrr2(), kSubstep);
  DriveState state;
  DriveInputs in;
  in.enabled = false;
  in.current_command_A = 5;
  in.motor_speed_rad_s = 50;  // back-EMF well below the bus: no rectification
  DriveOutputs out;
  StepDrive(c, HardwareCondition{}, in, 20, &state, &out);
  EXPECT_EQ(out.torque_Nm, 0.0);
  EXPECT_DOUBLE_EQ(out.p_supply_W, c.inverter.quiescent_power_W);
}

TEST(DriveTest, KtFactorScalesTorquePerAmpere) {
  const DriveConstants c = MakeDriveConstants(Mrr2(), kSubstep);
  HardwareCondition weak;
  weak.kt_factor = 0.6;
  DriveState state;
  DriveInputs in;
  in.current_command_A = 2;
  DriveOutputs out;
  for (int step = 0; step < 5; ++step) StepDrive(c, weak, in, 20, &state, &out);
  EXPECT_NEAR(out.torque_Nm, 0.6 * 0.165 * 2, 1e-3);
}

}  // namespace
}  // namespace armfault
