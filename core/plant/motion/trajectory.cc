#include "core/plant/motion/trajectory.h"

#include "core/base/json_input.h"
#include "core/plant/motion/trajectories.h"

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

// The registry. Adding a type = one file in core/plant/motion/ (declared in
// trajectories.h) + one line here. The order is the order shown to users.
constexpr TrajectoryType kTypes[] = {
    {"sine_pair", MakeSinePair},
    {"cosine_ramp", MakeCosineRamp},
    {"min_jerk", MakeMinJerk},
    {"hold", MakeHold},
    {"csv", MakeCsv},
};

// A repeating work cycle: the inner trajectory's first `period_s` seconds, again and
// again: At(t) = inner.At(t mod period).
class Cycle final : public Trajectory {
 public:
  Cycle(std::unique_ptr<Trajectory> inner, double period_s) : inner_(std::move(inner)), period_s_(period_s) {}
  TrajectoryPoint At(double t_s) const override {
    if (t_s < 0) return inner_->At(t_s);
    // The cycle count from a floor, so t in [k P, (k+1) P) maps to [0, P) without drift.
    const double k = std::floor(t_s / period_s_);
    return inner_->At(std::max(0.0, t_s - k * period_s_));
  }
  const char* type() const override { return inner_->type(); }
  double shortest_period_s() const override { return std::min(period_s_, inner_->shortest_period_s()); }

 private:
  std::unique_ptr<Trajectory> inner_;
  double period_s_;
};

// How closely a cycle must return to its start (docs/assumptions.md): angle and velocity.
constexpr double kCycleAngleTolerance_rad = 1e-6;
constexpr double kCycleSpeedTolerance_rad_s = 1e-5;
constexpr double kMaxCyclePeriod_s = 86400;

// `spec` with "cycle" (and "cycle_period_s"): the trajectory without them, repeated. Throws
// InputError when the cycle does not return to its start angle and velocity.
std::unique_ptr<Trajectory> MakeCycle(const nlohmann::json& spec, const std::string& pointer, const InputContext& context);

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
  if (spec.is_object() && (spec.contains("cycle") || spec.contains("cycle_period_s"))) {
    try {
      return MakeCycle(spec, pointer, context);
    } catch (const InputError& e) {
      throw e.WithSource(context.source);
    }
  }
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

namespace {

std::unique_ptr<Trajectory> MakeCycle(const nlohmann::json& spec, const std::string& pointer, const InputContext& context) {
  const std::string cycle_ptr = PointerJoin(pointer, "cycle");
  const std::string period_ptr = PointerJoin(pointer, "cycle_period_s");
  const nlohmann::json* cycle = spec.contains("cycle") ? &spec.at("cycle") : nullptr;
  if (cycle == nullptr) {
    throw InputError("", period_ptr, "cycle_period_s needs \"cycle\": true beside it");
  }
  if (!cycle->is_boolean()) throw InputError("", cycle_ptr, "expected true or false, got " + Describe(*cycle));
  nlohmann::json inner = spec;
  inner.erase("cycle");
  inner.erase("cycle_period_s");
  if (!cycle->get<bool>()) {
    if (spec.contains("cycle_period_s")) {
      throw InputError("", period_ptr, "cycle_period_s is given but \"cycle\" is false");
    }
    return MakeTrajectory(inner, pointer, context);
  }
  ErrorList errors;
  double period_s = 0;
  errors.Try([&] {
    if (!spec.contains("cycle_period_s")) {
      throw InputError("", period_ptr, "required with \"cycle\": true: the length [s] of the motion that repeats");
    }
    period_s = AsNumber(spec.at("cycle_period_s"), period_ptr);
    RequireAbove(period_s, 0.0, period_ptr);
    RequireInRange(period_s, 0.0, kMaxCyclePeriod_s, period_ptr);
  });
  std::unique_ptr<Trajectory> made;
  errors.Try([&] { made = MakeTrajectory(inner, pointer, context); });
  errors.ThrowIfAny();
  // A cycle must return to where it started, at the same velocity: otherwise the reference
  // jumps at every repeat, which no joint can follow.
  const TrajectoryPoint start = made->At(0.0), end = made->At(period_s);
  const double dq = end.q_rad - start.q_rad, dqd = end.qd_rad_s - start.qd_rad_s;
  if (!(std::fabs(dq) <= kCycleAngleTolerance_rad && std::fabs(dqd) <= kCycleSpeedTolerance_rad_s)) {
    throw InputError("", cycle_ptr,
                     "the cycle does not return to its start after cycle_period_s = " + FormatNumber(period_s) +
                         " s: angle " + FormatNumber(end.q_rad * 180.0 / M_PI) + " deg vs " +
                         FormatNumber(start.q_rad * 180.0 / M_PI) + " deg at t = 0 (mismatch " +
                         FormatNumber(dq * 180.0 / M_PI) + " deg), velocity " + FormatNumber(end.qd_rad_s * 180.0 / M_PI) +
                         " deg/s vs " + FormatNumber(start.qd_rad_s * 180.0 / M_PI) + " deg/s (mismatch " +
                         FormatNumber(dqd * 180.0 / M_PI) + " deg/s); allowed: 1e-6 rad and 1e-5 rad/s");
  }
  return std::make_unique<Cycle>(std::move(made), period_s);
}

}  // namespace

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
