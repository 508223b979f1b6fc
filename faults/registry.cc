// The fault families: one line each. A new family is a new file plus a line here.
// Dependencies go one way: this table uses the family files and the shared pieces (fault.cc,
// onset_condition.cc, family_support.h); they never call back into it. A family gets its
// magnitude's key and range from its line here as a parameter of its factory (MakeFault).
#include <cstdio>

#include "core/base/suggest.h"
#include "faults/family_support.h"

namespace armfault {

namespace {

// How a magnitude m becomes a severity s (FaultSeverity), and back.
enum class Severity {
  kMagnitude,  // s = m (a drag fraction, a drift rate)
  kLoss,       // s = 1 - m (a factor below nominal)
  kGain,       // s = m - 1 (a factor above nominal)
  kInverse,    // s = 1 / m (a short's conductance from its resistance)
};

struct Family {
  const char* name;
  FaultFactory make;
  const char* magnitude_key;   // the parameter that sizes a fault of this family
  const char* magnitude_unit;  // its unit, for axis labels ("" if none)
  Severity severity;           // of a magnitude
  bool needs_motion;           // its signature shows only while the joint moves (fault.h)
  bool discrete;               // present or absent (a lead, a short), not graded by a magnitude
  const char* color;           // the family's colour in every plot of the report
  FaultMagnitudeRange range;   // of the magnitude (unused without a magnitude key)
  bool needs_torque_sensor = false;  // an error on a joint without one (robot_config.h)
};

const Family kFamilies[] = {
    {"kt_degradation", &MakeKtDegradation, "kt_factor", "× nominal K_T", Severity::kLoss, true, false, "#1f77b4", {0, 1, true, false}},
    {"friction_increase", &MakeFrictionIncrease, "friction_factor", "× nominal friction", Severity::kGain, true, false,
     "#ff7f0e", {1, 100, false, false}},
    {"brake_lock", &MakeBrakeLock, "drag_fraction", "× brake holding torque", Severity::kMagnitude, true, false, "#2ca02c", {0, 1, true, false}},
    {"torque_sensor_stuck", &MakeTorqueSensorStuck, "", "", Severity::kMagnitude, false, true, "#d62728", {}, true},
    {"inverter_short", &MakeInverterShort, "resistance_ohm", "Ω", Severity::kInverse, false, true, "#9467bd", {0.001, 1000, false, false}},
    {"winding_resistance", &MakeWindingResistance, "resistance_factor", "× nominal winding resistance", Severity::kGain,
     false, false, "#8c564b", {1, 20, false, false}},
    {"torque_sensor_drift", &MakeTorqueSensorDrift, "drift_Nm_per_s", "N m/s", Severity::kMagnitude, false, false,
     "#e377c2", {-100, 100, false, true}, true},
};

// The family sized by `magnitude_key`; nullptr if none.
const Family* FamilyOfMagnitude(const std::string& magnitude_key) {
  for (const Family& f : kFamilies) {
    if (!magnitude_key.empty() && magnitude_key == f.magnitude_key) return &f;
  }
  return nullptr;
}

}  // namespace

std::vector<std::string> FaultFamilyNames() {
  std::vector<std::string> names;
  for (const Family& f : kFamilies) names.push_back(f.name);
  return names;
}

std::string FaultMagnitudeKey(const std::string& family) {
  for (const Family& f : kFamilies) {
    if (family == f.name) return f.magnitude_key;
  }
  return "";
}

bool FaultMagnitudeRangeOf(const std::string& family, FaultMagnitudeRange* range) {
  for (const Family& f : kFamilies) {
    if (family != f.name || *f.magnitude_key == '\0') continue;
    *range = f.range;
    return true;
  }
  return false;
}

std::string FaultMagnitudeRangeText(const std::string& family) {
  FaultMagnitudeRange r;
  if (!FaultMagnitudeRangeOf(family, &r)) return "";
  // Typographic minus, as the docs write a negative bound.
  auto number = [](double x) { return x < 0 ? "−" + FormatNumber(-x) : FormatNumber(x); };
  return number(r.min) + (r.min_exclusive ? " < `" : " ≤ `") + FaultMagnitudeKey(family) + "` ≤ " +
         number(r.max) + (r.zero_excluded ? ", ≠ 0" : "");
}

std::string FaultMagnitudeUnit(const std::string& magnitude_key) {
  const Family* f = FamilyOfMagnitude(magnitude_key);
  return f ? f->magnitude_unit : "";
}

double FaultSeverity(const std::string& magnitude_key, double m) {
  const Family* f = FamilyOfMagnitude(magnitude_key);
  switch (f ? f->severity : Severity::kMagnitude) {
    case Severity::kLoss: return 1 - m;
    case Severity::kGain: return m - 1;
    case Severity::kInverse: return 1 / m;
    case Severity::kMagnitude: break;
  }
  return m;
}

double FaultMagnitudeOfSeverity(const std::string& magnitude_key, double s) {
  const Family* f = FamilyOfMagnitude(magnitude_key);
  switch (f ? f->severity : Severity::kMagnitude) {
    case Severity::kLoss: return 1 - s;
    case Severity::kGain: return 1 + s;
    case Severity::kInverse: return 1 / s;
    case Severity::kMagnitude: break;
  }
  return s;
}

std::string FaultFamilyColor(const std::string& family) {
  for (const Family& f : kFamilies) {
    if (family == f.name) return f.color;
  }
  return "";
}

bool FaultNeedsMotion(const std::string& family) {
  for (const Family& f : kFamilies) {
    if (family == f.name) return f.needs_motion;
  }
  return false;
}

bool FaultIsDiscrete(const std::string& family) {
  for (const Family& f : kFamilies) {
    if (family == f.name) return f.discrete;
  }
  return false;
}

std::string NotExcitedReason(const Fault& fault, const FaultEffect& effect) {
  if (FaultNeedsMotion(fault.family()) && effect.joint_travel_rad < kMinTravelToExcite_rad) {
    char travel[32];
    std::snprintf(travel, sizeof travel, "%.3g", effect.joint_travel_rad);
    return "joint " + std::to_string(fault.joint_index() + 1) + " was asked to move " + travel + " rad after the onset (less than " +
           FormatNumber(kMinTravelToExcite_rad) + " rad), and " + fault.family() + " shows only in motion";
  }
  if (!effect.took_effect && (!effect.measured || FaultIsDiscrete(fault.family()))) {
    return "the fault took no effect: " + effect.note;
  }
  return "";
}

std::unique_ptr<Fault> MakeFault(const nlohmann::json& spec, const std::string& pointer, const RobotConfig& robot) {
  ObjectReader reader(spec, pointer);
  const std::string family = reader.RequireString("family");
  for (const Family& f : kFamilies) {
    if (family != f.name) continue;
    try {
      std::unique_ptr<Fault> fault = f.make(reader, robot, FaultMagnitudeSpec{f.name, f.magnitude_key, f.range});
      const int j = fault->joint_index();
      if (f.needs_torque_sensor && j >= 0 && j < static_cast<int>(robot.modules.size()) &&
          !robot.modules[j].torque_sensor.present) {
        const std::string name = j < static_cast<int>(robot.bodies.size()) ? " (" + robot.bodies[j].joint_name + ")" : "";
        throw InputError("", reader.PointerTo("joint"),
                         "joint " + std::to_string(j + 1) + name + " has no torque sensor (robot " + robot.name +
                             "): this family needs one");
      }
      return fault;
    } catch (const InputError& e) {
      // Each error the family found (there may be several unknown keys) names the family.
      throw e.Edited([&](std::string*, std::string*, std::string* message) { *message = family + ": " + *message; });
    }
  }
  std::string known;
  for (const std::string& name : FaultFamilyNames()) known += (known.empty() ? "" : ", ") + name;
  const std::string near = NearestWord(family, FaultFamilyNames());
  throw InputError("", reader.PointerTo("family"), "unknown fault family \"" + family + "\" (known: " + known + ")",
                   near.empty() ? "" : "did you mean \"" + near + "\"?");
}

std::vector<std::unique_ptr<Fault>> MakeFaults(const nlohmann::json& specs, const std::string& pointer,
                                               const RobotConfig& robot) {
  if (!specs.is_array()) throw InputError("", pointer, "expected an array of faults, got " + Describe(specs));
  std::vector<std::unique_ptr<Fault>> faults;
  ErrorList errors;  // each fault on its own: all bad ones are reported
  for (size_t i = 0; i < specs.size(); ++i) {
    errors.Try([&] { faults.push_back(MakeFault(specs[i], PointerJoin(pointer, i), robot)); });
  }
  errors.ThrowIfAny();
  return faults;
}

}  // namespace armfault
