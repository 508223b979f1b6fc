#include "core/observe.h"

#include <vector>

namespace armfault {

TickObserver ObserveWith(HealthMonitor* monitor, TickObserver also) {
  return [monitor, also, signals = std::vector<JointSignals>()](const Tick& tick) mutable {
    signals.resize(tick.joints->size());
    for (size_t j = 0; j < signals.size(); ++j) signals[j] = (*tick.joints)[j].signals;
    monitor->Observe(tick.t_s, signals);
    if (also) also(tick);
  };
}

}  // namespace armfault
