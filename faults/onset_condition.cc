// Conditional onsets (onset_condition.h): one of the shared pieces of the fault families, like
// fault.cc; it uses fault.cc's ReadJointIndex and calls nothing in registry.cc or a family file.
#include "faults/onset_condition.h"

#include <cmath>
#include <limits>
#include <vector>

#include "core/base/json_input.h"
#include "faults/family_support.h"
#include "faults/fault.h"

namespace armfault {

namespace {

const char* const kWhenNames = "joint_velocity_above, joint_position_crosses, after_reversals";

std::string JointText(int joint_index) { return "joint " + std::to_string(joint_index + 1); }

}  // namespace

std::string OnsetCondition::Text() const {
  std::string s;
  switch (when) {
    case OnsetWhen::kJointVelocityAbove:
      s = JointText(joint_index) + "'s |velocity| above " + FormatNumber(rad_s) + " rad/s";
      break;
    case OnsetWhen::kJointPositionCrosses:
      s = JointText(joint_index) + "'s position crossing " + FormatNumber(position_rad * 180.0 / M_PI) + " deg" +
          (direction > 0 ? " rising" : direction < 0 ? " falling" : "");
      break;
    case OnsetWhen::kAfterReversals:
      s = JointText(joint_index) + "'s reversal " + std::to_string(count) + " (deadband " + FormatNumber(deadband_rad_s) +
          " rad/s)";
      break;
  }
  if (not_before_s > 0) s += " from " + FormatNumber(not_before_s) + " s on";
  if (delay_s > 0) s += ", + " + FormatNumber(delay_s) + " s";
  return s;
}

OnsetCondition ReadOnsetCondition(const nlohmann::json& value, const std::string& pointer, const RobotConfig& robot) {
  if (!value.is_object()) {
    throw InputError("", pointer,
                     "expected a condition object {\"when\": \"...\", \"joint\": N, ...} (or a list of them in a campaign), got " +
                         Describe(value));
  }
  ObjectReader reader(value, pointer);
  ErrorList errors;
  OnsetCondition c;
  c.input = value;
  std::string when;
  const bool when_ok = errors.Try([&] {
    when = reader.RequireString("when");
    if (when == "joint_velocity_above") {
      c.when = OnsetWhen::kJointVelocityAbove;
    } else if (when == "joint_position_crosses") {
      c.when = OnsetWhen::kJointPositionCrosses;
    } else if (when == "after_reversals") {
      c.when = OnsetWhen::kAfterReversals;
    } else {
      throw InputError("", reader.PointerTo("when"), "unknown condition \"" + when + "\" (known: " + kWhenNames + ")");
    }
  });
  std::vector<std::string> keys = {"when", "joint", "delay_s", "not_before_s"};
  const bool velocity = when_ok && c.when == OnsetWhen::kJointVelocityAbove;
  const bool crosses = when_ok && c.when == OnsetWhen::kJointPositionCrosses;
  const bool reversals = when_ok && c.when == OnsetWhen::kAfterReversals;
  // With an unknown "when" every condition's keys are accepted: the error is the "when".
  if (velocity || !when_ok) keys.push_back("rad_s");
  if (crosses || !when_ok) keys.insert(keys.end(), {"deg", "rad", "direction"});
  if (reversals || !when_ok) keys.insert(keys.end(), {"count", "deadband_rad_s"});
  errors.Try([&] {
    try {
      reader.AllowOnly(keys);
    } catch (const InputError& e) {
      if (!when_ok) throw;
      // Name the condition: "rad_s" is a key of another condition, not a typo.
      std::vector<InputError> named;
      for (const InputError& one : e.errors()) {
        named.push_back(one.Edited([&](std::string*, std::string*, std::string* message) {
          *message = when + ": " + *message;
        }));
      }
      throw InputError(named);
    }
  });
  bool joint_ok = false;
  errors.Try([&] {
    if (!reader.ShouldRead("joint")) return;
    c.joint_index = ReadJointIndex(reader, robot);
    joint_ok = true;
  });
  errors.Try([&] {
    reader.OptionalNumber("delay_s", &c.delay_s);
    RequireAtLeast(c.delay_s, 0.0, reader.PointerTo("delay_s"));
  });
  errors.Try([&] {
    reader.OptionalNumber("not_before_s", &c.not_before_s);
    RequireAtLeast(c.not_before_s, 0.0, reader.PointerTo("not_before_s"));
  });
  if (velocity) {
    errors.Try([&] {
      if (!reader.ShouldRead("rad_s")) return;
      c.rad_s = reader.RequireNumber("rad_s");
      RequireAtLeast(c.rad_s, 0.0, reader.PointerTo("rad_s"));
    });
  }
  if (crosses) {
    errors.Try([&] {
      const bool deg = reader.Has("deg"), rad = reader.Has("rad");
      if (deg && rad) {
        throw InputError("", reader.PointerTo("rad"),
                         "joint_position_crosses takes one of deg or rad, not both (" + reader.PointerTo("deg") + " is given)");
      }
      if (!deg && !rad) {
        if (!reader.ShouldRead("deg")) return;
        throw InputError("", pointer, "joint_position_crosses needs the position crossed: \"deg\" or \"rad\"");
      }
      const std::string key = deg ? "deg" : "rad";
      const double x = reader.RequireNumber(key);
      c.position_rad = deg ? x * M_PI / 180.0 : x;
      if (joint_ok) {
        const ModuleParams& m = robot.modules[static_cast<size_t>(c.joint_index)];
        const double x_deg = c.position_rad * 180.0 / M_PI;
        if (x_deg < m.min_angle_deg || x_deg > m.max_angle_deg) {
          throw InputError("", reader.PointerTo(key),
                           FormatNumber(x) + " " + key + " is outside joint " + std::to_string(c.joint_index + 1) +
                               "'s range [" + FormatNumber(m.min_angle_deg) + ", " + FormatNumber(m.max_angle_deg) +
                               "] deg: it can never be crossed");
        }
      }
    });
    errors.Try([&] {
      std::string direction = "either";
      reader.OptionalString("direction", &direction);
      if (direction == "either") {
        c.direction = 0;
      } else if (direction == "rising") {
        c.direction = 1;
      } else if (direction == "falling") {
        c.direction = -1;
      } else {
        throw InputError("", reader.PointerTo("direction"),
                         "unknown direction \"" + direction + "\" (known: either, rising, falling)");
      }
    });
  }
  if (reversals) {
    errors.Try([&] {
      if (!reader.ShouldRead("count")) return;
      c.count = reader.RequireInt("count");
      if (c.count < 1) {
        throw InputError("", reader.PointerTo("count"), "count must be at least 1, got " + std::to_string(c.count));
      }
    });
    errors.Try([&] {
      reader.OptionalNumber("deadband_rad_s", &c.deadband_rad_s);
      RequireAbove(c.deadband_rad_s, 0.0, reader.PointerTo("deadband_rad_s"));
    });
  }
  errors.ThrowIfAny();
  return c;
}

bool OnsetWatcher::Observe(double t_s, const JointTick& joint) {
  if (fired_ || t_s < c_.not_before_s) return false;
  bool now = false;
  switch (c_.when) {
    case OnsetWhen::kJointVelocityAbove:
      now = std::fabs(joint.qd_rad_s) > c_.rad_s;
      break;
    case OnsetWhen::kJointPositionCrosses: {
      const double x = c_.position_rad, q = joint.q_rad;
      if (has_previous_) {
        const bool rising = previous_q_rad_ < x && q >= x;
        const bool falling = previous_q_rad_ > x && q <= x;
        now = c_.direction > 0 ? rising : c_.direction < 0 ? falling : rising || falling;
      }
      has_previous_ = true;
      previous_q_rad_ = q;
      break;
    }
    case OnsetWhen::kAfterReversals: {
      const double v = joint.qd_rad_s;
      const int sign = v > c_.deadband_rad_s ? 1 : v < -c_.deadband_rad_s ? -1 : sign_;
      if (sign_ != 0 && sign != sign_) now = ++reversals_ >= c_.count;
      sign_ = sign;
      break;
    }
  }
  fired_ = now;
  return now;
}

void Fault::FireOnset(double fired_s) {
  timing_.fired_s = fired_s;
  timing_.onset_s = fired_s + timing_.condition->delay_s;
}

std::string NotInjectedReason(const Fault& fault, double end_s) {
  const FaultTiming& t = fault.timing();
  if (!t.condition) return "";
  if (std::isnan(t.fired_s)) return "the onset condition never fired: " + t.condition->Text();
  if (t.onset_s > end_s) {
    return "the onset condition fired at " + FormatNumber(RoundToMicroseconds(t.fired_s)) + " s, but its onset " +
           FormatNumber(RoundToMicroseconds(t.onset_s)) + " s is after the run's end (" + FormatNumber(end_s) + " s)";
  }
  return "";
}

int ResolveConditionalOnsets(const ArmModel& model, const RunSpec& run, const std::vector<Fault*>& faults) {
  std::vector<Fault*> pending;
  for (Fault* f : faults) {
    if (f->timing().condition && std::isnan(f->timing().fired_s)) pending.push_back(f);
  }
  int passes = 0;
  // Each pass runs the plant with the resolved faults acting and the pending ones not yet.
  // Until the earliest onset among the conditions fired in it, the pass is exactly the real
  // run, so every condition that fired by then is resolved; a pass ends there (a condition
  // that fires later might have seen the plant under that fault).
  while (!pending.empty()) {
    ++passes;
    std::vector<std::shared_ptr<const Fault>> acting;
    for (Fault* f : faults) acting.push_back(std::shared_ptr<const Fault>(f, [](const Fault*) {}));
    RunSpec spec = run;
    spec.hardware = std::make_shared<FaultSchedule>(acting);
    std::vector<OnsetWatcher> watchers;
    watchers.reserve(pending.size());
    for (Fault* f : pending) watchers.emplace_back(*f->timing().condition);
    std::vector<double> fired(pending.size(), std::numeric_limits<double>::quiet_NaN());
    double earliest_onset = std::numeric_limits<double>::infinity();
    bool done = false;
    spec.stop = [&] { return done; };
    Simulate(model, spec, [&](const Tick& tick) {
      for (size_t k = 0; k < pending.size(); ++k) {
        const OnsetCondition& c = *pending[k]->timing().condition;
        if (watchers[k].Observe(tick.t_s, (*tick.joints)[static_cast<size_t>(c.joint_index)])) {
          fired[k] = tick.t_s;
          earliest_onset = std::min(earliest_onset, tick.t_s + c.delay_s);
        }
      }
      done = tick.t_s >= earliest_onset;
    });
    std::vector<Fault*> still;
    for (size_t k = 0; k < pending.size(); ++k) {
      if (!std::isnan(fired[k]) && fired[k] <= earliest_onset) {
        pending[k]->FireOnset(fired[k]);
      } else if (std::isfinite(earliest_onset)) {
        still.push_back(pending[k]);  // watched again with the resolved faults acting
      }
    }
    pending = std::move(still);
  }
  return passes;
}

}  // namespace armfault
