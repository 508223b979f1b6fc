#include "core/plant/drive/encoder.h"

#include <cmath>

namespace armfault {

double EncoderRadPerCount(const EncoderParams& p) { return 2.0 * M_PI / p.counts_per_rev; }

int64_t EncoderCount(const EncoderParams& p, double motor_angle_rad) {
  return static_cast<int64_t>(std::floor(motor_angle_rad / EncoderRadPerCount(p)));
}

}  // namespace armfault
