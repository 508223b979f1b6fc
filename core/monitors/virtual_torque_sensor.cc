#include "core/monitors/virtual_torque_sensor.h"

#include <cmath>

namespace armfault {

bool VirtualTorqueSensor::any() const {
  for (char v : virtual_joint) {
    if (v) return true;
  }
  return false;
}

void VirtualTorqueSensor::Fill(const std::vector<JointSignals>& prev, double dt_s, std::vector<JointSignals>* now) const {
  const size_t n = virtual_joint.size();
  if (now->size() != n || prev.size() != n) return;
  thread_local std::vector<double> q, qd, qdd, tau;
  q.resize(n), qd.resize(n), qdd.resize(n), tau.resize(n);
  for (size_t j = 0; j < n; ++j) {
    const JointSignals& s = (*now)[j];
    q[j] = s.q_meas_rad;
    qd[j] = s.qd_est_rad_s;
    qdd[j] = dt_s > 0 ? (s.qd_est_rad_s - prev[j].qd_est_rad_s) / dt_s : 0.0;
  }
  TransmittedTorques(bodies, q.data(), qd.data(), qdd.data(), tau.data());
  for (size_t j = 0; j < n; ++j) {
    if (virtual_joint[j]) (*now)[j].tau_sensor_Nm = tau[j];
  }
}

VirtualTorqueSensor MakeVirtualTorqueSensor(const RobotConfig& robot) {
  VirtualTorqueSensor v;
  for (const ModuleParams& m : robot.modules) v.virtual_joint.push_back(m.torque_sensor.present ? 0 : 1);
  if (v.any()) v.bodies = MakeRigidBodyModel(robot, robot.payload_kg);
  return v;
}

}  // namespace armfault
