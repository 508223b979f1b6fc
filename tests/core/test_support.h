// Shared helpers for the core tests.
#pragma once

#include <memory>
#include <vector>

#include "core/simulation.h"

namespace armfault::testing_support {

// A hardware condition applied to one joint (0-based) from t = 0: the simplest fault.
class ConstantCondition : public HardwareSchedule {
 public:
  ConstantCondition(int joint, HardwareCondition condition) : joint_(joint), condition_(condition) {}
  void Apply(double, std::vector<HardwareCondition>* conditions) const override {
    (*conditions)[joint_] = condition_;
  }

 private:
  int joint_;
  HardwareCondition condition_;
};

// All ticks of a run, copied.
struct Recording {
  std::vector<double> t;
  std::vector<std::vector<JointTick>> ticks;
  TickObserver Observer() {
    return [this](const Tick& tick) {
      t.push_back(tick.t_s);
      ticks.push_back(*tick.joints);
    };
  }
};

}  // namespace armfault::testing_support
