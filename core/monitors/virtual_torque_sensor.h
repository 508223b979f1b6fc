// The torque sensor a monitor computes where a joint has none (UR-class arms): the robot
// model's transmitted torque (core/plant/robot/rigid_body_dynamics.h, the nominal robot's bodies and
// payload) in place of the reading, so the power monitor's balances run unchanged.
//
// Inputs per tick: every joint's JointSignals now and at the previous tick, the period dt [s].
// Output: tau_sensor_Nm [N m, link side] of each joint without a sensor, from the encoder
// angles q_meas, the controller's velocity estimates qd_est and, for the accelerations, their
// difference over the period (qd_est now − qd_est before)/dt. That difference is noisy tick by
// tick (±1 N m at the ur-class base), but the torque is linear in it and every use of the
// reading low-passes it (the balance filter, the windows): over 50 ms it follows the true
// torque within 0.4–1.8 % rms (tests/core/monitors/virtual_torque_sensor_test.cc), where the
// references' accelerations miss the controller's corrections (14 % at the base). What this
// cannot see: a payload the model does not hold, and the sensor's own families
// (docs/monitor.md, "Without torque sensors").
#pragma once

#include <vector>

#include "core/plant/robot/rigid_body_dynamics.h"
#include "core/signals/joint_signals.h"

namespace armfault {

struct VirtualTorqueSensor {
  RigidBodyModel bodies;
  std::vector<char> virtual_joint;  // per joint: 1 where the robot has no torque sensor
  bool any() const;
  // Fills tau_sensor_Nm of the joints without a sensor in `now`.
  void Fill(const std::vector<JointSignals>& prev, double dt_s, std::vector<JointSignals>* now) const;
};

// From the nominal robot: its bodies with its payload_kg, and which joints lack a sensor.
VirtualTorqueSensor MakeVirtualTorqueSensor(const RobotConfig& robot);

}  // namespace armfault
