// The torque sensor a monitor computes where a joint has none (UR-class arms): the robot
// model's transmitted torque (core/plant/rigid_body_dynamics.h, the nominal robot's bodies and
// payload) in place of the reading, so the power monitor's balances run unchanged.
//
// Inputs per tick: every joint's JointSignals now and at the previous tick, the period dt [s].
// Output: tau_sensor_Nm [N m, link side] of each joint without a sensor, from the encoder
// angles q_meas, the controller's velocity estimates qd_est and, for the accelerations, the
// references' (qd_ref now − qd_ref before)/dt: the joints track within a fraction of a degree,
// and an encoder's second difference at 500 Hz is noise. A joint far from its reference
// (|q_ref − q_meas| > kTrackingLimit_rad: blocked, or its drive lost) is taken as not
// accelerating. What this cannot see: a payload the model does not hold, and the sensor's own
// families (docs/monitor.md, "Without torque sensors").
#pragma once

#include <vector>

#include "core/plant/rigid_body_dynamics.h"
#include "core/signals/joint_signals.h"

namespace armfault {

constexpr double kTrackingLimit_rad = 0.02;

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
