#include "core/plant/drive/brake.h"

#include <algorithm>

namespace armfault {

double BrakeTorqueLimitNm(const BrakeParams& p, const HardwareCondition& condition, bool engaged) {
  // A dragging brake never exceeds the holding torque of a fully engaged one.
  return engaged ? p.holding_torque_Nm : std::min(condition.brake_drag_Nm, p.holding_torque_Nm);
}

}  // namespace armfault
