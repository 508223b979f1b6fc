// Factories of the trajectory types (one per file in this directory) and the few helpers
// they share. Only core/trajectory.cc (the registry table) and these files use this header.
//
// A factory gets an ObjectReader over the trajectory's JSON object whose "type" key has
// already been read by MakeTrajectory. It reads its own keys (angles in degrees, times in
// seconds), converts angles to radians and returns an immutable Trajectory. Errors are
// InputError; those without a source get the JSON file's name added by MakeTrajectory.
#pragma once

#include "core/json_input.h"
#include "core/trajectory.h"

#include <initializer_list>
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

// Marks `keys` as known (whether present or not) and rejects every other key, before any
// value is looked at. Factories call it first so that a misspelt key is reported as
// unknown at its own pointer, rather than as "required key is missing" for the key the
// user meant to write, or silently ignored when the key is optional.
inline void AcceptOnlyKeys(ObjectReader& reader, std::initializer_list<const char*> keys) {
  for (const char* key : keys) reader.Find(key);
  reader.Finish();
}

// A number for error messages, 12 significant digits ("0.5", "1e-07").
std::string FormatNumber(double x);

}  // namespace trajectory_detail
}  // namespace armfault
