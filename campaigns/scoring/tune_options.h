// What `armfault tune` is asked (campaigns/tuning/tuning.h): the sweep, the rule that picks the
// operating point, the threads. Apart from tuning.h so that its scoring engine
// (campaigns/scoring/tune_scoring.h) takes them without depending on the command it serves.
#pragma once

#include <string>

namespace armfault {

struct OperatingRule {
  enum class Kind { kMaxDetection, kYouden, kMinCost };
  Kind kind = Kind::kMaxDetection;
  double false_alarm_ceiling = 0.01;  // kMaxDetection: highest detection with FA <= this
  double miss_cost = 1.0;             // kMinCost: cost of a missed fault ...
  double false_alarm_cost = 1.0;      // ... and of a false alarm; minimises miss_cost (1 - DR) + false_alarm_cost FA
};
// "max_detection", "youden", "min_cost"; throws InputError.
OperatingRule::Kind OperatingRuleKind(const std::string& name);

struct TuneOptions {
  std::string sweep;
  OperatingRule rule;
  int threads = 0;  // 0: all cores
};

}  // namespace armfault
