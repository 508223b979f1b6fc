// The fault families: one line each. A new family is a new file plus a line here.
#include "core/base/suggest.h"
#include "faults/family_support.h"

namespace armfault {

namespace {

struct Family {
  const char* name;
  FaultFactory make;
  const char* magnitude_key;  // the parameter that sizes a fault of this family
  bool needs_motion;          // its signature shows only while the joint moves (fault.h)
  bool discrete;              // present or absent (a lead, a short), not graded by a magnitude
};

const Family kFamilies[] = {
    {"kt_degradation", &MakeKtDegradation, "kt_factor", true, false},
    {"friction_increase", &MakeFrictionIncrease, "friction_factor", true, false},
    {"brake_lock", &MakeBrakeLock, "drag_fraction", true, false},
    {"torque_sensor_stuck", &MakeTorqueSensorStuck, "", false, true},
    {"inverter_short", &MakeInverterShort, "resistance_ohm", false, true},
    {"winding_resistance", &MakeWindingResistance, "resistance_factor", false, false},
    {"torque_sensor_drift", &MakeTorqueSensorDrift, "drift_Nm_per_s", false, false},
};

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

std::unique_ptr<Fault> MakeFault(const nlohmann::json& spec, const std::string& pointer, const RobotConfig& robot) {
  ObjectReader reader(spec, pointer);
  const std::string family = reader.RequireString("family");
  for (const Family& f : kFamilies) {
    if (family != f.name) continue;
    try {
      return f.make(reader, robot);
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
