// Power-off brake on the motor shaft. Inputs: engaged flag (engaged = coil unpowered), drag
// from a fault [N m]. Output: the maximum torque the brake can exert on the motor shaft
// [N m]; it acts like dry friction (holds the shaft up to this torque, opposes slipping).
#pragma once

#include "core/plant/parts/hardware_condition.h"
#include "core/plant/robot/robot_config.h"

namespace armfault {

double BrakeTorqueLimitNm(const BrakeParams& p, const HardwareCondition& condition, bool engaged);

}  // namespace armfault
