// MonitorConfig <-> JSON, driven by one table so parsing, checks and output cannot drift.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "core/monitors/monitor_config.h"

#include "core/base/json_input.h"
#include "core/base/suggest.h"

namespace armfault {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct NumberField {
  const char* key;
  double MonitorConfig::*member;
  double min, max;  // inclusive
};
struct IntField {
  const char* key;
  int MonitorConfig::*member;
  int min, max;
};
enum class Direction { kBelow, kAbove, kMagnitude };
struct LimitField {
  const char* key;
  StateLimits MonitorConfig::*member;
  Direction direction;  // kBelow: healthy 1, falls; kAbove: healthy 1, rises; kMagnitude: |x| rises from 0
};

const std::vector<NumberField>& NumberFields() {
  static const std::vector<NumberField> f = {
      {"rest_velocity_rad_s", &MonitorConfig::rest_velocity_rad_s, 1e-6, 10},
      {"min_window_s", &MonitorConfig::min_window_s, 0, 1e3},
      {"min_window_energy_J", &MonitorConfig::min_window_energy_J, 0, 1e6},
      {"electrical_time_constant_s", &MonitorConfig::electrical_time_constant_s, 0.01, 1e3},
      {"min_rotor_energy_J", &MonitorConfig::min_rotor_energy_J, 0, 1e6},
      {"min_copper_energy_J", &MonitorConfig::min_copper_energy_J, 0, 1e6},
      {"significance", &MonitorConfig::significance, 0, 100},
      {"debounce_s", &MonitorConfig::debounce_s, 0, 1e3},
      {"overpower_W", &MonitorConfig::overpower_W, 0, 1e6},
      {"overpower_time_s", &MonitorConfig::overpower_time_s, 0, 1e3},
      {"dead_drive_current_A", &MonitorConfig::dead_drive_current_A, 0, 1e4},
      {"dead_drive_time_s", &MonitorConfig::dead_drive_time_s, 0, 1e3},
      {"stuck_time_s", &MonitorConfig::stuck_time_s, 0, 1e3},
      {"stuck_torque_span_Nm", &MonitorConfig::stuck_torque_span_Nm, 0, 1e6},
      {"rail_time_s", &MonitorConfig::rail_time_s, 0, 1e3},
      {"blocked_current_A", &MonitorConfig::blocked_current_A, 0, 1e4},
      {"blocked_error_rad", &MonitorConfig::blocked_error_rad, 0, 10},
      {"blocked_time_s", &MonitorConfig::blocked_time_s, 0, 1e3},
      {"balance_filter_s", &MonitorConfig::balance_filter_s, 0.002, 10},
      {"balance_time_constant_s", &MonitorConfig::balance_time_constant_s, 0.01, 1e3},
      {"min_balance_moving_s", &MonitorConfig::min_balance_moving_s, 0, 1e3},
      {"constant_power_uncertainty_W", &MonitorConfig::constant_power_uncertainty_W, 1e-3, 1e4},
      {"window_friction_prior", &MonitorConfig::window_friction_prior, 0, 1e6},
      {"window_drift_prior", &MonitorConfig::window_drift_prior, 0, 1e6},
      {"window_noise_fraction", &MonitorConfig::window_noise_fraction, 0, 10},
      {"window_noise_floor_J", &MonitorConfig::window_noise_floor_J, 1e-6, 1e6},
      {"electrical_prior_W2", &MonitorConfig::electrical_prior_W2, 1e-6, 1e9},
      {"electrical_tick_sigma_W", &MonitorConfig::electrical_tick_sigma_W, 1e-6, 1e4},
      {"copper_resistance_per_K", &MonitorConfig::copper_resistance_per_K, 1e-4, 0.1},
      {"magnet_kt_loss_per_K", &MonitorConfig::magnet_kt_loss_per_K, 0, 0.01},
      {"max_magnet_kt_loss_per_K", &MonitorConfig::max_magnet_kt_loss_per_K, 0, 0.01},
      {"max_winding_rise_K", &MonitorConfig::max_winding_rise_K, 0, 1e3},
      {"winding_thermometer_time_constant_s", &MonitorConfig::winding_thermometer_time_constant_s, 0.01, 1e5},
      {"winding_reading_time_constant_s", &MonitorConfig::winding_reading_time_constant_s, 0.01, 1e5},
      {"winding_settle_s", &MonitorConfig::winding_settle_s, 0, 1e5},
      {"winding_unsettled_se", &MonitorConfig::winding_unsettled_se, 0, 100},
      {"winding_reading_converged_s", &MonitorConfig::winding_reading_converged_s, 0, 1e5},
      {"winding_reading_error_K", &MonitorConfig::winding_reading_error_K, 0, 100},
      {"warm_magnet_hypothesis_s", &MonitorConfig::warm_magnet_hypothesis_s, 0, 1e5},
      {"warm_magnet_reading_factor", &MonitorConfig::warm_magnet_reading_factor, 0, 100},
      {"max_lubricant_slope_per_K", &MonitorConfig::max_lubricant_slope_per_K, 0, 1},
      {"min_lubricant_slope_per_K", &MonitorConfig::min_lubricant_slope_per_K, 0, 1},
      {"cold_held_by_limit_K", &MonitorConfig::cold_held_by_limit_K, 0, 200},
      {"max_cold_K", &MonitorConfig::max_cold_K, 0, 200},
      {"max_warm_counted_K", &MonitorConfig::max_warm_counted_K, 0, 200},
      {"max_warm_K", &MonitorConfig::max_warm_K, 0, 200},
      {"gear_warmth_se", &MonitorConfig::gear_warmth_se, 0, 100},
      {"friction_block_s", &MonitorConfig::friction_block_s, 1e-3, 1e3},
      {"friction_reference_time_constant_s", &MonitorConfig::friction_reference_time_constant_s, 0.01, 1e6},
      {"min_friction_reference", &MonitorConfig::min_friction_reference, 0, 1},
      {"brake_drag_friction_factor", &MonitorConfig::brake_drag_friction_factor, 1, 1e6},
      {"drift_balance_time_constant_s", &MonitorConfig::drift_balance_time_constant_s, 0.01, 1e5},
      {"min_offset_moving_each_way_s", &MonitorConfig::min_offset_moving_each_way_s, 0, 1e5},
      {"zero_balance_time_constant_s", &MonitorConfig::zero_balance_time_constant_s, 0.01, 1e5},
      {"sensor_zero_time_constant_s", &MonitorConfig::sensor_zero_time_constant_s, 0.01, 1e6},
      {"dead_drive_draw_fraction", &MonitorConfig::dead_drive_draw_fraction, 0, 1},
      {"rail_jump_fraction", &MonitorConfig::rail_jump_fraction, 0, 1},
      {"brake_torque_fraction", &MonitorConfig::brake_torque_fraction, 0, 1},
      {"min_balance_sigma_Nm", &MonitorConfig::min_balance_sigma_Nm, 1e-6, 1e3},
      {"gear_time_constant_s", &MonitorConfig::gear_time_constant_s, 1, 1e6},
      {"arm_temperature_spread_K", &MonitorConfig::arm_temperature_spread_K, 0.1, 200},
      {"unread_temperature_sd_K", &MonitorConfig::unread_temperature_sd_K, 0.1, 200},
      {"start_reading_s", &MonitorConfig::start_reading_s, 0, 1e5},
      {"gear_winding_gap_sd", &MonitorConfig::gear_winding_gap_sd, 0, 10},
      {"lubricant_slope_prior_sd_per_K", &MonitorConfig::lubricant_slope_prior_sd_per_K, 1e-6, 1},
      {"lubricant_forget_s", &MonitorConfig::lubricant_forget_s, 1, 1e7},
      {"friction_model_error", &MonitorConfig::friction_model_error, 1e-4, 10},
      {"friction_block_scatter", &MonitorConfig::friction_block_scatter, 1e-4, 10},
  };
  return f;
}
// The sequential decision's fields: read and written only with "decision": "sequential".
const std::vector<NumberField>& SequentialFields() {
  static const std::vector<NumberField> f = {
      // (0, one per tick] is checked on its own: a rate must be > 0, and its upper bound is
      // the control rate's (MakePowerMonitorModel).
      {"target_false_alarms_per_hour", &MonitorConfig::target_false_alarms_per_hour, -kInf, kInf},
      {"sequential_allowance_sd", &MonitorConfig::sequential_allowance_sd, 0.01, 10},
      {"sequential_look_memories", &MonitorConfig::sequential_look_memories, 0.1, 100},
      {"kt_se_scale", &MonitorConfig::kt_se_scale, 0.01, 100},
      {"resistance_se_scale", &MonitorConfig::resistance_se_scale, 0.01, 100},
      {"friction_factor_se_scale", &MonitorConfig::friction_factor_se_scale, 0.01, 100},
      {"sensor_drift_se_scale", &MonitorConfig::sensor_drift_se_scale, 0.01, 100},
      {"kt_bias_wander_s", &MonitorConfig::kt_bias_wander_s, 0.01, 1e9},
      {"resistance_bias_wander_s", &MonitorConfig::resistance_bias_wander_s, 0.01, 1e9},
      {"friction_factor_bias_wander_s", &MonitorConfig::friction_factor_bias_wander_s, 0.01, 1e9},
      {"sensor_drift_bias_wander_s", &MonitorConfig::sensor_drift_bias_wander_s, 0.01, 1e9},
      {"sequential_settle_s", &MonitorConfig::sequential_settle_s, 0, 1e6},
      {"kt_model_error", &MonitorConfig::kt_model_error, 0, 10},
      {"resistance_model_error", &MonitorConfig::resistance_model_error, 0, 10},
      {"friction_factor_model_error", &MonitorConfig::friction_factor_model_error, 0, 10},
      {"sensor_drift_model_error_Nm", &MonitorConfig::sensor_drift_model_error_Nm, 0, 1e3},
  };
  return f;
}
const std::vector<IntField>& IntFields() {
  static const std::vector<IntField> f = {
      {"mechanical_windows", &MonitorConfig::mechanical_windows, 1, 100},
      {"friction_envelope_blocks", &MonitorConfig::friction_envelope_blocks, 1, 10000},
      {"shown_friction_blocks", &MonitorConfig::shown_friction_blocks, 1, 10000},
      {"unconverged_friction_blocks", &MonitorConfig::unconverged_friction_blocks, 0, 10000},
      {"min_shown_friction_blocks", &MonitorConfig::min_shown_friction_blocks, 1, 10000},
  };
  return f;
}
const std::vector<LimitField>& LimitFields() {
  static const std::vector<LimitField> f = {
      {"kt_factor", &MonitorConfig::kt_factor, Direction::kBelow},
      {"friction_factor", &MonitorConfig::friction_factor, Direction::kAbove},
      {"resistance_factor", &MonitorConfig::resistance_factor, Direction::kAbove},
      {"sensor_drift_Nm", &MonitorConfig::sensor_drift_Nm, Direction::kMagnitude},
  };
  return f;
}

}  // namespace

namespace {

// One of the known friction references, else an error with the nearest as a hint.
void RequireChoice(const std::string& value, const std::vector<std::string>& known, const std::string& pointer) {
  if (std::find(known.begin(), known.end(), value) != known.end()) return;
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  const std::string near = NearestWord(value, known);
  throw InputError("", pointer, "unknown friction reference " + nlohmann::json(value).dump() + " (known: " + list + ")",
                   near.empty() ? "" : "did you mean \"" + near + "\"?");
}

void RequireDecision(const std::string& value, const std::string& pointer) {
  const std::vector<std::string> known = {kThresholdDecision, kSequentialDecision};
  if (std::find(known.begin(), known.end(), value) != known.end()) return;
  const std::string near = NearestWord(value, known);
  throw InputError("", pointer, "unknown decision " + nlohmann::json(value).dump() + " (known: threshold, sequential)",
                   near.empty() ? "" : "did you mean \"" + near + "\"?");
}

// A false-alarm rate is a positive number of alarms per hour (no rate validates zero alarms).
void RequirePositiveRate(double per_hour, const std::string& pointer) {
  if (!(per_hour > 0 && std::isfinite(per_hour))) {
    throw InputError("", pointer, FormatNumber(per_hour) + " is not a false-alarm rate: alarms per hour must be > 0");
  }
}

// The range checks of Validate(), each on its own, into `errors`. A limit whose object could
// not be read (in `unread_limits`) is skipped: its defaults would be checked, not the file.
void CheckRanges(const MonitorConfig& c, const std::string& pointer, const std::set<std::string>& unread_limits,
                 ErrorList* errors) {
  for (const auto& f : NumberFields()) {
    errors->Try([&] { RequireInRange(c.*f.member, f.min, f.max, PointerJoin(pointer, f.key)); });
  }
  errors->Try([&] {
    RequireChoice(c.friction_reference, {kFrictionRules, kArmFrictionModel}, PointerJoin(pointer, "friction_reference"));
  });
  for (const auto& f : IntFields()) {
    errors->Try([&] { RequireInRange(c.*f.member, f.min, f.max, PointerJoin(pointer, f.key)); });
  }
  errors->Try([&] { RequireDecision(c.decision, PointerJoin(pointer, "decision")); });
  if (c.decision == kSequentialDecision) {
    for (const auto& f : SequentialFields()) {
      errors->Try([&] { RequireInRange(c.*f.member, f.min, f.max, PointerJoin(pointer, f.key)); });
    }
    errors->Try([&] { RequirePositiveRate(c.target_false_alarms_per_hour, PointerJoin(pointer, "target_false_alarms_per_hour")); });
  }
  // Fields bounded by others, checked once those are valid: a joint's shown friction is the
  // median of its last blocks, which the envelope's ring must hold, and its first friction is
  // read when it first has min_shown_friction_blocks of them; the warm side's slope is no
  // steeper than the steepest.
  auto in_range = [](int v) { return v >= 1 && v <= 10000; };
  if (in_range(c.friction_envelope_blocks) && in_range(c.shown_friction_blocks)) {
    errors->Try([&] {
      RequireInRange(c.shown_friction_blocks, 1, c.friction_envelope_blocks, PointerJoin(pointer, "shown_friction_blocks"));
    });
  }
  if (in_range(c.shown_friction_blocks) && in_range(c.min_shown_friction_blocks)) {
    errors->Try([&] {
      RequireInRange(c.min_shown_friction_blocks, 1, c.shown_friction_blocks, PointerJoin(pointer, "min_shown_friction_blocks"));
    });
  }
  if (c.max_lubricant_slope_per_K >= 0 && c.max_lubricant_slope_per_K <= 1 && c.min_lubricant_slope_per_K >= 0 &&
      c.min_lubricant_slope_per_K <= 1) {
    errors->Try([&] {
      RequireInRange(c.min_lubricant_slope_per_K, 0, c.max_lubricant_slope_per_K, PointerJoin(pointer, "min_lubricant_slope_per_K"));
    });
  }
  for (const auto& f : LimitFields()) {
    if (unread_limits.count(f.key)) continue;
    const StateLimits& l = c.*f.member;
    const std::string p = PointerJoin(pointer, f.key);
    // defective is bounded by worn: checked only when worn is valid.
    switch (f.direction) {
      case Direction::kBelow:
        if (errors->Try([&] { RequireInRange(l.worn, 0, 1, PointerJoin(p, "worn")); })) {
          errors->Try([&] { RequireInRange(l.defective, 0, l.worn, PointerJoin(p, "defective")); });
        }
        break;
      case Direction::kAbove:
        if (errors->Try([&] { RequireInRange(l.worn, 1, kInf, PointerJoin(p, "worn")); })) {
          errors->Try([&] { RequireInRange(l.defective, l.worn, kInf, PointerJoin(p, "defective")); });
        }
        break;
      case Direction::kMagnitude:
        if (errors->Try([&] { RequireInRange(l.worn, 0, kInf, PointerJoin(p, "worn")); })) {
          errors->Try([&] { RequireInRange(l.defective, l.worn, kInf, PointerJoin(p, "defective")); });
        }
        break;
    }
  }
}

}  // namespace

MonitorConfig MonitorConfigFromJson(const nlohmann::json& value, const std::string& pointer,
                                    const std::string& source) {
  MonitorConfig c;
  ErrorList errors;  // every key on its own: all bad ones are reported together
  std::set<std::string> unread_limits;
  try {
    ObjectReader reader(value, pointer);
    std::vector<std::string> keys;
    for (const auto& f : NumberFields()) keys.push_back(f.key);
    for (const auto& f : IntFields()) keys.push_back(f.key);
    for (const auto& f : LimitFields()) keys.push_back(f.key);
    keys.push_back("friction_reference");
    keys.push_back("decision");
    for (const auto& f : SequentialFields()) keys.push_back(f.key);
    errors.Try([&] { reader.AllowOnly(keys); });
    errors.Try([&] {
      reader.OptionalString("decision", &c.decision);
      RequireDecision(c.decision, reader.PointerTo("decision"));
    });
    // The sequential decision's fields would be silently unused by another: refused.
    for (const auto& f : SequentialFields()) {
      errors.Try([&] {
        if (!reader.Find(f.key)) return;
        if (c.decision != kSequentialDecision) {
          throw InputError("", reader.PointerTo(f.key),
                           std::string(f.key) + " sets the sequential decision: it needs \"decision\": \"sequential\"");
        }
        reader.OptionalNumber(f.key, &(c.*f.member));
      });
    }
    errors.Try([&] {
      reader.OptionalString("friction_reference", &c.friction_reference);
      RequireChoice(c.friction_reference, {kFrictionRules, kArmFrictionModel}, reader.PointerTo("friction_reference"));
    });
    for (const auto& f : NumberFields()) errors.Try([&] { reader.OptionalNumber(f.key, &(c.*f.member)); });
    for (const auto& f : IntFields()) errors.Try([&] { reader.OptionalInt(f.key, &(c.*f.member)); });
    for (const auto& f : LimitFields()) {
      const bool read = errors.Try([&] {
        const nlohmann::json* v = reader.Find(f.key);
        if (!v) return;
        ObjectReader limits(*v, reader.PointerTo(f.key));
        ErrorList limit_errors;
        limit_errors.Try([&] { limits.AllowOnly({"worn", "defective"}); });
        limit_errors.Try([&] { limits.OptionalNumber("worn", &(c.*f.member).worn); });
        limit_errors.Try([&] { limits.OptionalNumber("defective", &(c.*f.member).defective); });
        limit_errors.ThrowIfAny();
      });
      if (!read) unread_limits.insert(f.key);
    }
  } catch (const InputError& e) {
    throw e.WithSource(source);  // not an object
  }
  CheckRanges(c, pointer, unread_limits, &errors);
  if (!errors.empty()) throw InputError(errors.errors()).WithSource(source);
  return c;
}

void Validate(const MonitorConfig& c, const std::string& pointer, const std::string& source) {
  ErrorList errors;
  CheckRanges(c, pointer, {}, &errors);
  if (!errors.empty()) throw InputError(errors.errors()).WithSource(source);
}

void ValidateDecisionRate(const MonitorConfig& c, double control_rate_Hz, const std::string& pointer,
                          const std::string& source) {
  if (c.decision != kSequentialDecision) return;
  const double per_tick_per_hour = 3600.0 * control_rate_Hz;
  if (!(c.target_false_alarms_per_hour <= per_tick_per_hour)) {
    throw InputError(source, PointerJoin(pointer, "target_false_alarms_per_hour"),
                     FormatNumber(c.target_false_alarms_per_hour) + " alarms per hour is more than one per controller tick (" +
                         FormatNumber(per_tick_per_hour) + " per hour at " + FormatNumber(control_rate_Hz) + " Hz)");
  }
}

nlohmann::json MonitorConfigToJson(const MonitorConfig& c) {
  nlohmann::json j = nlohmann::json::object();
  j["friction_reference"] = c.friction_reference;
  for (const auto& f : NumberFields()) j[f.key] = c.*f.member;
  for (const auto& f : IntFields()) j[f.key] = c.*f.member;
  for (const auto& f : LimitFields()) j[f.key] = {{"worn", (c.*f.member).worn}, {"defective", (c.*f.member).defective}};
  // The default decision writes nothing of its own: a threshold monitor's settings read as before.
  if (c.decision == kSequentialDecision) {
    j["decision"] = c.decision;
    for (const auto& f : SequentialFields()) j[f.key] = c.*f.member;
  }
  return j;
}

}  // namespace armfault

namespace armfault {

namespace {
// Scales at which an error shows in a statistic: the current at which switching loss is
// judged, a typical joint torque, the self-heating a winding may add over ambient in a task
// (docs/monitor.md, "Without commissioning").
constexpr double kTypicalCurrent_A = 2.0;
constexpr double kTypicalTorque_Nm = 6.0;
constexpr double kSelfHeatingMargin_K = 10.0;
// How strongly a torque-scale error reaches the friction factor: torque over friction of a
// loaded joint; and the mesh loss over friction (μ |τ| / friction).
constexpr double kTorqueOverFriction = 2.5;
constexpr double kMeshOverFriction = 0.6;
}  // namespace

MonitorConfig WidenedForTolerances(const MonitorConfig& config, const StatedTolerances& tol, const RobotConfig& robot) {
  MonitorConfig c = config;
  const double dT = std::max(std::fabs(tol.ambient_max_C - 20.0), std::fabs(tol.ambient_min_C - 20.0)) + kSelfHeatingMargin_K;
  double dn = 0, drho = 0, dkappa = 0, ddrift = 0;
  for (const ModuleParams& m : robot.modules) {
    const double u = m.inverter.bus_voltage_V;
    const double sw = 2.0 * u * m.inverter.switching_time_s * m.inverter.pwm_frequency_Hz;
    const double constant_W = tol.quiescent_power * m.inverter.quiescent_power_W + tol.supply_current_offset_A * u +
                              tol.switching_loss * sw * kTypicalCurrent_A;
    const double r = m.motor.phase_resistance_ohm;
    const double friction_Nm = m.drive.ratio * (m.friction.coulomb_Nm + m.friction.static_Nm);
    // The electrical fit takes a constant power as a parameter of its own, pulled to the
    // calibration within this uncertainty: a constant error no longer passes for n or rho.
    c.constant_power_uncertainty_W = std::max(c.constant_power_uncertainty_W, constant_W);
    dn = std::max(dn, tol.kt + tol.supply_current_gain + c.magnet_kt_loss_per_K * dT);
    drho = std::max(drho, tol.winding_resistance + c.copper_resistance_per_K * dT + tol.supply_current_gain +
                              tol.switch_resistance * m.inverter.switch_resistance_ohm / r);
    dkappa = std::max(dkappa, tol.friction + kTorqueOverFriction * (tol.kt + tol.torque_sensor_gain + c.magnet_kt_loss_per_K * dT) +
                                  kMeshOverFriction * tol.mesh_loss + 0.5 * tol.rotor_inertia +
                                  0.3 * tol.stribeck_velocity + tol.torque_sensor_offset_Nm / friction_Nm);
    ddrift = std::max(ddrift, tol.torque_sensor_offset_Nm + tol.torque_sensor_gain * kTypicalTorque_Nm);
  }
  c.kt_factor.worn = std::max(0.02, c.kt_factor.worn - dn);
  c.kt_factor.defective = std::max(0.01, std::min(c.kt_factor.worn, c.kt_factor.defective - dn));
  c.resistance_factor.worn += drho;
  c.resistance_factor.defective += drho;
  c.friction_factor.worn += dkappa;
  c.friction_factor.defective += dkappa;
  c.sensor_drift_Nm.worn += ddrift;
  c.sensor_drift_Nm.defective += ddrift;
  return c;
}

}  // namespace armfault
