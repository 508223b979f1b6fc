#include "campaigns/campaign.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include "core/base/rng.h"
#include "core/run_config.h"
#include "core/base/suggest.h"
#include "campaigns/tuning.h"
#include "faults/fault.h"

namespace armfault {

namespace {

constexpr long kMaxCases = 10'000'000;

// Keys that time a fault rather than size it: not part of a scoring group.
const std::set<std::string> kTimingKeys = {"onset_s", "onset", "profile", "ramp_s", "duration_s", "period_s"};

uint64_t Fnv1a(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

std::string ValueText(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number()) return FormatNumber(v.get<double>());
  if (v.is_object()) {
    // An onset condition: "<when>:<key>=<value>:..." in key order, without the ',' and '/'
    // that separate a run_id's parts.
    const auto when = v.find("when");
    std::string text = when != v.end() && when->is_string() ? when->get<std::string>() : "?";
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (it.key() != "when") text += ":" + it.key() + "=" + ValueText(it.value());
    }
    return text;
  }
  return v.dump();
}


// A key's values. `swept` tells a list, grid or uniform from a single fixed value.
struct ParsedSweep {
  Sweep sweep;
  bool swept = false;
};

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

Sweep VariationSweep(ObjectReader& reader, const char* key, double min, double max) {
  Sweep s;
  const auto* v = reader.Find(key);
  if (!v) return s;
  ParsedSweep p = ParseSweep(*v, reader.PointerTo(key), true);
  if (!p.sweep.uniform && p.sweep.values.size() != 1) {
    throw InputError("", reader.PointerTo(key), "expected a number or {\"uniform\": [a, b]}, got " + Describe(*v));
  }
  if (p.sweep.uniform) {
    ErrorList errors;  // each bound on its own
    errors.Try([&] { RequireInRange(p.sweep.low, min, max, PointerJoin(PointerJoin(reader.PointerTo(key), "uniform"), 0)); });
    errors.Try([&] { RequireInRange(p.sweep.high, min, max, PointerJoin(PointerJoin(reader.PointerTo(key), "uniform"), 1)); });
    errors.ThrowIfAny();
  } else {
    RequireInRange(p.sweep.values[0].get<double>(), min, max, reader.PointerTo(key));
  }
  return p.sweep;
}

// "datasheet", {"preset": "datasheet", key: half-width...}, or {key: half-width...}.
StatedTolerances ParseTolerances(const nlohmann::json& v, const std::string& pointer) {
  if (v.is_string()) {
    if (v.get<std::string>() != "datasheet") {
      throw InputError("", pointer, "unknown tolerance preset " + Describe(v) + " (known: \"datasheet\")");
    }
    return DatasheetTolerances();
  }
  ObjectReader reader(v, pointer);
  std::vector<std::string> allowed = {"preset"};
  for (const ToleranceKey& k : ToleranceKeys()) allowed.push_back(k.name);
  ErrorList errors;  // every key on its own
  errors.Try([&] { reader.AllowOnly(allowed); });
  StatedTolerances t;
  errors.Try([&] {
    if (const auto* p = reader.Find("preset")) t = ParseTolerances(*p, reader.PointerTo("preset"));
  });
  for (const ToleranceKey& k : ToleranceKeys()) {
    errors.Try([&] {
      if (const auto* x = reader.Find(k.name)) {
        const double s = AsNumber(*x, reader.PointerTo(k.name));
        RequireInRange(s, 0, k.max, reader.PointerTo(k.name));
        t.*k.member = s;
      }
    });
  }
  errors.ThrowIfAny();
  return t;
}

FloorSet ParseFloorSet(const nlohmann::json& v, const std::string& pointer, bool allow_per_family) {
  ObjectReader reader(v, pointer);
  ErrorList errors;  // every key on its own
  errors.Try([&] {
    if (allow_per_family) {
      reader.AllowOnly({"detection_rate", "false_alarm_rate", "isolation_accuracy", "per_family", "monitor_us_per_tick"});
    }
    if (!allow_per_family) reader.AllowOnly({"detection_rate", "false_alarm_rate", "isolation_accuracy"});
  });
  FloorSet f;
  for (auto [key, member] : {std::pair{"detection_rate", &FloorSet::detection_rate},
                             std::pair{"false_alarm_rate", &FloorSet::false_alarm_rate},
                             std::pair{"isolation_accuracy", &FloorSet::isolation_accuracy}}) {
    errors.Try([&, key = key, member = member] {
      if (const auto* x = reader.Find(key)) {
        const double value = AsNumber(*x, reader.PointerTo(key));
        RequireInRange(value, 0, 1, reader.PointerTo(key));
        f.*member = value;
      }
    });
  }
  errors.ThrowIfAny();
  return f;
}

Floors ParseFloors(const nlohmann::json& v, const std::string& pointer) {
  Floors floors;
  ErrorList errors;  // the overall floors and each family's on their own
  errors.Try([&] { floors.overall = ParseFloorSet(v, pointer, true); });
  errors.Try([&] {
    if (!v.is_object() || !v.contains("monitor_us_per_tick")) return;
    const std::string at = PointerJoin(pointer, "monitor_us_per_tick");
    const double value = AsNumber(v["monitor_us_per_tick"], at);
    if (!(value > 0)) throw InputError("", at, "expected the monitor's mean time per tick in microseconds, > 0, got " + FormatNumber(value));
    floors.monitor_us_per_tick = value;
  });
  if (v.contains("per_family")) {
    const std::string pp = PointerJoin(pointer, "per_family");
    errors.Try([&] {
      ObjectReader(v["per_family"], pp);  // must be an object
      const std::vector<std::string> families = FaultFamilyNames();
      for (auto it = v["per_family"].begin(); it != v["per_family"].end(); ++it) {
        errors.Try([&] {
          if (std::find(families.begin(), families.end(), it.key()) == families.end()) {
            const std::string near = NearestWord(it.key(), families);
            throw InputError("", PointerJoin(pp, it.key()), "unknown fault family \"" + it.key() + "\"",
                             near.empty() ? "" : "did you mean \"" + near + "\"?");
          }
          floors.per_family[it.key()] = ParseFloorSet(it.value(), PointerJoin(pp, it.key()), false);
        });
      }
    });
  }
  errors.ThrowIfAny();
  return floors;
}

FaultEntry ParseCompoundEntry(const nlohmann::json& v, const std::string& pointer, const RobotConfig* robot);

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
    // The family still names the keys it does not know: it rejects them before reading any
    // value, so a probe with every key null and a valid joint gives exactly those errors.
    if (family_ok) {
      nlohmann::json probe = {{"family", e.family}, {"joint", 1}};
      for (auto it = v.begin(); it != v.end(); ++it) {
        if (it.key() != "family" && it.key() != "joint") probe[it.key()] = nullptr;
      }
      try {
        MakeFault(probe, pointer, robot ? *robot : RobotPreset("mrr-config1"));
      } catch (const InputError& err) {
        for (const InputError& one : err.errors()) {
          for (auto it = probe.begin(); it != probe.end(); ++it) {
            if (one.pointer() == PointerJoin(pointer, it.key()) &&
                one.message() == e.family + ": unknown key \"" + it.key() + "\"") {
              errors.Add(one);
            }
          }
        }
      }
    }
    errors.ThrowIfAny();
    return e;
  }
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
      {reader.PointerTo("joint"), ValuePointer(joints.sweep, 0, joints.swept)}};
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
        MakeFault(spec, pointer, *robot);
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
          if (!retry || one.pointer() == key_pointer) errors.Add(one.Edited(to_value));
        }
        // The profile decides which timing keys apply: without it the check would mislead.
        const bool profile = std::find(others.begin(), others.end(), "profile") != others.end();
        if (own || others.empty() || profile) return !own;
        for (const std::string& key : others) spec.erase(key);
      }
    }
  };
  for (size_t j = 0; j < e.joints.size(); ++j) {
    check(spec_with(SIZE_MAX, nullptr, e.joints[j]), reader.PointerTo("joint"), ValuePointer(joints.sweep, j, joints.swept));
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
  errors.ThrowIfAny();
  return e;
}


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

// The "search" block (docs/campaign-format.md, "Boundary search"). Needs the fault entries
// parsed (`faults_ok`) and the robot for the family checks of the range's ends.
void ParseSearch(const nlohmann::json& v, const std::string& pointer, const nlohmann::json* faults_json, Campaign* c,
                 bool faults_ok, bool robot_ok, ErrorList* errors) {
  ObjectReader reader(v, pointer);
  errors->Try([&] { reader.AllowOnly({"target", "confidence", "range", "batch", "max_runs", "tolerance", "runs"}); });
  SearchSpec& s = c->search;
  s.present = true;
  errors->Try([&] {
    reader.OptionalNumber("target", &s.target);
    RequireInRange(s.target, 0.5, 0.999, reader.PointerTo("target"));
  });
  errors->Try([&] {
    reader.OptionalNumber("confidence", &s.confidence);
    RequireInRange(s.confidence, 0.5, 0.9999, reader.PointerTo("confidence"));
  });
  errors->Try([&] {
    reader.OptionalInt("batch", &s.batch);
    RequireInRange(s.batch, 2, 1000, reader.PointerTo("batch"));
  });
  errors->Try([&] {
    reader.OptionalInt("max_runs", &s.max_runs);
    RequireInRange(s.max_runs, 2, 100000, reader.PointerTo("max_runs"));
  });
  bool has_range = false;
  double range_low = 0, range_high = 0;
  const bool range_ok = errors->Try([&] {
    if (const auto* r = reader.Find("range")) {
      const std::string rp = reader.PointerTo("range");
      if (!r->is_array() || r->size() != 2) throw InputError("", rp, "expected [low, high] magnitudes, got " + Describe(*r));
      ErrorList both;
      both.Try([&] { range_low = AsNumber((*r)[0], PointerJoin(rp, 0)); });
      both.Try([&] { range_high = AsNumber((*r)[1], PointerJoin(rp, 1)); });
      both.ThrowIfAny();
      if (range_low > range_high) {
        throw InputError("", PointerJoin(rp, 0), "inverted search range: low " + FormatNumber(range_low) +
                                                     " is greater than high " + FormatNumber(range_high));
      }
      if (range_low == range_high) {
        throw InputError("", rp, "empty search range [" + FormatNumber(range_low) + ", " + FormatNumber(range_high) +
                                     "]: give low < high");
      }
      has_range = true;
    }
  });
  double tolerance = 0;
  errors->Try([&] {
    if (reader.Has("tolerance")) {
      reader.OptionalNumber("tolerance", &tolerance);
      RequireAbove(tolerance, 0, reader.PointerTo("tolerance"));
    }
  });
  if (!faults_ok || !range_ok) return;
  if (c->faults.empty()) {
    errors->Add(InputError("", pointer, "a search needs fault entries to search: \"faults\" is empty"));
    return;
  }
  // Each fault entry: a family with a magnitude, one value for every other key (or a
  // uniform), and a range of magnitudes that are faults the family accepts.
  bool entries_ok = true;
  for (size_t i = 0; i < c->faults.size(); ++i) {
    const FaultEntry& e = c->faults[i];
    SearchEntryRange range;
    entries_ok &= errors->Try([&] {
      if (e.compound) {
        throw InputError("", e.pointer, "a compound fault entry cannot be searched (a boundary search sizes one fault "
                                        "by its magnitude); leave it out of a campaign with \"search\"");
      }
      range.key = FaultMagnitudeKey(e.family);
      if (range.key.empty()) {
        throw InputError("", PointerJoin(e.pointer, "family"),
                         "\"" + e.family + "\" has no magnitude to search (the search needs a family sized by a number: "
                         "kt_degradation, friction_increase, brake_lock, inverter_short, winding_resistance, "
                         "torque_sensor_drift); leave this entry out of a campaign with \"search\"");
      }
      ErrorList entry_errors;
      const Sweep* magnitude = nullptr;
      for (const auto& [key, sweep] : e.keys) {
        if (key == range.key) {
          magnitude = &sweep;
          continue;
        }
        if (!sweep.uniform && sweep.values.size() > 1) {
          entry_errors.Add(InputError("", sweep.pointer, "a searched entry takes one value (or a uniform) for \"" + key +
                                                             "\": only its magnitude \"" + range.key + "\" is searched"));
        }
      }
      entry_errors.ThrowIfAny();
      std::string range_pointer = reader.PointerTo("range");
      if (has_range) {
        range.low = range_low;
        range.high = range_high;
      } else if (!magnitude) {
        throw InputError("", e.pointer, "no \"" + range.key + "\" to search: give it as a list or a grid, or give "
                                        "\"range\": [low, high] in \"search\"");
      } else if (magnitude->uniform) {
        range.low = magnitude->low, range.high = magnitude->high;
        range_pointer = PointerJoin(magnitude->pointer, "uniform");
      } else {
        range_pointer = magnitude->pointer;
        range.low = range.high = magnitude->values[0].is_number() ? magnitude->values[0].get<double>() : 0;
        for (const nlohmann::json& x : magnitude->values) {
          if (!x.is_number()) throw InputError("", magnitude->pointer, "expected numbers to search, got " + Describe(x));
          range.low = std::min(range.low, x.get<double>());
          range.high = std::max(range.high, x.get<double>());
        }
        if (range.low == range.high) {
          throw InputError("", magnitude->pointer, "empty search range: \"" + range.key + "\" is the one value " +
                                                       FormatNumber(range.low) + "; give a list or grid of it, or "
                                                       "\"range\": [low, high] in \"search\"");
        }
      }
      // Both ends: a fault (severity > 0: the fit is in log severity) that the family accepts.
      for (int end = 0; end < 2; ++end) {
        const double m = end == 0 ? range.low : range.high;
        // Where the end comes from: the range's bound, the grid's end, the uniform's bound, or
        // the list element that holds it.
        std::string at;
        if (has_range || magnitude->uniform) {
          at = PointerJoin(range_pointer, std::to_string(end));
        } else if (magnitude->grid) {
          at = PointerJoin(range_pointer, end == 0 ? "from" : "to");
        } else {
          size_t index = 0;
          while (index + 1 < magnitude->values.size() && magnitude->values[index].get<double>() != m) ++index;
          at = PointerJoin(range_pointer, index);
        }
        entry_errors.Try([&] {
          if (!(PodSeverity(range.key, m) > 0) || !std::isfinite(PodSeverity(range.key, m))) {
            throw InputError("", at, e.family + ": " + range.key + " " + FormatNumber(m) +
                                         " is no fault (severity 0): a search range must exclude the healthy value");
          }
          if (!robot_ok) return;
          nlohmann::json spec = {{"family", e.family}, {"joint", e.joints[0]}, {range.key, m}};
          for (const auto& [key, sweep] : e.keys) {
            if (key != range.key) spec[key] = sweep.uniform ? nlohmann::json(sweep.low) : sweep.values[0];
          }
          try {
            MakeFault(spec, e.pointer, c->robot);
          } catch (const InputError& err) {
            throw InputError("", at, err.message());
          }
        });
      }
      entry_errors.ThrowIfAny();
      range.tolerance = tolerance > 0 ? tolerance : (range.high - range.low) / 10;
      range.lattice = std::pow(10.0, std::floor(std::log10(range.high - range.low)) - 3);
    });
    s.entries.push_back(range);
  }
  if (!entries_ok) return;
  if (const auto* runs = reader.Find("runs")) {
    const std::string rp = reader.PointerTo("runs");
    errors->Try([&] {
      if (!runs->is_array()) throw InputError("", rp, "expected an array of runs, got " + Describe(*runs));
      std::map<std::tuple<size_t, size_t, int>, long> numbers;
      for (size_t k = 0; k < runs->size(); ++k) {
        const std::string p = PointerJoin(rp, k);
        ObjectReader run(( *runs)[k], p);
        run.AllowOnly({"trajectory", "entry", "joint", "magnitude"});
        SearchRun r;
        const std::string name = run.RequireString("trajectory");
        const auto t = std::find_if(c->trajectories.begin(), c->trajectories.end(),
                                    [&](const CampaignTrajectory& x) { return x.name == name; });
        if (t == c->trajectories.end()) throw InputError("", run.PointerTo("trajectory"), "no trajectory \"" + name + "\"");
        r.trajectory = static_cast<size_t>(t - c->trajectories.begin());
        const int entry = run.RequireInt("entry");
        RequireInRange(entry, 0, static_cast<double>(c->faults.size()) - 1, run.PointerTo("entry"));
        r.entry = static_cast<size_t>(entry);
        r.joint = run.RequireInt("joint");
        const std::vector<int>& joints = c->faults[r.entry].joints;
        if (std::find(joints.begin(), joints.end(), r.joint) == joints.end()) {
          throw InputError("", run.PointerTo("joint"), "joint " + std::to_string(r.joint) + " is not a joint of fault entry " +
                                                           std::to_string(entry));
        }
        r.magnitude = run.RequireNumber("magnitude");
        r.number = numbers[{r.trajectory, r.entry, r.joint}]++;
        s.runs.push_back(r);
      }
      s.has_runs = true;
    });
  }
  (void)faults_json;
}
}  // namespace

const std::vector<ToleranceKey>& ToleranceKeys() {
  static const std::vector<ToleranceKey> keys = {
      {"kt", &StatedTolerances::kt, false, 0.5},
      {"winding_resistance", &StatedTolerances::winding_resistance, false, 0.9},
      {"switch_resistance", &StatedTolerances::switch_resistance, false, 0.9},
      {"switching_loss", &StatedTolerances::switching_loss, false, 0.9},
      {"quiescent_power", &StatedTolerances::quiescent_power, false, 0.9},
      {"mesh_loss", &StatedTolerances::mesh_loss, false, 0.9},
      {"rotor_inertia", &StatedTolerances::rotor_inertia, false, 0.5},
      {"stribeck_velocity", &StatedTolerances::stribeck_velocity, false, 0.9},
      {"torque_sensor_gain", &StatedTolerances::torque_sensor_gain, false, 0.5},
      {"torque_sensor_offset_Nm", &StatedTolerances::torque_sensor_offset_Nm, true, 100},
      {"supply_current_gain", &StatedTolerances::supply_current_gain, false, 0.5},
      {"supply_current_offset_A", &StatedTolerances::supply_current_offset_A, true, 10},
      {"bus_voltage", &StatedTolerances::bus_voltage, false, 0.5},
  };
  return keys;
}

StatedTolerances DatasheetTolerances() {
  // Sources and reasoning: docs/assumptions.md, "Unit tolerances".
  StatedTolerances t;
  t.kt = 0.10;
  t.winding_resistance = 0.10;
  t.switch_resistance = 0.20;
  t.switching_loss = 0.30;
  t.quiescent_power = 0.30;
  t.mesh_loss = 0.20;
  t.rotor_inertia = 0.05;
  t.stribeck_velocity = 0.20;
  t.torque_sensor_gain = 0.02;
  t.torque_sensor_offset_Nm = 0.28;
  t.supply_current_gain = 0.014;
  t.supply_current_offset_A = 0.007;
  t.bus_voltage = 0.02;
  return t;
}

nlohmann::json CaseSpec::VariationJson() const {
  nlohmann::json j = nlohmann::json::object();
  j["extra_payload_kg"] = extra_payload_kg;
  j["torque_noise_Nm"] = torque_noise_Nm < 0 ? nlohmann::json(nullptr) : nlohmann::json(torque_noise_Nm);
  j["friction_factors"] = friction_factors;
  // Only campaigns that use them carry the newer keys, so older results stay byte-identical.
  if (unit >= 0) j["unit"] = unit;
  if (ambient_C != 20) j["ambient_C"] = ambient_C;
  if (!tolerance_draws.empty()) {
    nlohmann::json drawn = nlohmann::json::object();
    for (size_t k = 0; k < ToleranceKeys().size(); ++k) {
      nlohmann::json per_joint = nlohmann::json::array();
      for (const auto& joint : tolerance_draws) per_joint.push_back(joint[k]);
      drawn[ToleranceKeys()[k].name] = per_joint;
    }
    j["tolerances"] = drawn;
  }
  return j;
}

RobotConfig UnitRobot(const Campaign& c, const CaseSpec& cs) {
  RobotConfig r = c.robot;
  for (size_t j = 0; j < r.modules.size(); ++j) {
    ModuleParams& m = r.modules[j];
    const double f = j < cs.friction_factors.size() ? cs.friction_factors[j] : 1.0;
    m.friction.viscous_Nm_s_per_rad *= f;
    m.friction.coulomb_Nm *= f;
    m.friction.static_Nm *= f;
    if (j >= cs.tolerance_draws.size()) continue;
    const std::vector<double>& d = cs.tolerance_draws[j];  // ToleranceKeys() order
    m.motor.kt_Nm_per_A *= d[0];
    m.motor.phase_resistance_ohm *= d[1];
    m.inverter.switch_resistance_ohm *= d[2];
    m.inverter.switching_time_s *= d[3];
    m.inverter.quiescent_power_W *= d[4];
    m.drive.mesh_loss_fraction *= d[5];
    m.motor.rotor_inertia_kg_m2 *= d[6];
    m.friction.stribeck_s2_per_rad2 /= d[7] * d[7];  // F_t = 1 / v_s²: the Stribeck velocity scales by d
    m.torque_sensor.gain_error = d[8] - 1.0;
    m.torque_sensor.offset_error_Nm = d[9];
    m.inverter.supply_current_gain_error = d[10] - 1.0;
    m.inverter.supply_current_offset_error_A = d[11];
    m.inverter.bus_voltage_V *= d[12];
  }
  return r;
}

RobotConfig CaseRobot(const Campaign& c, const CaseSpec& cs) {
  RobotConfig r = UnitRobot(c, cs);
  r.payload_kg += cs.extra_payload_kg;
  for (ModuleParams& m : r.modules) {
    if (cs.torque_noise_Nm >= 0) m.torque_sensor.noise_Nm = cs.torque_noise_Nm;
  }
  return r;
}

StatedTolerances StatedOf(const Campaign& c) {
  StatedTolerances t = c.variation.tolerances;
  t.friction = c.variation.friction_spread;
  const Sweep& a = c.variation.ambient_C;
  t.ambient_min_C = a.uniform ? a.low : (a.values.empty() ? 20.0 : a.values[0].get<double>());
  t.ambient_max_C = a.uniform ? a.high : t.ambient_min_C;
  return t;
}

Campaign CampaignFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir) {
  Campaign c;
  c.source = source;
  c.base_dir = base_dir;
  InputContext context;
  context.source = source;
  context.base_dir = base_dir;
  try {
    if (!value.is_object()) throw InputError("", "", "expected a JSON object describing a campaign, got " + Describe(value));
    ObjectReader reader(value, "");
    // Each independent part is read on its own and all errors are reported together; a check
    // that needs a part that failed (the robot, the duration) is skipped instead.
    ErrorList errors;
    errors.Try([&] {
      reader.AllowOnly({"name", "seed", "robot", "duration_s", "trajectories", "faults", "healthy", "repetitions",
                        "variation", "commissioning", "include_not_excited", "monitor", "floors", "search"});
    });
    c.name = std::filesystem::path(source).stem().string();
    errors.Try([&] { reader.OptionalString("name", &c.name); });
    errors.Try([&] {
      if (const auto* seed = reader.Find("seed")) {
        const double s = AsNumber(*seed, reader.PointerTo("seed"));
        if (s < 0 || s != std::floor(s) || s > 9007199254740991.0) {
          throw InputError("", reader.PointerTo("seed"), "expected a whole number >= 0, got " + Describe(*seed));
        }
        c.seed = static_cast<unsigned long long>(s);
      }
    });
    const bool robot_ok = errors.Try([&] {
      if (const auto* robot = reader.Find("robot")) c.robot = RobotFromJson(*robot, reader.PointerTo("robot"));
      else c.robot = RobotPreset("mrr-config1");
    });
    const bool duration_ok = errors.Try([&] {
      reader.OptionalNumber("duration_s", &c.duration_s);
      RequireInRange(c.duration_s, 0.002, 3600, reader.PointerTo("duration_s"));
    });

    const std::string tp = reader.PointerTo("trajectories");
    const nlohmann::json* trajectories = nullptr;
    errors.Try([&] {
      const nlohmann::json& given = reader.Require("trajectories");
      if (!given.is_array() || given.empty()) {
        throw InputError("", tp, "expected a non-empty array of trajectories, got " + Describe(given));
      }
      trajectories = &given;
    });
    std::set<std::string> names;
    for (size_t i = 0; trajectories && i < trajectories->size(); ++i) {
      errors.Try([&] {
        const std::string p = PointerJoin(tp, i);
        ObjectReader tr((*trajectories)[i], p);
        errors.Try([&] { tr.AllowOnly({"name", "joints"}); });
        CampaignTrajectory t;
        errors.Try([&] {
          t.name = tr.RequireString("name");
          if (t.name.empty() || t.name.find('/') != std::string::npos) {
            throw InputError("", tr.PointerTo("name"), "a trajectory name must be non-empty and without '/', got " +
                                                         Describe((*trajectories)[i]["name"]));
          }
          if (!names.insert(t.name).second) throw InputError("", tr.PointerTo("name"), "duplicate trajectory name \"" + t.name + "\"");
        });
        errors.Try([&] {
          t.joints = tr.Require("joints");
          // The joints are checked against the robot's joints over the duration; without
          // those, each trajectory is still checked on its own.
          if (robot_ok && duration_ok) {
            t.parsed = JointTrajectoriesFromJson(t.joints, tr.PointerTo("joints"), c.robot, c.duration_s, context);
          } else if (t.joints.is_object()) {
            for (auto it = t.joints.begin(); it != t.joints.end(); ++it) {
              errors.Try([&] { MakeTrajectory(it.value(), PointerJoin(tr.PointerTo("joints"), it.key()), context); });
            }
          }
        });
        c.trajectories.push_back(std::move(t));
      });
    }
    bool faults_ok = true;
    const nlohmann::json* faults_json = nullptr;
    faults_ok &= errors.Try([&] {
      if (const auto* faults = reader.Find("faults")) {
        if (!faults->is_array()) throw InputError("", reader.PointerTo("faults"), "expected an array of faults, got " + Describe(*faults));
        faults_json = faults;
        for (size_t i = 0; i < faults->size(); ++i) {
          faults_ok &= errors.Try([&] {
            c.faults.push_back(ParseFaultEntry((*faults)[i], PointerJoin(reader.PointerTo("faults"), i), robot_ok ? &c.robot : nullptr));
          });
        }
      }
    });
    errors.Try([&] {
      if (const auto* search = reader.Find("search")) {
        ParseSearch(*search, reader.PointerTo("search"), faults_json, &c, faults_ok && robot_ok && duration_ok, robot_ok,
                    &errors);
      }
    });
    errors.Try([&] {
      reader.OptionalInt("healthy", &c.healthy);
      RequireInRange(c.healthy, 0, 1000000, reader.PointerTo("healthy"));
    });
    errors.Try([&] {
      reader.OptionalInt("repetitions", &c.repetitions);
      RequireInRange(c.repetitions, 1, 1000000, reader.PointerTo("repetitions"));
    });
    errors.Try([&] {
      if (const auto* v = reader.Find("variation")) {
        ObjectReader vr(*v, reader.PointerTo("variation"));
        errors.Try([&] { vr.AllowOnly({"payload_kg", "torque_noise_Nm", "friction_spread", "tolerances", "ambient_C", "units"}); });
        errors.Try([&] { c.variation.payload_kg = VariationSweep(vr, "payload_kg", 0, 100); });
        errors.Try([&] { c.variation.torque_noise_Nm = VariationSweep(vr, "torque_noise_Nm", 0, 100); });
        errors.Try([&] {
          vr.OptionalNumber("friction_spread", &c.variation.friction_spread);
          RequireInRange(c.variation.friction_spread, 0, 0.9, vr.PointerTo("friction_spread"));
        });
        errors.Try([&] {
          if (const auto* t = vr.Find("tolerances")) {
            c.variation.tolerances = ParseTolerances(*t, vr.PointerTo("tolerances"));
            c.variation.has_tolerances = true;
          }
        });
        errors.Try([&] { c.variation.ambient_C = VariationSweep(vr, "ambient_C", -40, 120); });
        errors.Try([&] {
          if (vr.Has("units")) {
            vr.OptionalInt("units", &c.variation.units);
            RequireInRange(c.variation.units, 1, 100000, vr.PointerTo("units"));
          }
        });
      }
    });
    c.commissioning = c.variation.has_tolerances;
    errors.Try([&] {
      if (const auto* v = reader.Find("commissioning")) {
        if (!v->is_boolean()) throw InputError("", reader.PointerTo("commissioning"), "expected true or false, got " + Describe(*v));
        c.commissioning = v->get<bool>();
      }
    });
    errors.Try([&] {
      if (const auto* v = reader.Find("include_not_excited")) {
        if (!v->is_boolean()) {
          throw InputError("", reader.PointerTo("include_not_excited"), "expected true or false, got " + Describe(*v));
        }
        c.include_not_excited = v->get<bool>();
      }
    });
    errors.Try([&] {
      if (const auto* m = reader.Find("monitor")) c.monitor = MonitorSpecFromJson(*m, reader.PointerTo("monitor"), context);
    });
    errors.Try([&] {
      if (const auto* f = reader.Find("floors")) c.floors = ParseFloors(*f, reader.PointerTo("floors"));
    });
    // (Unknown keys were all reported by AllowOnly above.) The run count needs every part.
    errors.ThrowIfAny();

    const long cases = CaseCount(c);
    if (cases == 0) throw InputError("", "", "the campaign has no runs: give \"faults\" or \"healthy\" runs");
    if (cases > kMaxCases) {
      throw InputError("", "", "the campaign expands to " + std::to_string(cases) + " runs, more than " +
                                   std::to_string(kMaxCases) + "; split it");
    }
  } catch (const InputError& e) {
    throw e.WithSource(source);  // errors that name a file (a monitor or CSV file) keep it
  }

  MonitorContext monitor_context;
  monitor_context.robot = c.robot;
  monitor_context.has_tolerances = c.variation.has_tolerances;
  monitor_context.stated = StatedOf(c);
  monitor_context.commissioning = c.commissioning;
  monitor_context.input = context;
  try {
    c.monitor_model = MakeMonitorModel(c.monitor, monitor_context, "/monitor");
  } catch (const InputError& e) {
    throw e.WithSource(source);
  }
  c.resolved = value;
  c.resolved["name"] = c.name;
  c.resolved["seed"] = c.seed;
  c.resolved["robot"] = RobotToJson(c.robot);
  c.resolved["duration_s"] = c.duration_s;
  c.resolved["healthy"] = c.healthy;
  c.resolved["repetitions"] = c.repetitions;
  c.resolved["monitor"] = c.monitor.ToJson();  // as given: the widening is derived again on reading
  if (c.variation.has_tolerances || value.contains("commissioning")) c.resolved["commissioning"] = c.commissioning;
  if (value.contains("include_not_excited")) c.resolved["include_not_excited"] = c.include_not_excited;
  if (!c.resolved.contains("faults")) c.resolved["faults"] = nlohmann::json::array();
  if (!c.resolved.contains("variation")) c.resolved["variation"] = nlohmann::json::object();
  if (!c.resolved.contains("floors")) c.resolved["floors"] = nlohmann::json::object();
  if (c.search.present) {
    nlohmann::json& s = c.resolved["search"];
    s["target"] = c.search.target;
    s["confidence"] = c.search.confidence;
    s["batch"] = c.search.batch;
    s["max_runs"] = c.search.max_runs;
  }
  return c;
}

Campaign ReadCampaignFile(const std::string& path) {
  std::string base = std::filesystem::path(path).parent_path().string();
  if (base.empty()) base = ".";
  return CampaignFromJson(ReadJsonFile(path), path, base);
}

long CaseCount(const Campaign& c) {
  if (c.search.has_runs) return static_cast<long>(c.search.runs.size());
  long per_trajectory = c.healthy;
  for (const FaultEntry& e : c.faults) {
    long n = static_cast<long>(e.compound ? 1 : e.joints.size()) * c.repetitions;
    for (const auto& [key, sweep] : e.keys) {
      n *= static_cast<long>(sweep.count());
      if (n > kMaxCases) return kMaxCases + 1;
    }
    per_trajectory += n;
    if (per_trajectory > kMaxCases) return kMaxCases + 1;
  }
  const long total = per_trajectory * static_cast<long>(c.trajectories.size());
  return total > kMaxCases ? kMaxCases + 1 : total;
}

namespace {

// Draws a run's variation from its own stream, after the uniform fault values.
void DrawVariation(const Campaign& c, Rng* rng, CaseSpec* cs) {
  auto draw = [&](const Sweep& s, double fallback) {
    if (s.uniform) return s.low + (s.high - s.low) * rng->Uniform();
    if (!s.values.empty()) return s.values[0].get<double>();
    return fallback;
  };
  cs->extra_payload_kg = draw(c.variation.payload_kg, 0.0);
  cs->torque_noise_Nm = draw(c.variation.torque_noise_Nm, -1.0);
  cs->friction_factors.clear();
  for (size_t j = 0; j < c.robot.modules.size(); ++j) {
    const double u = rng->Uniform();
    cs->friction_factors.push_back(1.0 + c.variation.friction_spread * (2.0 * u - 1.0));
  }
  // Newer draws come after the older ones, and only where used, so older campaigns keep
  // their streams. A fleet's unit draws its friction and tolerances from its own stream.
  Rng unit_rng(0);
  Rng* parts = rng;
  if (c.variation.units > 0) {
    cs->unit = static_cast<int>(cs->seed % static_cast<unsigned long long>(c.variation.units));
    unit_rng = Rng(MixSeed(c.seed, 0x756e6974ULL + static_cast<uint64_t>(cs->unit)));
    parts = &unit_rng;
    for (size_t j = 0; j < c.robot.modules.size(); ++j) {
      cs->friction_factors[j] = 1.0 + c.variation.friction_spread * (2.0 * parts->Uniform() - 1.0);
    }
  }
  cs->tolerance_draws.clear();
  if (c.variation.has_tolerances) {
    for (size_t j = 0; j < c.robot.modules.size(); ++j) {
      std::vector<double> d;
      for (const ToleranceKey& k : ToleranceKeys()) {
        const double s = c.variation.tolerances.*k.member * (2.0 * parts->Uniform() - 1.0);
        d.push_back(k.absolute ? s : 1.0 + s);
      }
      cs->tolerance_draws.push_back(std::move(d));
    }
  }
  cs->ambient_C = draw(c.variation.ambient_C, 20.0);
}

}  // namespace

namespace {

// Runs of one fault entry: its value combinations x joints x repetitions.
long EntryRuns(const Campaign& c, const FaultEntry& e) {
  if (e.compound) return c.repetitions;  // one case per trajectory x repetition
  long n = static_cast<long>(e.joints.size()) * c.repetitions;
  for (const auto& [key, sweep] : e.keys) n *= static_cast<long>(sweep.count());
  return n;
}

// A boundary search's run: its entry at the run's magnitude, the other keys at their one
// value or drawn from their uniform, the variation drawn after them, as for a grid case.
CaseSpec SearchCaseAt(const Campaign& c, long index) {
  const SearchRun& run = c.search.runs[static_cast<size_t>(index)];
  const FaultEntry& e = c.faults[run.entry];
  const std::string& key = c.search.entries[run.entry].key;
  CaseSpec cs;
  cs.index = index;
  cs.trajectory = run.trajectory;
  cs.run_id = SearchRunId(c, run);
  cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
  Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
  std::map<std::string, std::pair<nlohmann::json, std::string>> values;  // sorted: value, group text
  for (const auto& [name, sweep] : e.keys) {
    if (name == key) continue;
    if (sweep.uniform) {
      values[name] = {sweep.low + (sweep.high - sweep.low) * rng.Uniform(),
                      "U[" + FormatNumber(sweep.low) + "," + FormatNumber(sweep.high) + "]"};
    } else {
      values[name] = {sweep.values[0], ValueText(sweep.values[0])};
    }
  }
  values[key] = {run.magnitude, FormatNumber(run.magnitude)};
  nlohmann::json fault = {{"family", e.family}, {"joint", run.joint}};
  std::string group = e.family;
  for (const auto& [name, value] : values) {
    fault[name] = value.first;
    if (!kTimingKeys.count(name)) group += " " + name + "=" + value.second;
  }
  cs.group = group + " joint=" + std::to_string(run.joint);
  cs.fault = fault;
  DrawVariation(c, &rng, &cs);
  return cs;
}

}  // namespace

std::string SearchRunId(const Campaign& c, const SearchRun& run) {
  const FaultEntry& e = c.faults[run.entry];
  return c.trajectories[run.trajectory].name + "/" + e.family + "#" + std::to_string(run.entry) + "/" +
         c.search.entries[run.entry].key + "=" + FormatNumber(run.magnitude) + "/j" + std::to_string(run.joint) + "/s" +
         std::to_string(run.number);
}

double SearchLatticeValue(const SearchEntryRange& range, double magnitude) {
  const double m = std::min(range.high, std::max(range.low, magnitude));
  // Through the decimal text, so a value prints and reads back as the same short number.
  return std::stod(FormatNumber(std::round(m / range.lattice) * range.lattice));
}

CaseSpec CaseAt(const Campaign& c, long index) {
  const long total = CaseCount(c);
  if (index < 0 || index >= total) {
    throw std::out_of_range("case " + std::to_string(index) + " of a campaign of " + std::to_string(total) + " runs");
  }
  if (c.search.has_runs) return SearchCaseAt(c, index);
  long per_trajectory = c.healthy;
  for (const FaultEntry& e : c.faults) per_trajectory += EntryRuns(c, e);
  const size_t t = static_cast<size_t>(index / per_trajectory);
  long r = index % per_trajectory;
  const std::string& tname = c.trajectories[t].name;
  CaseSpec cs;
  cs.index = index;
  cs.trajectory = t;
  for (size_t ei = 0; ei < c.faults.size(); ++ei) {
    const FaultEntry& e = c.faults[ei];
    const long n = EntryRuns(c, e);
    if (r >= n) {
      r -= n;
      continue;
    }
    if (e.compound) {
      // One case per repetition: all its elements act together.
      cs.repetition = static_cast<int>(r);
      cs.run_id = tname + "/compound#" + std::to_string(ei) + "/" + e.name + "/r" + std::to_string(r);
      cs.group = "compound:" + e.name;
      cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
      Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
      cs.fault = {{"family", "compound"}, {"name", e.name}, {"compound", e.elements}};
      DrawVariation(c, &rng, &cs);
      return cs;
    }
    // r = (values x joints + joint) x repetitions + repetition; values: last key fastest.
    const int rep = static_cast<int>(r % c.repetitions);
    r /= c.repetitions;
    const int joint = e.joints[static_cast<size_t>(r % static_cast<long>(e.joints.size()))];
    long combination = r / static_cast<long>(e.joints.size());
    std::vector<size_t> at(e.keys.size(), 0);
    for (size_t k = e.keys.size(); k-- > 0;) {
      const long count = static_cast<long>(e.keys[k].second.count());
      at[k] = static_cast<size_t>(combination % count);
      combination /= count;
    }
    cs.repetition = rep;
    std::string values, group = e.family;
    for (size_t k = 0; k < e.keys.size(); ++k) {
      const Sweep& s = e.keys[k].second;
      std::string text = s.uniform ? "U[" + FormatNumber(s.low) + "," + FormatNumber(s.high) + "]" : ValueText(s.values[at[k]]);
      if (s.uniform || s.values.size() > 1) values += (values.empty() ? "" : ",") + e.keys[k].first + "=" + text;
      if (!kTimingKeys.count(e.keys[k].first)) group += " " + e.keys[k].first + "=" + text;
    }
    group += " joint=" + std::to_string(joint);
    cs.run_id = tname + "/" + e.family + "#" + std::to_string(ei) + "/" + (values.empty() ? "-" : values) + "/j" +
                std::to_string(joint) + "/r" + std::to_string(rep);
    cs.group = group;
    cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
    Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
    nlohmann::json fault = {{"family", e.family}, {"joint", joint}};
    for (size_t k = 0; k < e.keys.size(); ++k) {
      const Sweep& s = e.keys[k].second;
      fault[e.keys[k].first] = s.uniform ? nlohmann::json(s.low + (s.high - s.low) * rng.Uniform()) : s.values[at[k]];
    }
    cs.fault = fault;
    DrawVariation(c, &rng, &cs);
    return cs;
  }
  // The healthy runs, after every fault entry.
  cs.run_id = tname + "/healthy/" + std::to_string(r);
  cs.seed = MixSeed(c.seed, Fnv1a(cs.run_id));
  Rng rng(MixSeed(cs.seed, 0x7a71a710ULL));
  cs.fault = nullptr;
  DrawVariation(c, &rng, &cs);
  return cs;
}

std::vector<CaseSpec> ExpandCases(const Campaign& c) {
  std::vector<CaseSpec> cases;
  const long n = CaseCount(c);
  cases.reserve(static_cast<size_t>(n));
  for (long k = 0; k < n; ++k) cases.push_back(CaseAt(c, k));
  return cases;
}

std::vector<std::string> CampaignWarnings(const Campaign& c) {
  std::vector<std::string> out;
  for (const CampaignTrajectory& t : c.trajectories) {
    // Joints a trajectory does not name hold their start; named ones may still not move.
    std::set<int> still;
    for (int j = 1; j <= static_cast<int>(c.robot.modules.size()); ++j) {
      const auto it = t.parsed.find(j);
      if (it == t.parsed.end()) {
        still.insert(j);
        continue;
      }
      const AngleRange range = SampleRange(*it->second, c.duration_s);
      if (range.max_rad - range.min_rad < kMinTravelToExcite_rad) still.insert(j);
    }
    auto warn = [&](const std::string& pointer, const std::string& family, int j) {
      if (still.count(j) == 0) return;
      out.push_back(pointer + " (" + family + ") targets joint " + std::to_string(j) + ", which trajectory \"" +
                    t.name + "\" leaves still: " +
                    (FaultNeedsMotion(family) ? "its runs there will be not excited (" + family +
                                                    " shows only in motion) and left out of the rates"
                                              : "the fault can act at rest, but no motion of its joint helps see it"));
    };
    for (const FaultEntry& e : c.faults) {
      for (int j : e.joints) warn(e.pointer, e.family, j);
      // A compound entry: each element (its run is not excited only if no element can act).
      for (size_t i = 0; i < e.elements.size(); ++i) {
        const nlohmann::json& el = e.elements[i];
        if (el.contains("joint") && el["joint"].is_number_integer() && el.contains("family") && el["family"].is_string()) {
          warn(PointerJoin(PointerJoin(e.pointer, "compound"), i), el["family"].get<std::string>(), el["joint"].get<int>());
        }
      }
    }
  }
  return out;
}

}  // namespace armfault
