// Incremental encoder on the motor shaft. Input: motor angle [rad] = ratio x link angle.
// Output: integer count (floor quantisation, counts_per_rev per revolution).
#pragma once

#include <cstdint>

#include "core/plant/robot/robot_config.h"

namespace armfault {

int64_t EncoderCount(const EncoderParams& p, double motor_angle_rad);
// Radians of motor angle per count.
double EncoderRadPerCount(const EncoderParams& p);

}  // namespace armfault
