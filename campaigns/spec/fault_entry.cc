#include <algorithm>
#include <map>

#include "campaigns/spec/spec_parse.h"
#include "faults/fault.h"

namespace armfault {
namespace spec_parse {

ParsedSweep ParseSweep(const nlohmann::json& v, const std::string& pointer, bool numbers_only) {
  ParsedSweep p;
  p.sweep.pointer = pointer;
  auto check_element = [&](const nlohmann::json& e, const std::string& ptr) {
    if (e.is_number()) return;
    if (!numbers_only && (e.is_string() || e.is_boolean())) return;
    throw InputError("", ptr, std::string("expected ") + (numbers_only ? "a number" : "a number or a string") +
                                  ", got " + Describe(e));
  };
  if (v.is_array()) {
    if (v.empty()) throw InputError("", pointer, "empty sweep: give at least one value");
    ErrorList errors;  // every bad element is reported
    for (size_t i = 0; i < v.size(); ++i) {
      errors.Try([&] { check_element(v[i], PointerJoin(pointer, i)); });
      p.sweep.values.push_back(v[i]);
    }
    errors.ThrowIfAny();
    p.swept = true;
    return p;
  }
  if (v.is_object()) {
    ObjectReader reader(v, pointer);
    reader.AllowOnly({"from", "to", "steps", "uniform"});
    if (const auto* u = reader.Find("uniform")) {
      if (reader.Has("from") || reader.Has("to") || reader.Has("steps")) {
        throw InputError("", pointer, "give either {\"uniform\": [a, b]} or {\"from\", \"to\", \"steps\"}, not both");
      }
      const std::string up = reader.PointerTo("uniform");
      if (!u->is_array() || u->size() != 2) throw InputError("", up, "expected [low, high], got " + Describe(*u));
      ErrorList errors;  // both bounds are checked before their order
      errors.Try([&] { p.sweep.low = AsNumber((*u)[0], PointerJoin(up, 0)); });
      errors.Try([&] { p.sweep.high = AsNumber((*u)[1], PointerJoin(up, 1)); });
      errors.ThrowIfAny();
      if (p.sweep.low > p.sweep.high) {
        throw InputError("", PointerJoin(up, 0),
                         "low " + FormatNumber(p.sweep.low) + " is greater than high " + FormatNumber(p.sweep.high));
      }
      p.sweep.uniform = true;
      p.swept = true;
      return p;
    }
    double from = 0, to = 0;
    int steps = 0;
    ErrorList errors;  // all three keys are checked before the grid is
    errors.Try([&] { from = reader.RequireNumber("from"); });
    errors.Try([&] { to = reader.RequireNumber("to"); });
    errors.Try([&] { steps = reader.RequireInt("steps"); });
    errors.ThrowIfAny();
    if (from > to) {
      throw InputError("", reader.PointerTo("from"),
                       FormatNumber(from) + " is greater than \"to\" (" + FormatNumber(to) + ")");
    }
    RequireInRange(steps, from == to ? 1 : 2, 100000, reader.PointerTo("steps"));
    for (int i = 0; i < steps; ++i) {
      const double x = steps == 1 ? from : (i == steps - 1 ? to : from + (to - from) * i / (steps - 1));
      p.sweep.values.push_back(x);
    }
    p.sweep.grid = true;
    p.swept = true;
    return p;
  }
  check_element(v, pointer);
  p.sweep.values.push_back(v);
  return p;
}


namespace {

FaultEntry ParseCompoundEntry(const nlohmann::json& v, const std::string& pointer, const RobotConfig* robot);

// The "onset" key of a fault entry: a condition object (one value) or a non-empty list of
// them (a sweep); the conditions themselves are checked by the family (faults/onset_condition.h).
ParsedSweep ParseOnsetSweep(const nlohmann::json& v, const std::string& pointer) {
  ParsedSweep p;
  p.sweep.pointer = pointer;
  if (v.is_object()) {
    p.sweep.values.push_back(v);
    return p;
  }
  if (!v.is_array() || v.empty()) {
    throw InputError("", pointer,
                     "expected a condition {\"when\": ..., \"joint\": ...} or a non-empty list of them (a time goes in "
                     "onset_s), got " + Describe(v));
  }
  ErrorList errors;
  for (size_t i = 0; i < v.size(); ++i) {
    errors.Try([&] {
      if (!v[i].is_object()) {
        throw InputError("", PointerJoin(pointer, i), "expected a condition {\"when\": ..., \"joint\": ...}, got " + Describe(v[i]));
      }
    });
    p.sweep.values.push_back(v[i]);
  }
  errors.ThrowIfAny();
  p.swept = true;
  return p;
}

// A value's own pointer inside a sweep: the list element, the grid end or the uniform bound.
std::string ValuePointer(const Sweep& s, size_t index, bool swept) {
  if (!swept) return s.pointer;
  if (s.uniform) return PointerJoin(PointerJoin(s.pointer, "uniform"), index);
  if (s.grid) {
    if (index == 0) return PointerJoin(s.pointer, "from");
    if (index + 1 == s.values.size()) return PointerJoin(s.pointer, "to");
    return s.pointer;
  }
  return PointerJoin(s.pointer, index);
}

// The family still names the keys it does not know: it rejects them before reading any value,
// so a probe with every key null and a valid joint gives exactly those errors (into `errors`).
void AddUnknownKeyErrors(const nlohmann::json& v, const std::string& pointer, const std::string& family,
                         const RobotConfig* robot, ErrorList* errors) {
  nlohmann::json probe = {{"family", family}, {"joint", 1}};
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (it.key() != "family" && it.key() != "joint") probe[it.key()] = nullptr;
  }
  try {
    MakeFault(probe, pointer, robot ? *robot : RobotPreset("mrr-config1"));
  } catch (const InputError& err) {
    for (const InputError& one : err.errors()) {
      for (auto it = probe.begin(); it != probe.end(); ++it) {
        if (one.pointer() == PointerJoin(pointer, it.key()) &&
            one.message() == family + ": unknown key \"" + it.key() + "\"") {
          errors->Add(one);
        }
      }
    }
  }
}

// Each value of a parsed entry (`joints` and every key's values, `swept` per key) through the
// family's own checks on `robot`, its errors into `errors`.
void CheckEntryValues(const FaultEntry& e, const ParsedSweep& joints, const std::vector<bool>& swept,
                      const RobotConfig& robot, ErrorList* errors) {
  const std::string& pointer = e.pointer;
  // Each value on its own, through the family's own checks, with the others at their first
  // value; an error on the key is moved to the value's own pointer.
  auto spec_with = [&](size_t key_index, const nlohmann::json& value, int joint_number) {
    nlohmann::json spec = {{"family", e.family}, {"joint", joint_number}};
    for (size_t k = 0; k < e.keys.size(); ++k) {
      const Sweep& s = e.keys[k].second;
      spec[e.keys[k].first] = k == key_index ? value : (s.uniform ? nlohmann::json(s.low) : s.values[0]);
    }
    return spec;
  };
  // Where an error on a key belongs when every key sits at its first value.
  std::map<std::string, std::string> first_value_pointer = {
      {PointerJoin(pointer, "joint"), ValuePointer(joints.sweep, 0, joints.swept)}};
  for (size_t k = 0; k < e.keys.size(); ++k) {
    first_value_pointer[PointerJoin(pointer, e.keys[k].first)] = ValuePointer(e.keys[k].second, 0, swept[k]);
  }
  // Checks one value through the family's code and records its errors (ErrorList drops the
  // repeats of a bad first value). An error about another key would hide this value's own, so
  // that key is then left out (at its default) and the check repeated for this value's own
  // errors. Returns false if this value itself is bad.
  auto check = [&](nlohmann::json spec, const std::string& key_pointer, const std::string& value_pointer) {
    auto to_value = [&](std::string*, std::string* at, std::string*) {
      if (*at == key_pointer) {
        *at = value_pointer;
      } else if (const auto it = first_value_pointer.find(*at); it != first_value_pointer.end()) {
        *at = it->second;
      } else if (const size_t slash = at->rfind(pointer + "/", 0) == 0 ? at->find('/', pointer.size() + 1) : std::string::npos;
                 slash != std::string::npos) {
        // Inside a key's value (an onset condition's "joint"): under that value's own pointer.
        const std::string key = at->substr(0, slash), rest = at->substr(slash);
        if (key == key_pointer) {
          *at = value_pointer + rest;
        } else if (const auto k = first_value_pointer.find(key); k != first_value_pointer.end()) {
          *at = k->second + rest;
        }
      }
    };
    for (bool retry = false;; retry = true) {
      try {
        MakeFault(spec, pointer, robot);
        return true;
      } catch (const InputError& err) {
        bool own = false;
        std::vector<std::string> others;  // keys of the entry that the errors are about
        for (const InputError& one : err.errors()) {
          if (one.pointer() == key_pointer) own = true;
          for (const auto& key : e.keys) {
            if (one.pointer() == PointerJoin(pointer, key.first) && one.pointer() != key_pointer && spec.contains(key.first)) {
              others.push_back(key.first);
            }
          }
        }
        for (const InputError& one : err.errors()) {
          if (!retry || one.pointer() == key_pointer) errors->Add(one.Edited(to_value));
        }
        // The profile decides which timing keys apply: without it the check would mislead.
        const bool profile = std::find(others.begin(), others.end(), "profile") != others.end();
        if (own || others.empty() || profile) return !own;
        for (const std::string& key : others) spec.erase(key);
      }
    }
  };
  for (size_t j = 0; j < e.joints.size(); ++j) {
    check(spec_with(SIZE_MAX, nullptr, e.joints[j]), PointerJoin(pointer, "joint"), ValuePointer(joints.sweep, j, joints.swept));
  }
  for (size_t k = 0; k < e.keys.size(); ++k) {
    const Sweep& s = e.keys[k].second;
    const std::string kp = PointerJoin(pointer, e.keys[k].first);
    if (s.uniform) {
      check(spec_with(k, s.low, e.joints[0]), kp, ValuePointer(s, 0, true));
      check(spec_with(k, s.high, e.joints[0]), kp, ValuePointer(s, 1, true));
    } else if (s.grid) {
      // The ends first. The points between share the grid's pointer and fail anyway when an
      // end does, so they are checked only after both ends pass, up to the first bad one.
      auto check_point = [&](size_t i) { return check(spec_with(k, s.values[i], e.joints[0]), kp, ValuePointer(s, i, true)); };
      const size_t last = s.values.size() - 1;
      const bool from_ok = check_point(0);
      const bool to_ok = last == 0 || check_point(last);
      for (size_t i = 1; from_ok && to_ok && i < last; ++i) {
        if (!check_point(i)) break;
      }
    } else {
      for (size_t i = 0; i < s.values.size(); ++i) check(spec_with(k, s.values[i], e.joints[0]), kp, ValuePointer(s, i, swept[k]));
    }
  }
}

}  // namespace

// Reports every error of the entry it can find. Without a robot (the campaign's own is bad)
// only the entry's shape is checked: the family's checks need the robot's joints.
FaultEntry ParseFaultEntry(const nlohmann::json& v, const std::string& pointer, const RobotConfig* robot) {
  if (v.is_object() && v.contains("compound")) return ParseCompoundEntry(v, pointer, robot);
  ObjectReader reader(v, pointer);
  FaultEntry e;
  e.pointer = pointer;
  ErrorList errors;
  const bool family_ok = errors.Try([&] {
    e.family = reader.RequireString("family");
    const std::vector<std::string> families = FaultFamilyNames();
    if (std::find(families.begin(), families.end(), e.family) == families.end()) {
      MakeFault(v, pointer, RobotConfig());  // throws the registry's "unknown fault family" error
    }
  });
  ParsedSweep joints;
  const bool joints_ok = errors.Try([&] {
    const nlohmann::json& joint = reader.Require("joint");
    joints = ParseSweep(joint, reader.PointerTo("joint"), true);
    if (joints.sweep.uniform || (joint.is_object())) {
      throw InputError("", reader.PointerTo("joint"), "expected a joint number or a list of them, got " + Describe(joint));
    }
    ErrorList joint_errors;  // every bad joint number
    for (size_t i = 0; i < joints.sweep.values.size(); ++i) {
      joint_errors.Try([&] {
        e.joints.push_back(AsInt(joints.sweep.values[i], ValuePointer(joints.sweep, i, joints.swept)));
      });
    }
    joint_errors.ThrowIfAny();
  });
  std::vector<bool> swept;
  bool keys_ok = true;
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (it.key() == "family" || it.key() == "joint") continue;
    reader.Find(it.key());
    keys_ok &= errors.Try([&] {
      ParsedSweep p = it.key() == "onset" ? ParseOnsetSweep(it.value(), reader.PointerTo(it.key()))
                                          : ParseSweep(it.value(), reader.PointerTo(it.key()), false);
      e.keys.emplace_back(it.key(), p.sweep);
      swept.push_back(p.swept);
    });
  }
  // The family's checks below need a known family, the robot, and every key's values.
  if (!family_ok || !joints_ok || !keys_ok || robot == nullptr) {
    if (family_ok) AddUnknownKeyErrors(v, pointer, e.family, robot, &errors);
    errors.ThrowIfAny();
    return e;
  }
  CheckEntryValues(e, joints, swept, *robot, &errors);
  errors.ThrowIfAny();
  return e;
}

namespace {

// A compound entry: {"compound": [FAULT, FAULT, ...], "name": "..."} (docs/campaign-format.md,
// "Compound faults"). Each element is an ordinary fault with single values, checked by the
// ordinary entry parsing under its own pointer (/faults/2/compound/1/joint).
FaultEntry ParseCompoundEntry(const nlohmann::json& v, const std::string& pointer, const RobotConfig* robot) {
  ObjectReader reader(v, pointer);
  FaultEntry e;
  e.pointer = pointer;
  e.family = "compound";
  e.compound = true;
  ErrorList errors;
  errors.Try([&] { reader.AllowOnly({"compound", "name"}); });
  std::string default_name;
  errors.Try([&] {
    const nlohmann::json& list = reader.Require("compound");
    const std::string lp = reader.PointerTo("compound");
    if (!list.is_array() || list.size() < 2) {
      throw InputError("", lp, "expected a list of at least 2 faults that act together, got " + Describe(list));
    }
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string ep = PointerJoin(lp, i);
      errors.Try([&] {
        const nlohmann::json& el = list[i];
        if (!el.is_object()) throw InputError("", ep, "expected a fault object {\"family\": ..., \"joint\": ...}, got " + Describe(el));
        ErrorList shape;  // every swept key of the element
        for (auto it = el.begin(); it != el.end(); ++it) {
          const std::string kp = PointerJoin(ep, it.key());
          if (it.key() == "compound") {
            shape.Add(InputError("", kp, "a compound fault cannot hold another compound fault"));
          } else if (it.value().is_array() || (it.value().is_object() && it.key() != "onset")) {
            // (An "onset" object is one condition: a single value.)
            shape.Add(InputError("", kp, "compound elements take single values (no lists, grids or uniforms), got " +
                                             Describe(it.value())));
          }
        }
        shape.ThrowIfAny();
        const FaultEntry one = ParseFaultEntry(el, ep, robot);
        e.elements.push_back(el);
        if (!one.joints.empty()) {
          default_name += (default_name.empty() ? "" : "+") + one.family + "_j" + std::to_string(one.joints[0]);
        }
      });
    }
  });
  errors.Try([&] {
    if (const auto* name = reader.Find("name")) {
      if (!name->is_string() || name->get<std::string>().empty() || name->get<std::string>().find('/') != std::string::npos) {
        throw InputError("", reader.PointerTo("name"), "expected a non-empty name without '/', got " + Describe(*name));
      }
      e.name = name->get<std::string>();
    }
  });
  errors.ThrowIfAny();
  if (e.name.empty()) e.name = default_name;
  return e;
}

}  // namespace

}  // namespace spec_parse
}  // namespace armfault
