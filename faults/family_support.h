// Shared pieces of the fault families: the common JSON fields, the magnitude reader and the
// effect meters (defined in fault.cc). Only the family files, onset_condition.cc and registry.cc
// include this. Dependencies go one way: registry.cc (the table of families) uses the family
// files and these pieces, the family files use these pieces, and these never call back into
// registry.cc.
#pragma once

#include <functional>
#include <initializer_list>
#include <memory>
#include <string>

#include "core/base/json_input.h"
#include "faults/fault.h"

namespace armfault {

struct FaultCommon {
  int joint_index = 0;  // 0-based
  FaultTiming timing;
};

// Accepts exactly the common keys plus `own_keys` (rejecting any other key), then reads and
// checks the common fields: joint (1..joints of the robot), onset_s >= 0, profile, and the
// profile's ramp_s, period_s, duty. Every error goes to `errors`, each key on its own (a bad
// one left at its default), so the family checks its own keys too and reports them all at
// once; the family throws `errors` before it builds anything.
FaultCommon ReadFaultCommon(ObjectReader& reader, const RobotConfig& robot, std::initializer_list<const char*> own_keys,
                            ErrorList* errors);

// The 0-based index of the required key "joint" (1..joints of the robot); an InputError naming
// the pointer and the robot's joints otherwise.
int ReadJointIndex(ObjectReader& reader, const RobotConfig& robot);

// A family's magnitude as its line in registry.cc's table states it. MakeFault hands it to the
// family's factory, so a family reads its magnitude without looking the table up.
struct FaultMagnitudeSpec {
  const char* family;
  const char* key;  // "" for a family without a magnitude
  FaultMagnitudeRange range;
};

// Reads the magnitude's key into *value, checking the range (a missing key: an error when
// `required`, else *value stays): "0 must be greater than 0" for an excluded minimum, then
// "1.7 is outside [0, 1]", "0 is no change" for an excluded zero. Throws std::logic_error for a
// family without a magnitude.
void ReadMagnitude(ObjectReader& reader, const FaultMagnitudeSpec& magnitude, double* value, bool required = true);

// Ticks after onset + settle_s count as "faulty"; before onset as "healthy".
constexpr double kEffectSettle_s = 0.05;

// Ratio of two sums over the selected ticks, before and after onset: e.g. torque per ampere
// = sum(T i) / sum(i^2). Healthy is the pre-onset ratio, or `nominal` when fewer than
// `min_samples` ticks were seen before onset. Took effect when |faulty/healthy - 1| > threshold.
struct RatioTerms {
  bool include = false;
  double numerator = 0, denominator = 0;
};
std::unique_ptr<EffectMeter> MakeRatioMeter(std::string measure, double onset_s, double nominal, double threshold,
                                            std::function<RatioTerms(const JointTick&)> terms);

// Root mean square of a quantity before and after onset; took effect when the faulty RMS
// exceeds factor x healthy + margin.
std::unique_ptr<EffectMeter> MakeRmsMeter(std::string measure, double onset_s, double factor, double margin,
                                          std::function<double(const JointTick&)> value);

// Mean of a quantity before and after onset; took effect when faulty > healthy + margin.
std::unique_ptr<EffectMeter> MakeMeanMeter(std::string measure, double onset_s, double margin,
                                           std::function<double(const JointTick&)> value);

// Standard deviation of a quantity before and after onset; took effect when the faulty
// value is flat: std below `fraction` x healthy std (a stuck signal).
std::unique_ptr<EffectMeter> MakeFlatnessMeter(std::string measure, double onset_s, double fraction,
                                               std::function<double(const JointTick&)> value);

// Either meter's evidence: the first that took effect, else the first's result.
std::unique_ptr<EffectMeter> MakeEitherMeter(std::unique_ptr<EffectMeter> first, std::unique_ptr<EffectMeter> second);

// Factory signature of a family (registry.cc); `magnitude` is the family's line in the table.
using FaultFactory = std::unique_ptr<Fault> (*)(ObjectReader& reader, const RobotConfig& robot,
                                                const FaultMagnitudeSpec& magnitude);

std::unique_ptr<Fault> MakeKtDegradation(ObjectReader& reader, const RobotConfig& robot,
                                         const FaultMagnitudeSpec& magnitude);
std::unique_ptr<Fault> MakeFrictionIncrease(ObjectReader& reader, const RobotConfig& robot,
                                            const FaultMagnitudeSpec& magnitude);
std::unique_ptr<Fault> MakeBrakeLock(ObjectReader& reader, const RobotConfig& robot,
                                     const FaultMagnitudeSpec& magnitude);
std::unique_ptr<Fault> MakeTorqueSensorStuck(ObjectReader& reader, const RobotConfig& robot,
                                             const FaultMagnitudeSpec& magnitude);
std::unique_ptr<Fault> MakeInverterShort(ObjectReader& reader, const RobotConfig& robot,
                                         const FaultMagnitudeSpec& magnitude);
std::unique_ptr<Fault> MakeWindingResistance(ObjectReader& reader, const RobotConfig& robot,
                                             const FaultMagnitudeSpec& magnitude);
std::unique_ptr<Fault> MakeTorqueSensorDrift(ObjectReader& reader, const RobotConfig& robot,
                                             const FaultMagnitudeSpec& magnitude);

}  // namespace armfault
