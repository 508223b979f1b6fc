#include "core/plant/trajectory.h"

#include "core/base/json_input.h"
#include "core/plant/trajectories/trajectories.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace armfault {

namespace {

using Factory = std::unique_ptr<Trajectory> (*)(ObjectReader& reader, const InputContext& ctx);

struct TrajectoryType {
  const char* name;
  Factory make;
};

// The registry. Adding a type = one file in core/plant/trajectories/ (declared in
// trajectories.h) + one line here. The order is the order shown to users.
constexpr TrajectoryType kTypes[] = {
    {"sine_pair", MakeSinePair},
    {"cosine_ramp", MakeCosineRamp},
    {"min_jerk", MakeMinJerk},
    {"hold", MakeHold},
    {"csv", MakeCsv},
};

std::string KnownTypesText() {
  std::string text;
  for (const TrajectoryType& t : kTypes) {
    if (!text.empty()) text += ", ";
    text += t.name;
  }
  return text;
}

}  // namespace

std::unique_ptr<Trajectory> MakeTrajectory(const nlohmann::json& spec, const std::string& pointer,
                                           const InputContext& context) {
  try {
    ObjectReader reader(spec, pointer);
    if (!reader.Has("type")) {
      throw InputError("", reader.PointerTo("type"),
                       "required key is missing; known types: " + KnownTypesText());
    }
    const std::string name = reader.RequireString("type");
    for (const TrajectoryType& t : kTypes) {
      if (name == t.name) return t.make(reader, context);
    }
    throw InputError("", reader.PointerTo("type"),
                     "unknown trajectory type " + Describe(spec.at("type")) +
                         "; known types: " + KnownTypesText());
  } catch (const InputError& e) {
    // The JSON helpers do not know the file name; errors from a CSV file carry their own.
    throw e.WithSource(context.source);
  }
}

std::vector<std::string> TrajectoryTypeNames() {
  std::vector<std::string> names;
  for (const TrajectoryType& t : kTypes) names.emplace_back(t.name);
  return names;
}

AngleRange SampleRange(const Trajectory& trajectory, double duration_s) {
  const double q0 = trajectory.At(0.0).q_rad;
  AngleRange range{q0, q0};
  auto add = [&range](double q) {
    range.min_rad = std::min(range.min_rad, q);
    range.max_rad = std::max(range.max_rad, q);
  };
  // A non-finite duration would sample forever: a caller's bug, not a user input error.
  if (!std::isfinite(duration_s)) {
    throw std::invalid_argument("SampleRange: duration must be finite");
  }
  if (duration_s <= 0.0) return range;  // only t = 0 lies in [0, duration]
  // t = k / 1000 from an integer counter, so no rounding error accumulates over long runs.
  for (long long k = 1;; ++k) {
    const double t = static_cast<double>(k) / 1000.0;
    if (t > duration_s) break;
    add(trajectory.At(t).q_rad);
  }
  add(trajectory.At(duration_s).q_rad);  // the end, when not a multiple of 1 ms
  return range;
}

}  // namespace armfault
