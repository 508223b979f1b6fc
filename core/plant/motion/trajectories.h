// Factories of the trajectory types (one per file in this directory) and the few helpers
// they share. Only core/plant/motion/trajectory.cc (the registry table) and these files use this header.
//
// A factory gets an ObjectReader over the trajectory's JSON object whose "type" key has
// already been read by MakeTrajectory. It reads its own keys (angles in degrees, times in
// seconds), converts angles to radians and returns an immutable Trajectory. Errors are
// InputError; those without a source get the JSON file's name added by MakeTrajectory. Each
// key is checked on its own (ErrorList), so every unknown or bad key of one trajectory is
// reported at once.
#pragma once

#include "core/base/json_input.h"
#include "core/plant/motion/trajectory.h"

#include <memory>
#include <string>

namespace armfault {

std::unique_ptr<Trajectory> MakeSinePair(ObjectReader& reader, const InputContext& ctx);
std::unique_ptr<Trajectory> MakeCosineRamp(ObjectReader& reader, const InputContext& ctx);
std::unique_ptr<Trajectory> MakeMinJerk(ObjectReader& reader, const InputContext& ctx);
std::unique_ptr<Trajectory> MakeHold(ObjectReader& reader, const InputContext& ctx);
std::unique_ptr<Trajectory> MakeCsv(ObjectReader& reader, const InputContext& ctx);

namespace trajectory_detail {

constexpr double kPi = 3.14159265358979323846;

// Degrees (as written in JSON) to radians (used internally).
inline double DegToRad(double deg) { return deg * (kPi / 180.0); }

}  // namespace trajectory_detail
}  // namespace armfault
