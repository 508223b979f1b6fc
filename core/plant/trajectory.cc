#include "core/plant/trajectory.h"

#include "core/base/json_input.h"
#include "core/plant/trajectories/trajectories.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

double Trajectory::shortest_period_s() const { return std::numeric_limits<double>::infinity(); }

MotionEnvelope SampleMotion(const Trajectory& trajectory, double duration_s) {
  MotionEnvelope envelope;
  bool first = true;
  auto add = [&](const TrajectoryPoint& p) {
    if (!std::isfinite(p.q_rad) || !std::isfinite(p.qd_rad_s) || !std::isfinite(p.qdd_rad_s2)) {
      envelope.finite = false;
      return;
    }
    envelope.min_rad = first ? p.q_rad : std::min(envelope.min_rad, p.q_rad);
    envelope.max_rad = first ? p.q_rad : std::max(envelope.max_rad, p.q_rad);
    envelope.peak_speed_rad_s = std::max(envelope.peak_speed_rad_s, std::fabs(p.qd_rad_s));
    envelope.peak_acceleration_rad_s2 = std::max(envelope.peak_acceleration_rad_s2, std::fabs(p.qdd_rad_s2));
    first = false;
  };
  // A non-finite duration would sample forever: a caller's bug, not a user input error.
  if (!std::isfinite(duration_s)) {
    throw std::invalid_argument("SampleMotion: duration must be finite");
  }
  add(trajectory.At(0.0));
  if (duration_s <= 0.0) return envelope;  // only t = 0 lies in [0, duration]
  // t = k / 1000 from an integer counter, so no rounding error accumulates over long runs.
  for (long long k = 1;; ++k) {
    const double t = static_cast<double>(k) / 1000.0;
    if (t > duration_s) break;
    add(trajectory.At(t));
  }
  add(trajectory.At(duration_s));  // the end, when not a multiple of 1 ms
  return envelope;
}

}  // namespace armfault
