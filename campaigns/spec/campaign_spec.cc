#include "campaigns/spec/campaign_spec.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "core/base/suggest.h"
#include "core/run_config.h"
#include "campaigns/spec/spec_parse.h"
#include "faults/fault.h"

namespace armfault {

using spec_parse::ParsedSweep;
using spec_parse::ParseFaultEntry;
using spec_parse::ParseSearch;
using spec_parse::ParseSweep;

namespace {

constexpr long kMaxCases = 10'000'000;
// Commissioning on a work cycle: two cycles of 14 s and more (the held-out-b bench's place
// cycle; docs/campaign-format.md, "Commissioning").
constexpr double kDefaultTrajectoryCommissioning_s = 30.0;

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

// The "trajectories" list into c->trajectories; with `loaded`, each trajectory is also loaded
// into it, checked against the robot's joints over the duration when both are good
// (`robot_ok`, `duration_ok`), else each joint's trajectory on its own.
void ParseTrajectories(ObjectReader& reader, bool robot_ok, bool duration_ok, const InputContext& context,
                       CampaignSpec* c, LoadedTrajectories* loaded, ErrorList* errors) {
  const std::string tp = reader.PointerTo("trajectories");
  const nlohmann::json* trajectories = nullptr;
  errors->Try([&] {
    const nlohmann::json& given = reader.Require("trajectories");
    if (!given.is_array() || given.empty()) {
      throw InputError("", tp, "expected a non-empty array of trajectories, got " + Describe(given));
    }
    trajectories = &given;
  });
  std::set<std::string> names;
  for (size_t i = 0; trajectories && i < trajectories->size(); ++i) {
    errors->Try([&] {
      const std::string p = PointerJoin(tp, i);
      ObjectReader tr((*trajectories)[i], p);
      errors->Try([&] { tr.AllowOnly({"name", "joints"}); });
      CampaignTrajectory t;
      errors->Try([&] {
        t.name = tr.RequireString("name");
        if (t.name.empty() || t.name.find('/') != std::string::npos) {
          throw InputError("", tr.PointerTo("name"), "a trajectory name must be non-empty and without '/', got " +
                                                       Describe((*trajectories)[i]["name"]));
        }
        if (!names.insert(t.name).second) throw InputError("", tr.PointerTo("name"), "duplicate trajectory name \"" + t.name + "\"");
      });
      std::map<int, std::shared_ptr<const Trajectory>> joints;
      errors->Try([&] {
        t.joints = tr.Require("joints");
        if (loaded == nullptr) return;  // the spec alone: the joints as given, unread
        // The joints are checked against the robot's joints over the duration; without
        // those, each trajectory is still checked on its own.
        if (robot_ok && duration_ok) {
          joints = JointTrajectoriesFromJson(t.joints, tr.PointerTo("joints"), c->robot, c->duration_s, context);
        } else if (t.joints.is_object()) {
          for (auto it = t.joints.begin(); it != t.joints.end(); ++it) {
            errors->Try([&] { MakeTrajectory(it.value(), PointerJoin(tr.PointerTo("joints"), it.key()), context); });
          }
        }
      });
      c->trajectories.push_back(std::move(t));
      if (loaded != nullptr) loaded->push_back(std::move(joints));
    });
  }
}

// The object form of "commissioning": on, on one of the campaign's trajectories (by name,
// default the first) for duration_s (default 30 s or the campaign's duration if shorter; at most
// the campaign's duration, over which the trajectory was checked against the robot).
void ParseCommissioningOnTrajectory(const nlohmann::json& v, const std::string& pointer, CampaignSpec* c,
                                    ErrorList* errors) {
  ObjectReader r(v, pointer);
  errors->Try([&] { r.AllowOnly({"trajectory", "duration_s"}); });
  c->commissioning = true;
  c->commissioning_trajectory = 0;
  c->commissioning_duration_s = std::min(kDefaultTrajectoryCommissioning_s, std::max(1.0, c->duration_s));
  errors->Try([&] {
    std::string name = c->trajectories.empty() ? std::string() : c->trajectories.front().name;
    r.OptionalString("trajectory", &name);
    for (size_t i = 0; i < c->trajectories.size(); ++i) {
      if (c->trajectories[i].name == name) {
        c->commissioning_trajectory = static_cast<int>(i);
        return;
      }
    }
    if (r.Has("trajectory")) {
      std::string known;
      for (const CampaignTrajectory& t : c->trajectories) known += (known.empty() ? "\"" : ", \"") + t.name + "\"";
      throw InputError("", r.PointerTo("trajectory"),
                       "no trajectory named " + Describe(v["trajectory"]) + " in this campaign (its trajectories: " + known + ")");
    }
  });
  errors->Try([&] {
    r.OptionalNumber("duration_s", &c->commissioning_duration_s);
    RequireInRange(c->commissioning_duration_s, 1.0, std::max(1.0, c->duration_s), r.PointerTo("duration_s"));
  });
}

// The "variation" object.
void ParseVariation(const nlohmann::json& v, const std::string& pointer, Variation* out, ErrorList* errors) {
  ObjectReader vr(v, pointer);
  errors->Try([&] { vr.AllowOnly({"payload_kg", "torque_noise_Nm", "friction_spread", "tolerances", "ambient_C", "units",
                                       "warm_start_fraction", "confounders"}); });
  errors->Try([&] { out->payload_kg = VariationSweep(vr, "payload_kg", 0, 100); });
  errors->Try([&] { out->torque_noise_Nm = VariationSweep(vr, "torque_noise_Nm", 0, 100); });
  errors->Try([&] {
    vr.OptionalNumber("friction_spread", &out->friction_spread);
    RequireInRange(out->friction_spread, 0, 0.9, vr.PointerTo("friction_spread"));
  });
  errors->Try([&] {
    if (const auto* t = vr.Find("tolerances")) {
      out->tolerances = ParseTolerances(*t, vr.PointerTo("tolerances"));
      out->has_tolerances = true;
    }
  });
  errors->Try([&] {
    if (const auto* t = vr.Find("confounders")) {
      out->confounders = ParseConfounderRanges(*t, vr.PointerTo("confounders"));
      out->has_confounders = true;
    }
  });
  errors->Try([&] { out->ambient_C = VariationSweep(vr, "ambient_C", -40, 120); });
  errors->Try([&] {
    if (vr.Has("warm_start_fraction")) {
      vr.OptionalNumber("warm_start_fraction", &out->warm_start_fraction);
      RequireInRange(out->warm_start_fraction, 0, 1, vr.PointerTo("warm_start_fraction"));
    }
  });
  errors->Try([&] {
    if (vr.Has("units")) {
      vr.OptionalInt("units", &out->units);
      RequireInRange(out->units, 1, 100000, vr.PointerTo("units"));
    }
  });
}

// The campaign with defaults filled in (campaign.json): `value` as given, the parsed values over it.
nlohmann::json Resolved(const CampaignSpec& c, const nlohmann::json& value) {
  nlohmann::json resolved = value;
  resolved.erase("$schema");  // for editors: not part of the campaign
  resolved["name"] = c.name;
  resolved["seed"] = c.seed;
  resolved["robot"] = RobotToJson(c.robot);
  resolved["duration_s"] = c.duration_s;
  resolved["healthy"] = c.healthy;
  resolved["repetitions"] = c.repetitions;
  resolved["monitor"] = c.monitor.ToJson();  // as given: the widening is derived again on reading
  if (c.commissioning_trajectory >= 0 && static_cast<size_t>(c.commissioning_trajectory) < c.trajectories.size()) {
    resolved["commissioning"] = {{"trajectory", c.trajectories[c.commissioning_trajectory].name},
                                 {"duration_s", c.commissioning_duration_s}};
  } else if (c.variation.has_tolerances || value.contains("commissioning")) {
    resolved["commissioning"] = c.commissioning;
  }
  if (value.contains("include_not_excited")) resolved["include_not_excited"] = c.include_not_excited;
  if (!resolved.contains("faults")) resolved["faults"] = nlohmann::json::array();
  if (!resolved.contains("variation")) resolved["variation"] = nlohmann::json::object();
  if (!resolved.contains("floors")) resolved["floors"] = nlohmann::json::object();
  if (c.search.present) {
    nlohmann::json& s = resolved["search"];
    s["target"] = c.search.target;
    s["confidence"] = c.search.confidence;
    s["batch"] = c.search.batch;
    s["max_runs"] = c.search.max_runs;
  }
  return resolved;
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

CampaignSpec CampaignSpecFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir,
                                  LoadedTrajectories* loaded) {
  CampaignSpec c;
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
      reader.AllowOnly({"$schema", "name", "seed", "robot", "duration_s", "trajectories", "faults", "healthy",
                        "repetitions", "variation", "commissioning", "include_not_excited", "monitor", "floors", "search",
                        "engine"});
    });
    // For editors only (the schema's address): checked to be a string, not recorded.
    errors.Try([&] {
      std::string schema;
      reader.OptionalString("$schema", &schema);
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
      if (const auto* robot = reader.Find("robot")) c.robot = RobotFromJson(*robot, reader.PointerTo("robot"), base_dir);
      else c.robot = RobotPreset("mrr-config1");
    });
    // The campaign's engine overrides the robot's (RobotConfig::engine).
    errors.Try([&] {
      if (const auto* engine = reader.Find("engine")) {
        const PhysicsEngine e = EngineFromJson(*engine, reader.PointerTo("engine"));
        if (robot_ok) {
          c.robot.engine = e;
          CheckEngineTakes(c.robot, reader.PointerTo("engine"));
        }
      }
    });
    const bool duration_ok = errors.Try([&] {
      reader.OptionalNumber("duration_s", &c.duration_s);
      RequireInRange(c.duration_s, 0.002, 3600, reader.PointerTo("duration_s"));
    });

    ParseTrajectories(reader, robot_ok, duration_ok, context, &c, loaded, &errors);
    bool faults_ok = true;
    faults_ok &= errors.Try([&] {
      if (const auto* faults = reader.Find("faults")) {
        if (!faults->is_array()) throw InputError("", reader.PointerTo("faults"), "expected an array of faults, got " + Describe(*faults));
        for (size_t i = 0; i < faults->size(); ++i) {
          faults_ok &= errors.Try([&] {
            c.faults.push_back(ParseFaultEntry((*faults)[i], PointerJoin(reader.PointerTo("faults"), i), robot_ok ? &c.robot : nullptr));
          });
        }
      }
    });
    errors.Try([&] {
      if (const auto* search = reader.Find("search")) {
        ParseSearch(*search, reader.PointerTo("search"), &c, faults_ok && robot_ok && duration_ok, robot_ok,
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
      if (const auto* v = reader.Find("variation")) ParseVariation(*v, reader.PointerTo("variation"), &c.variation, &errors);
      if (c.variation.has_confounders && robot_ok) {
        errors.Try([&] { RequireGearboxGroups(c.robot, "/variation/confounders"); });
      }
    });
    c.commissioning = c.variation.has_tolerances;
    errors.Try([&] {
      if (const auto* v = reader.Find("commissioning")) {
        if (v->is_object()) {
          ParseCommissioningOnTrajectory(*v, reader.PointerTo("commissioning"), &c, &errors);
        } else if (!v->is_boolean()) {
          throw InputError("", reader.PointerTo("commissioning"),
                           "expected true, false or {\"trajectory\": NAME, \"duration_s\": SECONDS}, got " + Describe(*v));
        } else {
          c.commissioning = v->get<bool>();
        }
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
  c.resolved = Resolved(c, value);
  return c;
}

double StatedFalseAlarmsPerHour(const CampaignSpec& c) {
  if (c.monitor.type != "power_efficiency") return 0.0;
  const MonitorConfig m = MonitorConfigFromJson(c.monitor.settings, "/monitor", c.source);
  return m.decision == kSequentialDecision ? m.target_false_alarms_per_hour : 0.0;
}

long CaseCount(const CampaignSpec& c) {
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

}  // namespace armfault
