// Where the plant's ticks and a monitor meet: a monitor in the simulation's loop. Here, above
// both, so that neither the plant nor the monitor interface includes the other.
#pragma once

#include "core/monitors/monitor.h"
#include "core/plant/simulation.h"

namespace armfault {

// Adapts a monitor to the simulation's tick observer: passes on only each joint's signals
// (JointTick::signals), then calls `also` (if any) with the whole tick.
TickObserver ObserveWith(HealthMonitor* monitor, TickObserver also = nullptr);

}  // namespace armfault
