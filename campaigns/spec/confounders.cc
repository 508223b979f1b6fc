#include "campaigns/spec/confounders.h"

#include <cmath>

#include "core/base/json_input.h"

namespace armfault {

namespace {

constexpr double kArrheniusC_C = -273.15;

// One range key: its member, and the interval its ends must lie in (the plant's accepted
// values, docs/robot-format.md, or a factor's plausible span).
struct RangeKey {
  const char* name;
  ConfounderRange ConfounderRanges::*member;
  double min, max;
};

const std::vector<RangeKey>& RangeKeys() {
  static const std::vector<RangeKey> keys = {
      {"cold_to_warm_ratio", &ConfounderRanges::cold_to_warm_ratio, 1.0, 10.0},
      {"vogel_C_C", &ConfounderRanges::vogel_C_C, -273.15, -60.0},
      {"reference_C", &ConfounderRanges::reference_C, -40.0, 120.0},
      {"coulomb_exponent", &ConfounderRanges::coulomb_exponent, 0.0, 2.0},
      {"load_friction_driving", &ConfounderRanges::load_friction_driving, 0.0, 0.5},
      {"load_friction_backdriven", &ConfounderRanges::load_friction_backdriven, 0.0, 0.5},
      {"sensor_offset_fs_per_K", &ConfounderRanges::sensor_offset_fs_per_K, 0.0, 0.01},
      {"sensor_gain_per_K", &ConfounderRanges::sensor_gain_per_K, 0.0, 0.01},
      {"thermal_resistance_factor", &ConfounderRanges::thermal_resistance_factor, 0.1, 10.0},
      {"thermal_time_constant_factor", &ConfounderRanges::thermal_time_constant_factor, 0.1, 10.0},
      {"winding_coupling_factor", &ConfounderRanges::winding_coupling_factor, 0.0, 10.0},
      {"warm_duty_factor", &ConfounderRanges::warm_duty_factor, 0.0, 10.0},
      {"kinematic_error_2x_arcmin", &ConfounderRanges::kinematic_error_2x_arcmin, 0.0, 10.0},
      {"kinematic_error_1x_arcmin", &ConfounderRanges::kinematic_error_1x_arcmin, 0.0, 10.0},
      {"cogging_Nm", &ConfounderRanges::cogging_Nm, 0.0, 10.0},
  };
  return keys;
}

double Draw(const ConfounderRange& r, Rng* rng) { return r.low + (r.high - r.low) * rng->Uniform(); }
double Sign(Rng* rng) { return rng->Uniform() < 0.5 ? -1.0 : 1.0; }

// One drawn value per joint: draws[j].*group.*member.
template <class Group>
nlohmann::json PerJoint(const std::vector<ConfounderDraw>& draws, Group ConfounderDraw::*group, double Group::*member) {
  nlohmann::json per_joint = nlohmann::json::array();
  for (const ConfounderDraw& d : draws) per_joint.push_back(d.*group.*member);
  return per_joint;
}

}  // namespace

ConfounderRanges DocumentedConfounderRanges() { return ConfounderRanges{}; }

ConfounderRanges ParseConfounderRanges(const nlohmann::json& value, const std::string& pointer) {
  if (value.is_string()) {
    if (value.get<std::string>() != "documented") {
      throw InputError("", pointer, "unknown confounder preset " + Describe(value) + " (known: \"documented\")");
    }
    return DocumentedConfounderRanges();
  }
  ObjectReader reader(value, pointer);
  std::vector<std::string> allowed = {"preset", "arrhenius_fraction"};
  for (const RangeKey& k : RangeKeys()) allowed.push_back(k.name);
  ErrorList errors;  // every key on its own
  errors.Try([&] { reader.AllowOnly(allowed); });
  ConfounderRanges r;
  errors.Try([&] {
    if (const auto* p = reader.Find("preset")) r = ParseConfounderRanges(*p, reader.PointerTo("preset"));
  });
  errors.Try([&] {
    if (reader.Has("arrhenius_fraction")) {
      reader.OptionalNumber("arrhenius_fraction", &r.arrhenius_fraction);
      RequireInRange(r.arrhenius_fraction, 0, 1, reader.PointerTo("arrhenius_fraction"));
    }
  });
  for (const RangeKey& k : RangeKeys()) {
    errors.Try([&] {
      const auto* x = reader.Find(k.name);
      if (x == nullptr) return;
      const std::string p = reader.PointerTo(k.name);
      if (!x->is_array() || x->size() != 2) throw InputError("", p, "expected a range [low, high], got " + Describe(*x));
      ConfounderRange range{AsNumber((*x)[0], PointerJoin(p, 0)), AsNumber((*x)[1], PointerJoin(p, 1))};
      RequireInRange(range.low, k.min, k.max, PointerJoin(p, 0));
      RequireInRange(range.high, k.min, k.max, PointerJoin(p, 1));
      if (range.low > range.high) {
        throw InputError("", p, "low end " + FormatNumber(range.low) + " above high end " + FormatNumber(range.high));
      }
      r.*k.member = range;
    });
  }
  errors.ThrowIfAny();
  return r;
}

void RequireGearboxGroups(const RobotConfig& robot, const std::string& pointer) {
  for (size_t j = 0; j < robot.modules.size(); ++j) {
    if (!robot.modules[j].gearbox.present) {
      throw InputError("", pointer,
                       "randomized confounders scale each drive's gearbox group, and joint " + std::to_string(j + 1) +
                           " has none: give its drive a \"gearbox\" group or a -thermal type");
    }
  }
}

std::vector<ConfounderDraw> DrawConfounders(const ConfounderRanges& ranges, const RobotConfig& robot, Rng* rng) {
  // The unit's lubricant.
  const bool arrhenius = rng->Uniform() < ranges.arrhenius_fraction;
  const double vogel_c = Draw(ranges.vogel_C_C, rng);
  const double c = arrhenius ? kArrheniusC_C : vogel_c;
  const double ratio = Draw(ranges.cold_to_warm_ratio, rng);
  const double b = std::log(ratio) / (1.0 / (-10.0 - c) - 1.0 / (40.0 - c));
  const double reference = Draw(ranges.reference_C, rng);
  const double exponent = Draw(ranges.coulomb_exponent, rng);
  std::vector<ConfounderDraw> draws;
  for (const ModuleParams& m : robot.modules) {
    ConfounderDraw d;
    GearboxParams& g = d.gearbox;
    g = m.gearbox;
    g.vogel_B_K = b;
    g.vogel_C_C = c;
    g.reference_C = reference;
    g.coulomb_exponent = exponent;
    g.load_friction_driving = Draw(ranges.load_friction_driving, rng);
    g.load_friction_backdriven = Draw(ranges.load_friction_backdriven, rng);
    g.sensor_offset_Nm_per_K = Sign(rng) * Draw(ranges.sensor_offset_fs_per_K, rng) * m.torque_sensor.full_scale_Nm;
    g.sensor_gain_per_K = Sign(rng) * Draw(ranges.sensor_gain_per_K, rng);
    g.thermal_resistance_K_per_W *= Draw(ranges.thermal_resistance_factor, rng);
    g.thermal_time_constant_s *= Draw(ranges.thermal_time_constant_factor, rng);
    g.winding_coupling_W_per_K *= Draw(ranges.winding_coupling_factor, rng);
    const double duty = Draw(ranges.warm_duty_factor, rng);
    g.warm_copper_loss_W *= duty;
    g.warm_friction_loss_W *= duty;
    RippleParams& p = d.ripple;
    p = m.ripple;
    p.enabled = true;
    p.kinematic_error_2x_arcmin = Draw(ranges.kinematic_error_2x_arcmin, rng);
    p.kinematic_error_1x_arcmin = Draw(ranges.kinematic_error_1x_arcmin, rng);
    p.cogging_Nm = Draw(ranges.cogging_Nm, rng);
    p.phase_2x_deg = 360.0 * rng->Uniform();
    p.phase_1x_deg = 360.0 * rng->Uniform();
    p.cogging_phase_deg = 360.0 * rng->Uniform();
    draws.push_back(d);
  }
  return draws;
}

nlohmann::json ConfounderDrawsToJson(const std::vector<ConfounderDraw>& draws) {
  nlohmann::json j = nlohmann::json::object();
  if (draws.empty()) return j;
  j["lubricant"] = draws[0].gearbox.vogel_C_C == kArrheniusC_C ? "arrhenius" : "vogel";
  const std::vector<std::pair<const char*, double GearboxParams::*>> gear = {
      {"vogel_B_K", &GearboxParams::vogel_B_K},
      {"vogel_C_C", &GearboxParams::vogel_C_C},
      {"reference_C", &GearboxParams::reference_C},
      {"coulomb_exponent", &GearboxParams::coulomb_exponent},
      {"load_friction_driving", &GearboxParams::load_friction_driving},
      {"load_friction_backdriven", &GearboxParams::load_friction_backdriven},
      {"sensor_offset_Nm_per_K", &GearboxParams::sensor_offset_Nm_per_K},
      {"sensor_gain_per_K", &GearboxParams::sensor_gain_per_K},
      {"thermal_resistance_K_per_W", &GearboxParams::thermal_resistance_K_per_W},
      {"thermal_time_constant_s", &GearboxParams::thermal_time_constant_s},
      {"winding_coupling_W_per_K", &GearboxParams::winding_coupling_W_per_K},
      {"warm_copper_loss_W", &GearboxParams::warm_copper_loss_W},
      {"warm_friction_loss_W", &GearboxParams::warm_friction_loss_W},
  };
  for (const auto& [name, member] : gear) j[name] = PerJoint(draws, &ConfounderDraw::gearbox, member);
  const std::vector<std::pair<const char*, double RippleParams::*>> ripple = {
      {"kinematic_error_2x_arcmin", &RippleParams::kinematic_error_2x_arcmin},
      {"kinematic_error_1x_arcmin", &RippleParams::kinematic_error_1x_arcmin},
      {"cogging_Nm", &RippleParams::cogging_Nm},
      {"phase_2x_deg", &RippleParams::phase_2x_deg},
      {"phase_1x_deg", &RippleParams::phase_1x_deg},
      {"cogging_phase_deg", &RippleParams::cogging_phase_deg},
  };
  for (const auto& [name, member] : ripple) j[name] = PerJoint(draws, &ConfounderDraw::ripple, member);
  return j;
}

}  // namespace armfault
