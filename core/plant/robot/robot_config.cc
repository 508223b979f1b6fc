// A robot from JSON and back (robot_config.h): the field tables that drive parsing, validation
// and output, the link and body checks, and Validate. The presets and the drive catalogue:
// robot_presets.cc.
#include "core/plant/robot/robot_config.h"

#include <cmath>
#include <limits>

#include "core/base/json_input.h"
#include "core/base/suggest.h"
#include "core/plant/robot/mass_properties.h"
#include "core/plant/robot/robot_config_internal.h"
#include "core/plant/robot/urdf_robot.h"

namespace armfault {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One numeric parameter of a params struct: its JSON key, member and allowed range.
// Each struct's table drives parsing, validation and output, so they cannot drift apart.
template <class T>
struct Field {
  const char* key;
  double T::*member;
  double min;
  double max;
  bool min_exclusive;
  bool integer;
};

template <class T>
using Fields = std::vector<Field<T>>;

const Fields<MotorParams>& MotorFields() {
  static const Fields<MotorParams> f = {
      {"kt_Nm_per_A", &MotorParams::kt_Nm_per_A, 0, 10, true, false},
      {"phase_resistance_ohm", &MotorParams::phase_resistance_ohm, 0, 100, true, false},
      {"phase_inductance_H", &MotorParams::phase_inductance_H, 0, 1, true, false},
      {"pole_pairs", &MotorParams::pole_pairs, 1, 50, false, true},
      // Floor: the rotor body's moment of inertia (mass_properties.h, docs/assumptions.md).
      {"rotor_inertia_kg_m2", &MotorParams::rotor_inertia_kg_m2, kMinMoment_kg_m2, 1, false, false},
      {"thermal_resistance_K_per_W", &MotorParams::thermal_resistance_K_per_W, 0, 1000, false, false},
      {"thermal_time_constant_s", &MotorParams::thermal_time_constant_s, 0, 1e6, true, false},
  };
  return f;
}
const Fields<InverterParams>& InverterFields() {
  static const Fields<InverterParams> f = {
      {"bus_voltage_V", &InverterParams::bus_voltage_V, 0, 1000, true, false},
      {"current_per_volt_A_per_V", &InverterParams::current_per_volt_A_per_V, 0, 100, true, false},
      {"command_limit_A", &InverterParams::command_limit_A, 0, 1000, true, false},
      {"current_loop_bandwidth_Hz", &InverterParams::current_loop_bandwidth_Hz, 0, 1e5, true, false},
      {"switch_resistance_ohm", &InverterParams::switch_resistance_ohm, 0, 10, false, false},
      {"switching_time_s", &InverterParams::switching_time_s, 0, 1e-3, false, false},
      {"pwm_frequency_Hz", &InverterParams::pwm_frequency_Hz, 0, 1e6, true, false},
      {"diode_drop_V", &InverterParams::diode_drop_V, 0, 10, false, false},
      {"quiescent_power_W", &InverterParams::quiescent_power_W, 0, 1000, false, false},
      {"overcurrent_trip_A", &InverterParams::overcurrent_trip_A, 0, 1e4, true, false},
      {"supply_current_noise_A", &InverterParams::supply_current_noise_A, 0, 10, false, false},
      {"supply_current_gain_error", &InverterParams::supply_current_gain_error, -0.5, 0.5, false, false},
      {"supply_current_offset_error_A", &InverterParams::supply_current_offset_error_A, -10, 10, false, false},
  };
  return f;
}
const Fields<HarmonicDriveParams>& DriveFields() {
  static const Fields<HarmonicDriveParams> f = {
      // At least 2: the rotor is a planet on a sun wheel of radius (ratio - 1)/ratio, which vanishes at 1
      // (ODE asserts radii > 0); joint reducers have ratios of 30 and more (docs/assumptions.md).
      {"ratio", &HarmonicDriveParams::ratio, 2, 10000, false, false},
      {"mesh_loss_fraction", &HarmonicDriveParams::mesh_loss_fraction, 0, 0.9, false, false},
  };
  return f;
}
const Fields<FrictionParams>& FrictionFields() {
  static const Fields<FrictionParams> f = {
      {"viscous_Nm_s_per_rad", &FrictionParams::viscous_Nm_s_per_rad, 0, 10, false, false},
      {"coulomb_Nm", &FrictionParams::coulomb_Nm, 0, 100, false, false},
      {"static_Nm", &FrictionParams::static_Nm, 0, 100, false, false},
      {"stribeck_s2_per_rad2", &FrictionParams::stribeck_s2_per_rad2, 0, 1e6, false, false},
  };
  return f;
}
// The optional "gearbox" group (core/plant/parts/gear_thermal.h); limits and their reasons:
// docs/assumptions.md, "Gearbox temperature, load and sensor drift".
const Fields<GearboxParams>& GearboxFields() {
  static const Fields<GearboxParams> f = {
      {"thermal_resistance_K_per_W", &GearboxParams::thermal_resistance_K_per_W, 0, 1000, true, false},
      {"thermal_time_constant_s", &GearboxParams::thermal_time_constant_s, 0, 1e6, true, false},
      {"winding_coupling_W_per_K", &GearboxParams::winding_coupling_W_per_K, 0, 100, false, false},
      {"reference_C", &GearboxParams::reference_C, -40, 120, false, false},
      {"vogel_B_K", &GearboxParams::vogel_B_K, 0, 5000, false, false},
      {"vogel_C_C", &GearboxParams::vogel_C_C, -273.15, -60, false, false},
      {"coulomb_exponent", &GearboxParams::coulomb_exponent, 0, 2, false, false},
      {"load_friction_driving", &GearboxParams::load_friction_driving, 0, 0.9, false, false},
      {"load_friction_backdriven", &GearboxParams::load_friction_backdriven, 0, 0.9, false, false},
      {"sensor_offset_Nm_per_K", &GearboxParams::sensor_offset_Nm_per_K, -1, 1, false, false},
      {"sensor_gain_per_K", &GearboxParams::sensor_gain_per_K, -0.01, 0.01, false, false},
      {"warm_copper_loss_W", &GearboxParams::warm_copper_loss_W, 0, 1e4, false, false},
      {"warm_friction_loss_W", &GearboxParams::warm_friction_loss_W, 0, 1e4, false, false},
  };
  return f;
}
// Temperatures the plant may meet (a campaign's ambient range, docs/campaign-format.md): the
// lubricant law must stay within kMaxLubricantFactor of its reference over them.
constexpr double kColdestC = -40, kHottestC = 120, kMaxLubricantFactor = 100;
// Explicit Euler on the thermal nodes: each node's fastest time constant at least this many
// physics steps (the step's error then below 1 %).
constexpr double kMinThermalSteps = 100;
// A warm start's nodes at most this far above ambient: a winding's insulation class H allows
// 180 C, and the lubricant's law is bounded only up to 120 C of ambient plus this rise.
constexpr double kMaxWarmRise_K = 150;

// The gearbox group's values (a robot built in code, or a file's: the field table's ranges
// again) and their cross-field limits; each error names its pointer and value.
void CheckGearbox(const ModuleParams& m, double physics_rate_Hz, const std::string& pointer, ErrorList* errors) {
  const GearboxParams& g = m.gearbox;
  bool ok = true;
  for (const Field<GearboxParams>& field : GearboxFields()) {
    ok &= errors->Try([&] {
      const std::string ptr = PointerJoin(pointer, field.key);
      if (field.min_exclusive) RequireAbove(g.*field.member, field.min, ptr);
      RequireInRange(g.*field.member, field.min, field.max, ptr);
    });
  }
  if (!ok) return;
  const double cold = LubricantFactor(g, kColdestC), hot = LubricantFactor(g, kHottestC);
  if (!(cold <= kMaxLubricantFactor && hot >= 1.0 / kMaxLubricantFactor)) {
    errors->Add(InputError("", PointerJoin(pointer, "vogel_B_K"),
                           "vogel_B_K " + FormatNumber(g.vogel_B_K) + " K with vogel_C_C " + FormatNumber(g.vogel_C_C) +
                               " C scales friction by " + FormatNumber(cold) + " at -40 C and " + FormatNumber(hot) +
                               " at 120 C: outside [1/100, 100] of its value at reference_C"));
  }
  for (const auto& [key, mu] : {std::pair<const char*, double>{"load_friction_driving", g.load_friction_driving},
                                {"load_friction_backdriven", g.load_friction_backdriven}}) {
    if (m.drive.mesh_loss_fraction + mu >= 1.0) {
      errors->Add(InputError("", PointerJoin(pointer, key),
                             std::string(key) + " " + FormatNumber(mu) + " with the drive's mesh_loss_fraction " +
                                 FormatNumber(m.drive.mesh_loss_fraction) + " reaches 1: the gear would lock under its own load"));
    }
  }
  const ThermalNodes warm = SteadyThermalNodes(m.motor.thermal_resistance_K_per_W, g, 0.0, g.warm_copper_loss_W,
                                              g.warm_friction_loss_W);
  if (!(warm.winding_C <= kMaxWarmRise_K && warm.gear_C <= kMaxWarmRise_K)) {
    errors->Add(InputError("", PointerJoin(pointer, warm.winding_C > kMaxWarmRise_K ? "warm_copper_loss_W" : "warm_friction_loss_W"),
                           "the warm duty (" + FormatNumber(g.warm_copper_loss_W) + " W copper, " +
                               FormatNumber(g.warm_friction_loss_W) + " W friction) holds the winding " +
                               FormatNumber(warm.winding_C) + " K and the gearbox " + FormatNumber(warm.gear_C) +
                               " K above ambient: at most 150 K"));
  }
  if (!(physics_rate_Hz > 0)) return;
  const double min_tau_s = kMinThermalSteps / physics_rate_Hz;
  const double gear_tau = g.thermal_time_constant_s / (1.0 + g.thermal_resistance_K_per_W * g.winding_coupling_W_per_K);
  const double winding_tau =
      m.motor.thermal_time_constant_s / (1.0 + m.motor.thermal_resistance_K_per_W * g.winding_coupling_W_per_K);
  if (gear_tau < min_tau_s) {
    errors->Add(InputError("", PointerJoin(pointer, "thermal_time_constant_s"),
                           "the gearbox node's time constant " + FormatNumber(gear_tau) + " s (thermal_time_constant_s " +
                               FormatNumber(g.thermal_time_constant_s) + " s over 1 + R G) is below " +
                               FormatNumber(min_tau_s) + " s, 100 physics steps"));
  }
  if (winding_tau < min_tau_s) {
    errors->Add(InputError("", PointerJoin(pointer, "winding_coupling_W_per_K"),
                           "winding_coupling_W_per_K " + FormatNumber(g.winding_coupling_W_per_K) +
                               " W/K makes the winding node's time constant " + FormatNumber(winding_tau) +
                               " s, below " + FormatNumber(min_tau_s) + " s, 100 physics steps"));
  }
}

const Fields<BrakeParams>& BrakeFields() {
  static const Fields<BrakeParams> f = {
      {"holding_torque_Nm", &BrakeParams::holding_torque_Nm, 0, 1000, false, false},
  };
  return f;
}
const Fields<TorqueSensorParams>& TorqueSensorFields() {
  static const Fields<TorqueSensorParams> f = {
      {"full_scale_Nm", &TorqueSensorParams::full_scale_Nm, 0, 1e5, true, false},
      {"offset_Nm", &TorqueSensorParams::offset_Nm, -1e5, 1e5, false, false},
      {"adc_range_V", &TorqueSensorParams::adc_range_V, 0, 100, true, false},
      {"adc_bits", &TorqueSensorParams::adc_bits, 4, 24, false, true},
      {"noise_Nm", &TorqueSensorParams::noise_Nm, 0, 100, false, false},
      {"gain_error", &TorqueSensorParams::gain_error, -0.5, 0.5, false, false},
      {"offset_error_Nm", &TorqueSensorParams::offset_error_Nm, -1e3, 1e3, false, false},
  };
  return f;
}
const Fields<EncoderParams>& EncoderFields() {
  static const Fields<EncoderParams> f = {
      {"counts_per_rev", &EncoderParams::counts_per_rev, 4, 1e8, false, true},
  };
  return f;
}
const Fields<ControllerParams>& ControllerFields() {
  static const Fields<ControllerParams> f = {
      {"rate_Hz", &ControllerParams::rate_Hz, 0, 1e5, true, false},
      {"lambda_per_s", &ControllerParams::lambda_per_s, 0, 1e4, true, false},
      {"kp_adaptive", &ControllerParams::kp_adaptive, 0, 1e3, false, false},
      {"ku_robust_Nm", &ControllerParams::ku_robust_Nm, 0, 100, false, false},
      {"epsilon_robust", &ControllerParams::epsilon_robust, 0, 100, true, false},
      {"kt_hat_Nm_per_A", &ControllerParams::kt_hat_Nm_per_A, 0, 10, true, false},
      {"b_hat", &ControllerParams::b_hat, 0, 10, false, false},
      {"fc_hat_Nm", &ControllerParams::fc_hat_Nm, 0, 100, false, false},
      {"fs_hat_Nm", &ControllerParams::fs_hat_Nm, 0, 100, false, false},
      {"ft_hat", &ControllerParams::ft_hat, 0, 1e6, false, false},
      {"im_hat_kg_m2", &ControllerParams::im_hat_kg_m2, 0, 1, false, false},
      {"torque_filter_rad_s", &ControllerParams::torque_filter_rad_s, 0, 1e5, true, false},
      {"velocity_window", &ControllerParams::velocity_window, 1, 64, false, true},
      {"velocity_min_counts", &ControllerParams::velocity_min_counts, 1, 1e6, false, true},
  };
  return f;
}

// The optional "ripple" group (core/plant/parts/torque_ripple.h; ranges: docs/assumptions.md, "Torque
// ripple"): kinematic errors up to 10 arcmin (catalogues state 0.5 to 2 arcmin in all), stiffness
// up to 1e7 N m/rad (above the largest strain-wave gears' 1e6), cogging up to 10 N m on the motor
// shaft, at most 1000 periods per revolution.
const Fields<RippleParams>& RippleFields() {
  static const Fields<RippleParams> f = {
      {"kinematic_error_2x_arcmin", &RippleParams::kinematic_error_2x_arcmin, 0, 10, false, false},
      {"kinematic_error_1x_arcmin", &RippleParams::kinematic_error_1x_arcmin, 0, 10, false, false},
      {"phase_2x_deg", &RippleParams::phase_2x_deg, -360, 360, false, false},
      {"phase_1x_deg", &RippleParams::phase_1x_deg, -360, 360, false, false},
      {"drive_stiffness_Nm_per_rad", &RippleParams::drive_stiffness_Nm_per_rad, 0, 1e7, false, false},
      {"cogging_Nm", &RippleParams::cogging_Nm, 0, 10, false, false},
      {"cogging_periods_per_rev", &RippleParams::cogging_periods_per_rev, 1, 1000, false, true},
      {"cogging_phase_deg", &RippleParams::cogging_phase_deg, -360, 360, false, false},
  };
  return f;
}

// The same ranges on values already in a struct (a robot built in code, or read and then
// changed): what Validate checks. Throws InputError naming the first bad field's pointer.
template <class T>
void CheckFields(const Fields<T>& fields, const T& in, const std::string& pointer) {
  ErrorList errors;
  for (const Field<T>& field : fields) {
    errors.Try([&] {
      const double x = in.*field.member;
      const std::string ptr = PointerJoin(pointer, field.key);
      if (field.min_exclusive) RequireAbove(x, field.min, ptr);
      RequireInRange(x, field.min, field.max, ptr);
      if (field.integer && x != std::floor(x)) throw InputError("", ptr, "expected a whole number, got " + FormatNumber(x));
    });
  }
  errors.ThrowIfAny();
}

// Each field is checked on its own, so one call reports every bad field and unknown key.
template <class T>
void ReadFields(ObjectReader& reader, const Fields<T>& fields, T* out) {
  std::vector<std::string> keys;
  for (const Field<T>& field : fields) keys.push_back(field.key);
  ErrorList errors;
  errors.Try([&] { reader.AllowOnly(keys); });
  for (const Field<T>& field : fields) {
    errors.Try([&] {
      const nlohmann::json* v = reader.Find(field.key);
      if (v == nullptr) return;
      const std::string ptr = reader.PointerTo(field.key);
      double x = field.integer ? AsInt(*v, ptr) : AsNumber(*v, ptr);
      if (field.min_exclusive) {
        RequireAbove(x, field.min, ptr);
        RequireInRange(x, field.min, field.max, ptr);
      } else {
        RequireInRange(x, field.min, field.max, ptr);
      }
      out->*field.member = x;
    });
  }
  errors.ThrowIfAny();
}

template <class T>
void ReadGroup(ObjectReader& parent, const char* key, const Fields<T>& fields, T* out) {
  if (const nlohmann::json* v = parent.Find(key)) {
    ObjectReader reader(*v, parent.PointerTo(key));
    ReadFields(reader, fields, out);
  }
}

template <class T>
nlohmann::json WriteFields(const Fields<T>& fields, const T& in) {
  nlohmann::json out = nlohmann::json::object();
  for (const Field<T>& field : fields) out[field.key] = in.*field.member;
  return out;
}

std::array<double, 3> ReadVector3(const nlohmann::json& v, const std::string& pointer) {
  if (!v.is_array() || v.size() != 3) {
    throw InputError("", pointer, "expected an array of 3 numbers, got " + Describe(v));
  }
  std::array<double, 3> out{};
  for (size_t i = 0; i < 3; ++i) out[i] = AsNumber(v[i], PointerJoin(pointer, i));
  return out;
}

double Norm(const std::array<double, 3>& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Physical limits of a link and of the base (docs/assumptions.md, "Physical limits of the robot
// input"): far beyond any arm armfault models, tight enough that every derived number (anchors,
// inertias, squared norms) stays finite. The floors of masses and moments: mass_properties.h.
constexpr double kMaxLinkMass_kg = 1000;      // a ton on one joint module
constexpr double kMaxLinkLength_m = 10;
constexpr double kMinLinkRadius_m = 1e-3;     // a 1 mm rod
constexpr double kMaxLinkRadius_m = 1;
constexpr double kMaxMoment_kg_m2 = 1e5;      // above a 1000 kg, 10 m rod about its end (3.3e4)
constexpr double kMaxVectorComponent = 1e6;   // direction and joint_axis: the squared norm stays finite
constexpr double kMinVectorNorm = 1e-9;       // ... and normalises
constexpr double kMaxBasePosition_m = 1000;   // per coordinate

// One check per link value, used by LinkFromJson (on the file's values) and by Validate (on any
// robot, including one built in code); each throws InputError naming `pointer` and the value.
void CheckVector(const std::array<double, 3>& v, const std::string& pointer, const char* what) {
  ErrorList errors;
  for (size_t i = 0; i < 3; ++i) {
    errors.Try([&] { RequireInRange(v[i], -kMaxVectorComponent, kMaxVectorComponent, PointerJoin(pointer, i)); });
  }
  errors.ThrowIfAny();
  if (Norm(v) < kMinVectorNorm) throw InputError("", pointer, std::string("the ") + what + " must not be the zero vector");
}

// `mass_kg`: the link's own mass, already checked.
void CheckMoments(const std::array<double, 3>& moments, double mass_kg, const std::string& pointer) {
  ErrorList errors;
  for (size_t i = 0; i < 3; ++i) {
    errors.Try([&] { RequireInRange(moments[i], kMinMoment_kg_m2, kMaxMoment_kg_m2, PointerJoin(pointer, i)); });
  }
  errors.ThrowIfAny();
  // No body of a link's mass is more compact than the smallest cylinder the radius floor
  // allows: a disc of radius kMinLinkRadius_m about a diameter, m r^2 / 4.
  const double min_moment = mass_kg * kMinLinkRadius_m * kMinLinkRadius_m / 4;
  for (size_t i = 0; i < 3; ++i) {
    if (moments[i] < min_moment) {
      throw InputError("", PointerJoin(pointer, i),
                       FormatNumber(moments[i]) + " kg m^2 is below " + FormatNumber(min_moment) +
                           " kg m^2, the smallest moment of a " + FormatNumber(mass_kg) +
                           " kg link (a disc of radius 1 mm about a diameter)");
    }
  }
  // A rigid body's principal moments obey I_a <= I_b + I_c (equal for a flat plate); a part in
  // a million of slack for decimal values such as 0.01 + 0.02 = 0.03.
  for (size_t i = 0; i < 3; ++i) {
    const double others = moments[(i + 1) % 3] + moments[(i + 2) % 3];
    if (moments[i] > others * (1 + 1e-6)) {
      throw InputError("", PointerJoin(pointer, i),
                       FormatNumber(moments[i]) + " kg m^2 exceeds the sum of the other two principal moments (" +
                           FormatNumber(others) + " kg m^2): no rigid body has these moments");
    }
  }
}

void CheckLinkMass(double v, const std::string& p) { RequireInRange(v, kMinBodyMass_kg, kMaxLinkMass_kg, p); }
void CheckLinkLength(double v, const std::string& p) { RequireInRange(v, 0, kMaxLinkLength_m, p); }
void CheckLinkRadius(double v, const std::string& p) { RequireInRange(v, kMinLinkRadius_m, kMaxLinkRadius_m, p); }
void CheckComFraction(double v, const std::string& p) { RequireInRange(v, 0, 1, p); }

// Records its errors in `errors` and returns what it could read (the type's defaults where a
// value is bad), so the robot's cross-field checks still see one module per joint. Throws only
// when `value` is not an object.
ModuleParams ModuleFromJson(const nlohmann::json& value, const std::string& pointer, ErrorList* errors) {
  ObjectReader reader(value, pointer);
  errors->Try([&] {
    reader.AllowOnly({"type", "min_angle_deg", "max_angle_deg", "motor", "inverter", "drive", "friction", "brake",
                      "torque_sensor", "encoder", "controller", "winding_temperature_sensor", "ripple", "gearbox"});
  });
  std::string type = "MRR2";
  ModuleParams m;
  // An unknown type leaves the MRR2 defaults under the other keys, which are still checked.
  errors->Try([&] {
    reader.OptionalString("type", &type);
    m = ModuleDefaults(type, reader.PointerTo("type"));
  });
  errors->Try([&] { reader.OptionalNumber("min_angle_deg", &m.min_angle_deg); });
  errors->Try([&] { reader.OptionalNumber("max_angle_deg", &m.max_angle_deg); });
  errors->Try([&] { ReadGroup(reader, "motor", MotorFields(), &m.motor); });
  errors->Try([&] { ReadGroup(reader, "inverter", InverterFields(), &m.inverter); });
  errors->Try([&] { ReadGroup(reader, "drive", DriveFields(), &m.drive); });
  errors->Try([&] { ReadGroup(reader, "friction", FrictionFields(), &m.friction); });
  errors->Try([&] { ReadGroup(reader, "brake", BrakeFields(), &m.brake); });
  errors->Try([&] {
    const nlohmann::json* v = reader.Find("torque_sensor");
    if (v && v->is_null()) {
      m.torque_sensor.present = false;  // no sensor on this joint
    } else if (v && !v->is_object()) {
      throw InputError("", reader.PointerTo("torque_sensor"),
                       "expected an object (the sensor's parameters) or null (no torque sensor), got " + std::string(v->type_name()) + " " + Describe(*v));
    } else {
      ReadGroup(reader, "torque_sensor", TorqueSensorFields(), &m.torque_sensor);
      if (v) m.torque_sensor.present = true;  // overrides give the type's absent sensor back
    }
  });
  errors->Try([&] {
    // "gearbox": null switches a thermal drive type's group off; an object turns it on.
    const nlohmann::json* v = reader.Find("gearbox");
    if (v && v->is_null()) {
      m.gearbox.present = false;
    } else if (v && !v->is_object()) {
      throw InputError("", reader.PointerTo("gearbox"),
                       "expected an object (the gearbox's thermal, lubricant, load-friction and sensor-drift parameters) "
                       "or null (off), got " + std::string(v->type_name()) + " " + Describe(*v));
    } else if (v) {
      ReadGroup(reader, "gearbox", GearboxFields(), &m.gearbox);
      m.gearbox.present = true;
    }
  });
  errors->Try([&] { ReadGroup(reader, "encoder", EncoderFields(), &m.encoder); });
  errors->Try([&] { ReadGroup(reader, "controller", ControllerFields(), &m.controller); });
  errors->Try([&] {
    if (!reader.Find("ripple")) return;
    m.ripple.enabled = true;  // given: on, with the defaults for the keys left out
    ReadGroup(reader, "ripple", RippleFields(), &m.ripple);
  });
  errors->Try([&] {
    if (const nlohmann::json* v = reader.Find("winding_temperature_sensor")) {
      if (!v->is_boolean()) {
        throw InputError("", reader.PointerTo("winding_temperature_sensor"), "expected true or false, got " + Describe(*v));
      }
      m.winding_temperature_sensor = v->get<bool>();
    }
  });
  return m;
}

// Like ModuleFromJson: errors go to `errors`, defaults stand in for bad values (so Validate's
// checks of the built bodies see only values that passed their own checks).
LinkParams LinkFromJson(const nlohmann::json& value, const std::string& pointer, ErrorList* errors) {
  ObjectReader reader(value, pointer);
  errors->Try([&] {
    reader.AllowOnly({"mass_kg", "length_m", "radius_m", "com_fraction", "direction", "joint_axis", "inertia_kg_m2"});
  });
  LinkParams link;
  auto number = [&](const char* key, double* out, void (*check)(double, const std::string&)) {
    errors->Try([&] {
      double v = *out;
      reader.OptionalNumber(key, &v);
      check(v, reader.PointerTo(key));
      *out = v;
    });
  };
  number("mass_kg", &link.mass_kg, &CheckLinkMass);
  number("length_m", &link.length_m, &CheckLinkLength);
  number("radius_m", &link.radius_m, &CheckLinkRadius);
  number("com_fraction", &link.com_fraction, &CheckComFraction);
  errors->Try([&] {
    if (const auto* v = reader.Find("direction")) {
      const std::array<double, 3> d = ReadVector3(*v, reader.PointerTo("direction"));
      CheckVector(d, reader.PointerTo("direction"), "link direction");
      link.direction = d;
    }
  });
  errors->Try([&] {
    if (const auto* v = reader.Find("joint_axis")) {
      const std::array<double, 3> a = ReadVector3(*v, reader.PointerTo("joint_axis"));
      CheckVector(a, reader.PointerTo("joint_axis"), "joint axis");
      link.joint_axis = a;
    }
  });
  errors->Try([&] {
    if (const auto* v = reader.Find("inertia_kg_m2")) {
      const std::array<double, 3> moments = ReadVector3(*v, reader.PointerTo("inertia_kg_m2"));
      CheckMoments(moments, link.mass_kg, reader.PointerTo("inertia_kg_m2"));
      link.inertia_kg_m2 = moments;
      link.has_inertia = true;
    }
  });
  return link;
}

// A body of the general form (JointBody): world coordinates at the zero pose, as RobotToJson
// writes a URDF robot. Errors go to `errors`; bad values leave the defaults.
JointBody BodyFromJson(const nlohmann::json& value, const std::string& pointer, ErrorList* errors) {
  ObjectReader reader(value, pointer);
  errors->Try([&] {
    reader.AllowOnly({"joint_name", "anchor_m", "axis", "mass_kg", "com_m", "inertia_kg_m2", "frame_origin_m",
                      "frame_rotation"});
  });
  JointBody b;
  errors->Try([&] { reader.OptionalString("joint_name", &b.joint_name); });
  auto vector3 = [&](const char* key, std::array<double, 3>* out, bool direction) {
    errors->Try([&] {
      if (const auto* v = reader.Find(key)) {
        const std::array<double, 3> a = ReadVector3(*v, reader.PointerTo(key));
        if (direction) CheckVector(a, reader.PointerTo(key), "joint axis");
        for (size_t i = 0; i < 3 && !direction; ++i) {
          RequireInRange(a[i], -kMaxBasePosition_m, kMaxBasePosition_m, PointerJoin(reader.PointerTo(key), i));
        }
        *out = a;
      }
    });
  };
  vector3("anchor_m", &b.anchor_m, false);
  vector3("axis", &b.axis, true);
  vector3("com_m", &b.com_m, false);
  vector3("frame_origin_m", &b.frame_origin_m, false);
  errors->Try([&] {
    double m = b.mass_kg;
    reader.OptionalNumber("mass_kg", &m);
    CheckLinkMass(m, reader.PointerTo("mass_kg"));
    b.mass_kg = m;
  });
  auto numbers = [&](const char* key, double* out, size_t n, double lo, double hi) {
    errors->Try([&] {
      const auto* v = reader.Find(key);
      if (!v) return;
      if (!v->is_array() || v->size() != n) {
        throw InputError("", reader.PointerTo(key), "expected an array of " + std::to_string(n) + " numbers, got " + Describe(*v));
      }
      std::vector<double> read(n);
      for (size_t i = 0; i < n; ++i) {
        read[i] = AsNumber((*v)[i], PointerJoin(reader.PointerTo(key), i));
        RequireInRange(read[i], lo, hi, PointerJoin(reader.PointerTo(key), i));
      }
      std::copy(read.begin(), read.end(), out);
    });
  };
  numbers("inertia_kg_m2", b.inertia_kg_m2.data(), 6, -kMaxMoment_kg_m2, kMaxMoment_kg_m2);
  numbers("frame_rotation", b.frame_rotation.data(), 9, -1.0 - 1e-9, 1.0 + 1e-9);
  return b;
}

nlohmann::json BodyToJson(const JointBody& b) {
  return {{"joint_name", b.joint_name}, {"anchor_m", b.anchor_m}, {"axis", b.axis},
          {"mass_kg", b.mass_kg},       {"com_m", b.com_m},       {"inertia_kg_m2", b.inertia_kg_m2},
          {"frame_origin_m", b.frame_origin_m}, {"frame_rotation", b.frame_rotation}};
}

}  // namespace

const char* EngineName(PhysicsEngine engine) { return engine == PhysicsEngine::kOde ? "ode" : "articulated"; }

std::vector<std::string> EngineNames() { return {"ode", "articulated"}; }

PhysicsEngine EngineFromJson(const nlohmann::json& value, const std::string& pointer) {
  if (!value.is_string()) throw InputError("", pointer, "expected \"ode\" or \"articulated\", got " + Describe(value));
  const std::string name = value.get<std::string>();
  if (name == "ode") return PhysicsEngine::kOde;
  if (name == "articulated") return PhysicsEngine::kArticulated;
  const std::string near = NearestWord(name, EngineNames());
  throw InputError("", pointer, "unknown engine " + Describe(value) + " (known: ode, articulated)",
                   near.empty() ? "" : "did you mean \"" + near + "\"?");
}

void CheckEngineTakes(const RobotConfig& robot, const std::string& pointer) {
  // Every robot armfault reads is a serial chain of revolute joints (a URDF's branches and
  // prismatic joints are refused as it is read, for either engine); the count is the limit.
  const size_t n = robot.modules.size();
  if (robot.engine == PhysicsEngine::kArticulated && n > static_cast<size_t>(kMaxArticulatedJoints)) {
    throw InputError("", pointer, "the articulated engine takes serial chains of 1 to " +
                                      std::to_string(kMaxArticulatedJoints) + " revolute joints; this robot has " +
                                      std::to_string(n) + " joints (use \"engine\": \"ode\")");
  }
}

RobotConfig RobotFromJson(const nlohmann::json& value, const std::string& pointer, const std::string& base_dir) {
  if (value.is_string()) {
    RobotConfig r = RobotPreset(value.get<std::string>(), pointer);
    Validate(r, pointer);
    return r;
  }
  if (value.is_object() && value.contains("urdf")) {
    RobotConfig r = RobotFromUrdfJson(value, pointer, base_dir);
    Validate(r, pointer);
    return r;
  }
  ObjectReader reader(value, pointer);
  // Every part is read on its own and all errors are reported together (ErrorList).
  ErrorList errors;
  // "links" (the shorthand) or "bodies" (the general form, as a URDF robot is written out).
  const bool general = value.is_object() && value.contains("bodies");
  errors.Try([&] {
    if (general) {
      reader.AllowOnly({"name", "modules", "bodies", "payload_point_m", "base_position_m", "payload_kg", "gravity_m_s2",
                        "physics_rate_Hz", "electrical_substeps", "constraint_force_mixing", "engine"});
    } else {
      reader.AllowOnly({"name", "modules", "links", "base_position_m", "payload_kg", "gravity_m_s2", "physics_rate_Hz",
                        "electrical_substeps", "constraint_force_mixing", "engine"});
    }
  });
  RobotConfig r;
  errors.Try([&] { reader.OptionalString("name", &r.name); });
  const nlohmann::json* modules = nullptr;
  const nlohmann::json* links = nullptr;
  errors.Try([&] { modules = &reader.Require("modules"); });
  errors.Try([&] { links = &reader.Require(general ? "bodies" : "links"); });
  if (modules && (!modules->is_array() || modules->empty())) {
    errors.Add(InputError("", reader.PointerTo("modules"), "expected a non-empty array of modules, got " + Describe(*modules)));
    modules = nullptr;
  }
  if (links && !links->is_array()) {
    errors.Add(InputError("", reader.PointerTo(general ? "bodies" : "links"),
                          std::string("expected an array of ") + (general ? "bodies" : "links") + ", got " + Describe(*links)));
    links = nullptr;
  }
  // A module or link that is not even an object is replaced by the defaults, so the counts
  // the cross-field checks compare stay those of the file.
  for (size_t i = 0; modules && i < modules->size(); ++i) {
    ModuleParams m;
    errors.Try([&] { m = ModuleFromJson((*modules)[i], PointerJoin(reader.PointerTo("modules"), i), &errors); });
    r.modules.push_back(m);
  }
  for (size_t i = 0; links && i < links->size(); ++i) {
    if (general) {
      JointBody body;
      errors.Try([&] { body = BodyFromJson((*links)[i], PointerJoin(reader.PointerTo("bodies"), i), &errors); });
      if (body.joint_name.empty()) body.joint_name = "joint_" + std::to_string(i + 1);
      r.bodies.push_back(body);
      continue;
    }
    LinkParams link;
    errors.Try([&] { link = LinkFromJson((*links)[i], PointerJoin(reader.PointerTo("links"), i), &errors); });
    r.links.push_back(link);
  }
  if (general) {
    errors.Try([&] {
      if (const auto* v = reader.Find("payload_point_m")) r.payload_point_m = ReadVector3(*v, reader.PointerTo("payload_point_m"));
    });
    if (links && links->empty()) {
      errors.Add(InputError("", reader.PointerTo("bodies"), "expected one body per module, got an empty array"));
      links = nullptr;  // the count check below would name "links"
    }
  }
  bool top_level_read = modules && links;
  top_level_read &= errors.Try([&] {
    if (const auto* v = reader.Find("base_position_m")) r.base_position_m = ReadVector3(*v, reader.PointerTo("base_position_m"));
  });
  top_level_read &= errors.Try([&] { reader.OptionalNumber("payload_kg", &r.payload_kg); });
  top_level_read &= errors.Try([&] { reader.OptionalNumber("gravity_m_s2", &r.gravity_m_s2); });
  top_level_read &= errors.Try([&] { reader.OptionalNumber("physics_rate_Hz", &r.physics_rate_Hz); });
  top_level_read &= errors.Try([&] { reader.OptionalInt("electrical_substeps", &r.electrical_substeps); });
  top_level_read &= errors.Try([&] { reader.OptionalNumber("constraint_force_mixing", &r.constraint_force_mixing); });
  errors.Try([&] {
    if (const auto* v = reader.Find("engine")) r.engine = EngineFromJson(*v, reader.PointerTo("engine"));
  });
  // The cross-field checks need the robot's own counts and rates; bad values inside a module
  // or link left their defaults, which these checks accept.
  if (top_level_read) errors.Try([&] { Validate(r, pointer); });
  errors.ThrowIfAny();
  return r;
}

namespace {

// Validate's checks: each records its errors in `errors`, in the order Validate reports them.

// One link, or one body, per joint module.
void CheckJointCounts(const RobotConfig& r, const std::string& pointer, ErrorList* errors) {
  if (!r.bodies.empty()) {
    if (!r.links.empty()) {
      errors->Add(InputError("", PointerJoin(pointer, "links"), "give links or bodies, not both"));
    }
    if (r.bodies.size() != r.modules.size()) {
      errors->Add(InputError("", PointerJoin(pointer, "bodies"),
                             std::to_string(r.bodies.size()) + " bodies for " + std::to_string(r.modules.size()) +
                                 " modules: give one body per joint module"));
    }
  } else if (r.links.size() != r.modules.size()) {
    errors->Add(InputError("", PointerJoin(pointer, "links"),
                           std::to_string(r.links.size()) + " links for " + std::to_string(r.modules.size()) +
                               " modules: give one link per joint module"));
  }
}

// Module i: its joint range, its rotor body, its optional groups and its controller rate.
// `rate_ok`: the robot's physics rate is in range (the gearbox and rate checks need it).
void CheckModule(const RobotConfig& r, size_t i, bool rate_ok, const std::string& pointer, ErrorList* errors) {
  const ModuleParams& m = r.modules[i];
  const std::string mp = PointerJoin(PointerJoin(pointer, "modules"), i);
  // An empty range makes the bounds' own checks moot: one error for the pair.
  if (!(m.min_angle_deg < m.max_angle_deg)) {
    errors->Add(InputError("", PointerJoin(mp, "max_angle_deg"),
                           "the joint range [" + FormatNumber(m.min_angle_deg) + ", " +
                               FormatNumber(m.max_angle_deg) + "] deg is empty"));
  } else {
    // A range need not contain 0 (URDF arms have joints limited to one side of it).
    errors->Try([&] { RequireInRange(m.min_angle_deg, -360, 360, PointerJoin(mp, "min_angle_deg")); });
    errors->Try([&] { RequireInRange(m.max_angle_deg, -360, 360, PointerJoin(mp, "max_angle_deg")); });
  }
  // The rotor body ODE gets: its inertia after any tolerance draw (a campaign's unit), which
  // the field table's floor does not see.
  const double im = m.motor.rotor_inertia_kg_m2;
  const std::string rotor_problem = BodyMassProblem(kRotorMass_kg, im * Eigen::Matrix3d::Identity());
  if (!rotor_problem.empty()) {
    errors->Add(InputError("", PointerJoin(PointerJoin(mp, "motor"), "rotor_inertia_kg_m2"),
                           "the rotor body's " + rotor_problem));
  }
  if (m.ripple.enabled) errors->Try([&] { CheckFields(RippleFields(), m.ripple, PointerJoin(mp, "ripple")); });
  if (m.gearbox.present) CheckGearbox(m, rate_ok ? r.physics_rate_Hz : 0.0, PointerJoin(mp, "gearbox"), errors);
  // The controller runs every k physics steps: the rates must divide (needs a valid physics rate).
  double k = r.physics_rate_Hz / m.controller.rate_Hz;
  if (rate_ok && (std::fabs(k - std::round(k)) > 1e-9 || k < 1)) {
    errors->Add(InputError("", PointerJoin(PointerJoin(mp, "controller"), "rate_Hz"),
                           FormatNumber(m.controller.rate_Hz) + " Hz must divide the physics rate " +
                               FormatNumber(r.physics_rate_Hz) + " Hz"));
  }
}

// Every link's values (a robot built in code has not been through LinkFromJson), then its
// body as ODE gets it (the payload lumped into the last): mass and inertia above the floors.
// `payload_ok`: the payload is in range (else the last body is checked without it).
void CheckLinks(const RobotConfig& r, bool payload_ok, const std::string& pointer, ErrorList* errors) {
  for (size_t i = 0; i < r.links.size(); ++i) {
    const LinkParams& l = r.links[i];
    const std::string lp = PointerJoin(PointerJoin(pointer, "links"), i);
    bool ok = errors->Try([&] { CheckLinkMass(l.mass_kg, PointerJoin(lp, "mass_kg")); });
    ok &= errors->Try([&] { CheckLinkLength(l.length_m, PointerJoin(lp, "length_m")); });
    ok &= errors->Try([&] { CheckLinkRadius(l.radius_m, PointerJoin(lp, "radius_m")); });
    ok &= errors->Try([&] { CheckComFraction(l.com_fraction, PointerJoin(lp, "com_fraction")); });
    ok &= errors->Try([&] { CheckVector(l.direction, PointerJoin(lp, "direction"), "link direction"); });
    ok &= errors->Try([&] { CheckVector(l.joint_axis, PointerJoin(lp, "joint_axis"), "joint axis"); });
    if (l.has_inertia && ok) ok &= errors->Try([&] { CheckMoments(l.inertia_kg_m2, l.mass_kg, PointerJoin(lp, "inertia_kg_m2")); });
    if (!ok) continue;
    const bool last = i + 1 == r.links.size();
    const double payload = last && payload_ok ? r.payload_kg : 0.0;
    const Eigen::Vector3d dir = Eigen::Vector3d(l.direction[0], l.direction[1], l.direction[2]).normalized();
    const Eigen::Vector3d axis = Eigen::Vector3d(l.joint_axis[0], l.joint_axis[1], l.joint_axis[2]).normalized();
    const BodyMass body = LinkBody(l, Eigen::Vector3d::Zero(), dir, axis, payload);
    const std::string problem = BodyMassProblem(body.mass_kg, body.inertia_kg_m2);
    if (problem.empty()) continue;
    // Only the cylinder's moments can fall below the floor when every value is in range.
    const std::string what = l.has_inertia ? "the given principal moments"
                                           : "a solid cylinder of " + FormatNumber(l.mass_kg) + " kg, radius " +
                                                 FormatNumber(l.radius_m) + " m and length " + FormatNumber(l.length_m) + " m";
    errors->Add(InputError("", PointerJoin(lp, l.has_inertia ? "inertia_kg_m2" : "radius_m"),
                           "link " + std::to_string(i + 1) + "'s body (" + what + (payload > 0 ? ", with the payload" : "") +
                               "): " + problem));
  }
}

// The general form's bodies as ODE gets them (the payload lumped into the last).
// `payload_ok`: the payload is in range (else the last body is checked without it).
void CheckBodies(const RobotConfig& r, bool payload_ok, const std::string& pointer, ErrorList* errors) {
  for (size_t k = 0; k < 3 && !r.bodies.empty(); ++k) {
    errors->Try([&] {
      RequireInRange(r.payload_point_m[k], -kMaxBasePosition_m, kMaxBasePosition_m,
                     PointerJoin(PointerJoin(pointer, "payload_point_m"), k));
    });
  }
  for (size_t i = 0; i < r.bodies.size(); ++i) {
    const std::string bp = PointerJoin(PointerJoin(pointer, "bodies"), i);
    const bool last = i + 1 == r.bodies.size();
    const JointBody& jb = r.bodies[i];
    bool in_range = errors->Try([&] { CheckVector(jb.axis, PointerJoin(bp, "axis"), "joint axis"); });
    in_range &= errors->Try([&] { CheckLinkMass(jb.mass_kg, PointerJoin(bp, "mass_kg")); });
    for (size_t k = 0; k < 3; ++k) {
      in_range &= errors->Try([&] {
        RequireInRange(jb.anchor_m[k], -kMaxBasePosition_m, kMaxBasePosition_m, PointerJoin(PointerJoin(bp, "anchor_m"), k));
      });
      in_range &= errors->Try([&] {
        RequireInRange(jb.com_m[k], -kMaxBasePosition_m, kMaxBasePosition_m, PointerJoin(PointerJoin(bp, "com_m"), k));
      });
    }
    for (size_t k = 0; k < 6; ++k) {
      in_range &= errors->Try([&] {
        RequireInRange(jb.inertia_kg_m2[k], -kMaxMoment_kg_m2, kMaxMoment_kg_m2, PointerJoin(PointerJoin(bp, "inertia_kg_m2"), k));
      });
    }
    if (!in_range) continue;
    const BodyMass body = BodyOfJoint(r, static_cast<int>(i), last && payload_ok ? r.payload_kg : 0.0);
    const std::string problem = BodyMassProblem(body.mass_kg, body.inertia_kg_m2);
    if (!problem.empty()) {
      errors->Add(InputError("", bp, "the body joint \"" + r.bodies[i].joint_name + "\" moves: its " + problem));
    }
  }
}

}  // namespace

void Validate(const RobotConfig& r, const std::string& pointer) {
  if (r.modules.empty()) throw InputError("", PointerJoin(pointer, "modules"), "the robot has no modules");
  ErrorList errors;  // the checks below are independent, except where noted
  CheckJointCounts(r, pointer, &errors);
  const bool payload_ok = errors.Try([&] { RequireInRange(r.payload_kg, 0, 100, PointerJoin(pointer, "payload_kg")); });
  for (size_t i = 0; i < 3; ++i) {
    errors.Try([&] {
      RequireInRange(r.base_position_m[i], -kMaxBasePosition_m, kMaxBasePosition_m,
                     PointerJoin(PointerJoin(pointer, "base_position_m"), i));
    });
  }
  errors.Try([&] { RequireInRange(r.gravity_m_s2, 0, 100, PointerJoin(pointer, "gravity_m_s2")); });
  const bool rate_ok = errors.Try([&] { RequireInRange(r.physics_rate_Hz, 100, 1e5, PointerJoin(pointer, "physics_rate_Hz")); });
  errors.Try([&] { RequireInRange(r.electrical_substeps, 1, 1000, PointerJoin(pointer, "electrical_substeps")); });
  // Above 1e-6 the gear rows go soft enough to move accelerations by tens of percent (2.6x of the
  // largest at 1e-5 on ur-class); 0 is exact and solvable since no constraint is redundant.
  errors.Try([&] { RequireInRange(r.constraint_force_mixing, 0, 1e-6, PointerJoin(pointer, "constraint_force_mixing")); });
  errors.Try([&] { CheckEngineTakes(r, PointerJoin(pointer, "engine")); });
  for (size_t i = 0; i < r.modules.size(); ++i) CheckModule(r, i, rate_ok, pointer, &errors);
  CheckLinks(r, payload_ok, pointer, &errors);
  CheckBodies(r, payload_ok, pointer, &errors);
  errors.ThrowIfAny();
}

std::array<double, 3> JointAxisOf(const RobotConfig& r, int joint) {
  return r.bodies.empty() ? r.links.at(joint).joint_axis : r.bodies.at(joint).axis;
}

ModuleParams DriveFromJson(const nlohmann::json& value, const std::string& pointer, ErrorList* errors) {
  return ModuleFromJson(value, pointer, errors);
}

nlohmann::json RobotToJson(const RobotConfig& r) {
  nlohmann::json out;
  out["name"] = r.name;
  for (const ModuleParams& m : r.modules) {
    nlohmann::json jm;
    jm["type"] = m.type;
    jm["min_angle_deg"] = m.min_angle_deg;
    jm["max_angle_deg"] = m.max_angle_deg;
    jm["motor"] = WriteFields(MotorFields(), m.motor);
    jm["inverter"] = WriteFields(InverterFields(), m.inverter);
    jm["drive"] = WriteFields(DriveFields(), m.drive);
    jm["friction"] = WriteFields(FrictionFields(), m.friction);
    jm["brake"] = WriteFields(BrakeFields(), m.brake);
    jm["torque_sensor"] = m.torque_sensor.present ? WriteFields(TorqueSensorFields(), m.torque_sensor) : nlohmann::json();
    jm["encoder"] = WriteFields(EncoderFields(), m.encoder);
    jm["controller"] = WriteFields(ControllerFields(), m.controller);
    jm["winding_temperature_sensor"] = m.winding_temperature_sensor;
    if (m.ripple.enabled) jm["ripple"] = WriteFields(RippleFields(), m.ripple);  // absent: off
    // Absent for a type without the group; null where the type's own group is switched off, so it reads back off.
    if (m.gearbox.present) jm["gearbox"] = WriteFields(GearboxFields(), m.gearbox);
    else if (TypeHasGearbox(m.type)) jm["gearbox"] = nullptr;
    out["modules"].push_back(jm);
  }
  for (const JointBody& b : r.bodies) out["bodies"].push_back(BodyToJson(b));
  if (!r.bodies.empty()) out["payload_point_m"] = r.payload_point_m;
  for (const LinkParams& l : r.links) {
    nlohmann::json jl = {{"mass_kg", l.mass_kg},       {"length_m", l.length_m},
                         {"radius_m", l.radius_m},     {"com_fraction", l.com_fraction},
                         {"direction", l.direction},   {"joint_axis", l.joint_axis}};
    if (l.has_inertia) jl["inertia_kg_m2"] = l.inertia_kg_m2;
    out["links"].push_back(jl);
  }
  out["base_position_m"] = r.base_position_m;
  out["payload_kg"] = r.payload_kg;
  out["gravity_m_s2"] = r.gravity_m_s2;
  out["physics_rate_Hz"] = r.physics_rate_Hz;
  out["electrical_substeps"] = r.electrical_substeps;
  out["constraint_force_mixing"] = r.constraint_force_mixing;
  // Only when not the default, so that an ODE robot is written out as before.
  if (r.engine != PhysicsEngine::kOde) out["engine"] = EngineName(r.engine);
  return out;
}

}  // namespace armfault
