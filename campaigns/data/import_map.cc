// The import map (MAP.json): the units of each quantity, the map's parsing (ImportMapFromJson)
// and its checks against the robot and the fault families (ValidateImportMap).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>

#include "campaigns/data/import.h"
#include "campaigns/data/import_internal.h"
#include "core/base/json_input.h"
#include "core/base/suggest.h"
#include "faults/fault.h"

namespace armfault {

namespace fs = std::filesystem;

using import_detail::FieldInfo;
using import_detail::kFields;
using import_detail::Quantity;
using import_detail::Quoted;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Units by quantity: value in the field's SI unit = raw * scale + offset.
struct UnitInfo {
  Quantity quantity;
  const char* name;
  double scale, offset;
};
const UnitInfo kUnits[] = {
    {Quantity::kAngle, "rad", 1, 0},
    {Quantity::kAngle, "mrad", 1e-3, 0},
    {Quantity::kAngle, "deg", kPi / 180, 0},
    {Quantity::kAngularVelocity, "rad/s", 1, 0},
    {Quantity::kAngularVelocity, "deg/s", kPi / 180, 0},
    {Quantity::kAngularVelocity, "rpm", 2 * kPi / 60, 0},
    {Quantity::kTorque, "N m", 1, 0},
    {Quantity::kTorque, "Nm", 1, 0},
    {Quantity::kTorque, "mN m", 1e-3, 0},
    {Quantity::kTorque, "mNm", 1e-3, 0},
    {Quantity::kCurrent, "A", 1, 0},
    {Quantity::kCurrent, "mA", 1e-3, 0},
    {Quantity::kVoltage, "V", 1, 0},
    {Quantity::kVoltage, "mV", 1e-3, 0},
    {Quantity::kTemperature, "degC", 1, 0},
    {Quantity::kTemperature, "°C", 1, 0},
    {Quantity::kTemperature, "K", 1, -273.15},
};

ImportColumn ColumnFromJson(const nlohmann::json& value, const std::string& pointer, int field, ErrorList* errors) {
  ImportColumn c;
  ObjectReader r(value, pointer);
  errors->Try([&] { r.AllowOnly({"column", "unit", "scale", "offset", "resample"}); });
  errors->Try([&] {
    c.column = r.RequireString("column");
    if (c.column.empty()) throw InputError("", r.PointerTo("column"), "expected a column name, got \"\"");
  });
  const bool has_unit = r.Has("unit"), has_scale = r.Has("scale") || r.Has("offset");
  if (has_unit && has_scale) {
    errors->Add(InputError("", r.PointerTo("unit"), "give a \"unit\" or a \"scale\" and \"offset\", not both"));
  } else if (!has_unit && !has_scale) {
    errors->Add(InputError("", pointer,
                           "expected a \"unit\" (or a \"scale\" and \"offset\" to the field's unit) for column " +
                               Quoted(c.column)));
  }
  if (has_unit) {
    errors->Try([&] {
      c.unit = r.RequireString("unit");
      std::string known;
      if (field >= 0 && !UnitToSi(field, c.unit, &c.scale, &c.offset, &known)) {
        std::vector<std::string> all;
        for (const UnitInfo& u : kUnits) all.push_back(u.name);
        const std::string near = NearestWord(c.unit, all);
        throw InputError("", r.PointerTo("unit"),
                         "unknown unit " + Describe(value["unit"]) + " for " + kFields[field].name + " (known: " + known + ")",
                         near.empty() || near == c.unit ? "" : "did you mean \"" + near + "\"?");
      }
    });
  }
  errors->Try([&] {
    r.OptionalNumber("scale", &c.scale);
    if (!std::isfinite(c.scale) || c.scale == 0) {
      throw InputError("", r.PointerTo("scale"), "expected a finite non-zero number, got " + Describe(value["scale"]));
    }
  });
  errors->Try([&] { r.OptionalNumber("offset", &c.offset); });
  errors->Try([&] {
    std::string how = "linear";
    r.OptionalString("resample", &how);
    if (how != "linear" && how != "hold") {
      throw InputError("", r.PointerTo("resample"), "expected \"linear\" or \"hold\", got " + Describe(value["resample"]));
    }
    c.hold = how == "hold";
  });
  return c;
}

ImportLabel LabelFromJson(const nlohmann::json& value, const std::string& pointer) {
  ImportLabel l;
  l.pointer = pointer;
  if (value.is_string()) {
    const std::string s = value.get<std::string>();
    if (s == "healthy") l.kind = ImportLabel::Kind::kHealthy;
    else if (s == "unknown") l.kind = ImportLabel::Kind::kUnknown;
    else throw InputError("", pointer, "expected \"healthy\", \"unknown\" or a fault object, got " + Describe(value));
    return l;
  }
  if (!value.is_object()) {
    throw InputError("", pointer, "expected \"healthy\", \"unknown\" or a fault object, got " + Describe(value));
  }
  ErrorList errors;
  ObjectReader r(value, pointer);
  errors.Try([&] { r.AllowOnly({"family", "joint", "onset_s", "magnitude"}); });
  l.kind = ImportLabel::Kind::kFault;
  errors.Try([&] { l.family = r.RequireString("family"); });
  errors.Try([&] { l.joint = r.RequireInt("joint"); });
  errors.Try([&] {
    l.onset_s = r.RequireNumber("onset_s");
    RequireAtLeast(l.onset_s, 0, r.PointerTo("onset_s"));
  });
  errors.Try([&] {
    if (const nlohmann::json* m = r.Find("magnitude"); m && !m->is_null()) l.magnitude = AsNumber(*m, r.PointerTo("magnitude"));
  });
  errors.ThrowIfAny();
  return l;
}

RobotConfig RobotOfMap(const nlohmann::json& value, const std::string& pointer, const std::string& base_dir) {
  if (value.is_string()) {
    const std::string what = value.get<std::string>();
    for (const std::string& name : RobotPresetNames()) {
      if (what == name) return RobotPreset(name, pointer);
    }
    const fs::path path = fs::path(what).is_absolute() ? fs::path(what) : fs::path(base_dir) / what;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      std::string presets;
      for (const std::string& name : RobotPresetNames()) presets += (presets.empty() ? "" : ", ") + name;
      throw InputError("", pointer, Describe(value) + " is neither a robot preset (" + presets + ") nor a robot file");
    }
    const nlohmann::json file = ReadJsonFile(path.string());
    const std::string base = path.parent_path().string();
    try {
      const bool wrapper = file.is_object() && file.contains("robot") && !file.contains("modules") && !file.contains("urdf");
      return wrapper ? RobotFromJson(file.at("robot"), "/robot", base) : RobotFromJson(file, "", base);
    } catch (const InputError& e) {
      throw e.WithSource(path.string());
    }
  }
  return RobotFromJson(value, pointer, base_dir);
}

}  // namespace

bool UnitToSi(int field, const std::string& unit, double* scale, double* offset, std::string* known) {
  if (field < 0 || field >= kImportFields) return false;
  const Quantity q = kFields[field].quantity;
  std::string list;
  for (const UnitInfo& u : kUnits) {
    if (u.quantity != q) continue;
    if (unit == u.name) {
      *scale = u.scale;
      *offset = u.offset;
      return true;
    }
    list += (list.empty() ? "" : ", ") + std::string(u.name);
  }
  if (known) *known = list;
  return false;
}

bool TimeUnitToSeconds(const std::string& unit, double* seconds) {
  if (unit == "s") *seconds = 1;
  else if (unit == "ms") *seconds = 1e-3;
  else if (unit == "us" || unit == "µs") *seconds = 1e-6;
  else return false;
  return true;
}

ImportMap ImportMapFromJson(const nlohmann::json& value, const std::string& source, const std::string& base_dir) {
  ImportMap m;
  m.source = source;
  m.base_dir = base_dir;
  try {
    if (!value.is_object()) throw InputError("", "", "expected a JSON object (an import map), got " + Describe(value));
    ErrorList errors;
    ObjectReader r(value, "");
    errors.Try([&] {
      r.AllowOnly({"$schema", "name", "robot", "time", "run_column", "max_gap_periods", "joints", "labels", "floors"});
    });
    errors.Try([&] {
      std::string schema;
      r.OptionalString("$schema", &schema);
    });
    errors.Try([&] {
      r.OptionalString("name", &m.name);
      if (m.name.empty() || m.name.find('/') != std::string::npos) {
        throw InputError("", "/name", "a name must be non-empty and without '/', got " + Describe(value["name"]));
      }
    });
    errors.Try([&] {
      m.robot_given = r.Require("robot");
      m.robot = RobotOfMap(m.robot_given, "/robot", base_dir);
    });
    errors.Try([&] {
      const nlohmann::json& t = r.Require("time");
      ObjectReader tr(t, "/time");
      errors.Try([&] { tr.AllowOnly({"column", "unit"}); });
      errors.Try([&] { m.time.column = tr.RequireString("column"); });
      errors.Try([&] {
        m.time.unit = tr.RequireString("unit");
        if (!TimeUnitToSeconds(m.time.unit, &m.time.scale)) {
          const std::string near = NearestWord(m.time.unit, {"s", "ms", "us"});
          throw InputError("", "/time/unit", "unknown time unit " + Describe(t["unit"]) + " (known: s, ms, us)",
                           near.empty() ? "" : "did you mean \"" + near + "\"?");
        }
      });
    });
    errors.Try([&] { r.OptionalString("run_column", &m.run_column); });
    errors.Try([&] { r.OptionalNumber("max_gap_periods", &m.max_gap_periods); });
    errors.Try([&] {
      if (const nlohmann::json* f = r.Find("floors")) {
        if (!f->is_object()) throw InputError("", "/floors", "expected an object of floors, got " + Describe(*f));
        m.floors = *f;
      }
    });
    errors.Try([&] {
      const nlohmann::json& joints = r.Require("joints");
      if (!joints.is_object()) throw InputError("", "/joints", "expected an object keyed by joint number, got " + Describe(joints));
      for (auto it = joints.begin(); it != joints.end(); ++it) {
        const std::string jp = PointerJoin("/joints", it.key());
        errors.Try([&] {
          int j = 0;
          const auto [end, ec] = std::from_chars(it.key().data(), it.key().data() + it.key().size(), j);
          if (ec != std::errc() || end != it.key().data() + it.key().size() || j < 1 || j > 64) {
            throw InputError("", jp, "expected a joint number (1 = base), got \"" + it.key() + "\"");
          }
          if (static_cast<int>(m.joints.size()) < j) m.joints.resize(j);
          ObjectReader fr(it.value(), jp);
          std::vector<std::string> names;
          for (const FieldInfo& f : kFields) names.push_back(f.name);
          errors.Try([&] { fr.AllowOnly(names); });
          for (int f = 0; f < kImportFields; ++f) {
            if (const nlohmann::json* c = fr.Find(kFields[f].name)) {
              const std::string cp = fr.PointerTo(kFields[f].name);
              errors.Try([&] {
                if (c->is_string()) throw InputError("", cp, "expected {\"column\": ..., \"unit\": ...}, got " + Describe(*c));
                m.joints[j - 1][f] = ColumnFromJson(*c, cp, f, &errors);
              });
            }
          }
        });
      }
    });
    errors.Try([&] {
      if (const nlohmann::json* labels = r.Find("labels")) {
        if (!labels->is_object()) throw InputError("", "/labels", "expected an object keyed by run_id, got " + Describe(*labels));
        for (auto it = labels->begin(); it != labels->end(); ++it) {
          errors.Try([&] { m.labels[it.key()] = LabelFromJson(it.value(), PointerJoin("/labels", it.key())); });
        }
      }
    });
    errors.ThrowIfAny();
  } catch (const InputError& e) {
    throw e.WithSource(source);
  }
  return m;
}

void ValidateImportMap(const ImportMap& m) {
  ErrorList errors;
  const int joints = static_cast<int>(m.robot.modules.size());
  if (!(m.max_gap_periods >= 1 && m.max_gap_periods <= 1e6)) {
    errors.Add(InputError(m.source, "/max_gap_periods",
                          "expected a number of control periods from 1 to 1e6, got " + FormatNumber(m.max_gap_periods)));
  }
  if (static_cast<int>(m.joints.size()) > joints) {
    errors.Add(InputError(m.source, "/joints/" + std::to_string(m.joints.size()),
                          "joint " + std::to_string(m.joints.size()) + " does not exist: the robot has " +
                              std::to_string(joints) + " joints"));
  }
  std::map<std::string, std::string> used;  // column -> pointer of its first use
  used[m.time.column] = "/time/column";
  if (!m.run_column.empty()) {
    if (!used.emplace(m.run_column, "/run_column").second) {
      errors.Add(InputError(m.source, "/run_column", Quoted(m.run_column) + " is also the time column"));
    }
  }
  long columns = 0;
  for (size_t j = 0; j < m.joints.size(); ++j) {
    for (int f = 0; f < kImportFields; ++f) {
      if (!m.joints[j][f]) continue;
      ++columns;
      const std::string p = "/joints/" + std::to_string(j + 1) + "/" + kFields[f].name + "/column";
      if (!used.emplace(m.joints[j][f]->column, p).second) {
        errors.Add(InputError(m.source, p, "column " + Quoted(m.joints[j][f]->column) + " is also " + used[m.joints[j][f]->column]));
      }
    }
  }
  if (columns == 0) errors.Add(InputError(m.source, "/joints", "the map names no signal column"));
  const std::vector<std::string> families = FaultFamilyNames();
  for (const auto& [run, l] : m.labels) {
    if (l.kind != ImportLabel::Kind::kFault) continue;
    if (std::find(families.begin(), families.end(), l.family) == families.end()) {
      const std::string near = NearestWord(l.family, families);
      errors.Add(InputError(m.source, l.pointer + "/family", "unknown fault family \"" + l.family + "\"",
                            near.empty() ? "" : "did you mean \"" + near + "\"?"));
      continue;
    }
    if (l.joint < 1 || l.joint > joints) {
      errors.Add(InputError(m.source, l.pointer + "/joint",
                            "expected a joint from 1 to " + std::to_string(joints) + ", got " + std::to_string(l.joint)));
    }
    FaultMagnitudeRange range;
    if (l.magnitude && FaultMagnitudeRangeOf(l.family, &range)) {
      const double x = *l.magnitude;
      const bool low = range.min_exclusive ? !(x > range.min) : !(x >= range.min);
      if (low || !(x <= range.max) || (range.zero_excluded && x == 0)) {
        errors.Add(InputError(m.source, l.pointer + "/magnitude",
                              FormatNumber(x) + " is outside " + l.family + "'s range " + FaultMagnitudeRangeText(l.family)));
      }
    }
  }
  errors.ThrowIfAny();
}

ImportMap ReadImportMap(const std::string& path) {
  const nlohmann::json value = ReadJsonFile(path);
  ImportMap m = ImportMapFromJson(value, path, fs::path(path).parent_path().string());
  ValidateImportMap(m);
  return m;
}

}  // namespace armfault
