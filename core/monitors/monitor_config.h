// The built-in power-efficiency monitor's settings: every threshold and every tuned constant of
// its estimators, as one plain struct with defaults (`"monitor"` in a run or campaign file; all
// keys optional, docs/monitor.md "Settings"). Each field states its unit, its meaning and its
// source: material data, a catalogue, or the bench it was fitted on (docs/assumptions.md).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "core/plant/robot/robot_config.h"

namespace armfault {

// Worn / defective limits of one estimated parameter. For a factor whose healthy value is
// 1, "below" limits apply to falling parameters (K_T), "above" to rising ones (friction).
struct StateLimits {
  double worn = 0;
  double defective = 0;
};

// The friction references ("friction_reference"): the rules of friction_reference.h, or the
// arm's friction model of friction_model.h.
inline constexpr const char* kFrictionRules = "rules";
inline constexpr const char* kArmFrictionModel = "arm_model";
// How the detectors decide ("decision"): each statistic against its worn limit and a
// significance, held over the debounce time; or a CUSUM per detector whose threshold follows
// from a target false-alarm rate (core/monitors/sequential_test.h).
inline constexpr const char* kThresholdDecision = "threshold";
inline constexpr const char* kSequentialDecision = "sequential";

struct MonitorConfig {
  // --- which reference the friction statistic is judged against ---
  std::string friction_reference = kFrictionRules;
  // --- the arm's friction model (friction_model.h; docs/monitor.md "The arm's friction model") ---
  // the gear's lag behind its winding: a strain-wave gear housing's thermal time constant, the
  // order of catalogue data (20-40 min) [s]
  double gear_time_constant_s = 1200.0;
  // how far one joint's temperature may lie from its arm's at a start (1 sigma) [K]
  double arm_temperature_spread_K = 10.0;
  // a unit's temperature before any winding is read, about its commissioning: an ambient of
  // 0-45 degC against one near 20 degC (1 sigma) [K]
  double unread_temperature_sd_K = 25.0;
  // the start temperature follows the readings (its own, the arm's) this long, then holds [s]
  double start_reading_s = 30.0;
  // how far a gear's temperature may differ from its winding's, as a share of its rise (1 sigma)
  double gear_winding_gap_sd = 0.15;
  // the lubricant's slopes: prior sd about half of max_lubricant_slope_per_K [1/K]
  double lubricant_slope_prior_sd_per_K = 0.008;
  // the arm's information on its lubricant forgets with this time constant [s]
  double lubricant_forget_s = 600.0;
  // the model error: 1 sigma of a healthy joint's ln(friction) about its arm's law, the same for
  // all its blocks (fitted on healthy runs, docs/assumptions.md)
  double friction_model_error = 0.06;
  // 1 sigma of one block's ln(friction) about its joint's level beyond the fit's own error
  double friction_block_scatter = 0.03;
  // --- windows (thesis eq 4-11 ... 4-20) ---
  double rest_velocity_rad_s = 0.02;   // |qd| below this: at rest (eq 4-11), no window
  double min_window_s = 0.3;           // shorter windows are not judged
  double min_window_energy_J = 0.5;    // |E_out| and |E_mesh_in| below this: not judged
  int mechanical_windows = 3;          // windows in the mechanical fit
  // the window fit's priors, in the units of its 1/sigma^2-weighted normal equations: the friction
  // factor has the weight of one window with 1 J of friction known to 1 J; the drift a stronger
  // pull to 0, so that windows all one way (friction and drift inseparable) put it on friction
  double window_friction_prior = 1.0;
  double window_drift_prior = 10.0;
  // 1 sigma of a window's energy balance: this fraction of the energy through the mesh, plus a
  // floor (encoder quantisation, torque noise, residual inertia at the ends) [J]; MRR bench
  double window_noise_fraction = 0.03;
  double window_noise_floor_J = 0.05;
  // --- electrical fit ---
  double electrical_time_constant_s = 1.5;  // forgetting of the per-tick fit
  double min_rotor_energy_J = 2.0;     // weighted sum of |P_rotor| dt needed to judge n
  double min_copper_energy_J = 0.2;    // weighted sum of P_copper dt needed to judge rho
  // weight of the pulls n -> 1, rho -> 1 that keep the fit defined at rest [W^2]: a little
  // evidence against residuals of about 1 W (MRR bench)
  double electrical_prior_W2 = 50.0;
  // 1 sigma of one tick's electrical residual: supply-sensor noise, period averaging [W]
  double electrical_tick_sigma_W = 0.5;
  // 1 sigma of the supply's constant draw about the calibration [W] (quiescent, sensor offset)
  double constant_power_uncertainty_W = 0.1;
  // --- material data (docs/assumptions.md) ---
  double copper_resistance_per_K = 0.00393;   // copper's resistance rise [1/K]
  double magnet_kt_loss_per_K = 0.001;        // a typical NdFeB magnet's K_T loss [1/K] (with a winding sensor)
  double max_magnet_kt_loss_per_K = 0.0012;   // the most a magnet loses: NdFeB 0.08-0.12 %/K [1/K]
  double max_winding_rise_K = 100.0;          // a resistance rise beyond this many K is no temperature
  // --- the winding as a thermometer (its resistance factor rho) ---
  // the slow reading the K_T allowance takes: the fit's own for this long after rho is first
  // judged, then following it with this time constant (a winding warms over minutes) [s]
  double winding_thermometer_time_constant_s = 60.0;
  // the reading the cold allowance takes: the fit's rho averaged with this time constant (a
  // plain mean until then) [s]; the fit swings with a work cycle's current (+-0.03 on a wrist)
  double winding_reading_time_constant_s = 10.0;
  double winding_settle_s = 2.0;       // judged copper loss after which the reading counts as settled [s]
  double winding_unsettled_se = 2.0;   // until then: the reading less this many standard errors
  // judged copper loss after which the warm floor's coldest reading forgets the fit's first
  // moments, which start at its prior (1) [s]
  double winding_reading_converged_s = 10.0;
  double winding_reading_error_K = 5.0;  // how far the arm's reading of its windings errs [K]
  // a K_T loss judged for less than this is no more significant than the data's rejection of a
  // magnet as warm as its winding reads [s]; the line's rho at most this many times as far above 1
  double warm_magnet_hypothesis_s = 60.0;
  double warm_magnet_reading_factor = 3.0;
  // --- the friction the run finds (the lubricant's temperature; docs/monitor.md) ---
  // the steepest the no-load running torque of a strain-wave gear's lubricant falls with
  // temperature: a factor 3 from -10 to +40 degC, ln 3 / 50 K (catalogues) [1/K]
  double max_lubricant_slope_per_K = 0.021972245773362196;
  // the gentlest it falls above 20 degC: half the catalogues' typical 0.02/K [1/K]
  double min_lubricant_slope_per_K = 0.01;
  double cold_held_by_limit_K = 10.0;  // cold the friction limit already holds (exp(0.22) = 1.25) [K]
  double max_cold_K = 40.0;            // no colder than this is counted [K]
  double max_warm_counted_K = 14.0;    // warmth counted by the warm floor beyond the reading error [K]
  double max_warm_K = 40.0;            // a winding warmer than this over its commissioning gives no floor [K]
  double gear_warmth_se = 2.0;         // standard errors a gear must read below its curve to show warmth
  // the friction envelope: block medians of the fast fit over this much usable motion [s], the
  // last `friction_envelope_blocks` of them followed down with this time constant [s], never
  // below `min_friction_reference` (the thinnest a catalogue lubricant goes, 60 against 20 degC)
  double friction_block_s = 1.0;
  int friction_envelope_blocks = 60;
  double friction_reference_time_constant_s = 60.0;
  double min_friction_reference = 0.5;
  int shown_friction_blocks = 20;        // the friction a joint shows: the median of its last blocks
  int unconverged_friction_blocks = 2;   // a run's first blocks are not counted (the fit starts at 1)
  int min_shown_friction_blocks = 5;     // blocks before a joint's shown friction counts
  double brake_drag_friction_factor = 4.0;  // whole friction above this many times its reference: a dragging brake
  // --- the torque sensor's zero ---
  double drift_balance_time_constant_s = 4.0;   // memory of the fit that carries the offset [s]
  double min_offset_moving_each_way_s = 1.0;    // motion each way before the offset is judged [s]
  double zero_balance_time_constant_s = 30.0;   // memory of the zero fit: a work cycle's strokes both ways [s]
  double sensor_zero_time_constant_s = 120.0;   // the zero found follows the zero fit this slowly [s]
  // --- decision ---
  std::string decision = kThresholdDecision;
  // "sequential" only (sequential_test.h; docs/monitor.md "Sequential decision"):
  // the false alarms per healthy hour of the whole arm the thresholds are set for [1/h]
  double target_false_alarms_per_hour = 1.0;
  // the CUSUM's allowance k: optimal for a shift of 2k standard deviations [sd]
  double sequential_allowance_sd = 0.5;
  // looks this many of a detector's fit memories apart (correlation exp(-2) = 0.14)
  double sequential_look_memories = 2.0;
  // each detector's scale s of its deviation's standard error in the residual model: the
  // healthy innovations' standard deviation in the fit's own standard errors (the fit's
  // covariance is not the plant's noise; fitted on healthy runs, docs/assumptions.md)
  double kt_se_scale = 0.125;
  double resistance_se_scale = 0.072;
  double friction_factor_se_scale = 0.355;
  double sensor_drift_se_scale = 0.103;
  // each detector's time T in which a healthy bias may wander over its whole model error [s]
  // (fitted on healthy runs, docs/assumptions.md)
  double kt_bias_wander_s = 300.0;
  double resistance_bias_wander_s = 150.0;
  double friction_factor_bias_wander_s = 1200.0;
  double sensor_drift_bias_wander_s = 6000.0;
  // the seconds of a detector's statistic in which its bias may sit anywhere inside its model
  // error: the reference is still settling (fitted on healthy runs, docs/assumptions.md)
  double sequential_settle_s = 120.0;
  // each detector's model error m: the bound on a healthy deviation's bias, which the bias
  // filter follows up to and the innovation counts beyond, in the statistic's units (fitted on
  // healthy runs, docs/assumptions.md)
  double kt_model_error = 0.03;
  double resistance_model_error = 0.10;
  double friction_factor_model_error = 0.15;
  double sensor_drift_model_error_Nm = 0.3;
  double significance = 3.0;           // (|deviation| - worn margin) / std error must exceed this
  double debounce_s = 0.3;             // a candidate verdict must hold this long to alarm
  StateLimits kt_factor{0.95, 0.75};          // below
  StateLimits friction_factor{1.30, 1.80};    // above
  StateLimits resistance_factor{1.40, 2.00};  // above
  StateLimits sensor_drift_Nm{1.0, 3.0};      // |d| above
  // --- tick-level detectors ---
  double overpower_W = 40.0;           // supply power above the electrical model by this: short
  double overpower_time_s = 0.002;
  double dead_drive_current_A = 2.0;   // |i_cmd| at least this with no copper loss drawn ...
  double dead_drive_time_s = 0.02;     // ... this long: the bridge is open (tripped)
  double dead_drive_draw_fraction = 0.25;  // "no copper loss": less than this share of it drawn
  double stuck_time_s = 0.2;           // reading unchanged this long ...
  double stuck_torque_span_Nm = 3.0;   // ... while the commanded torque moved this much
  double rail_time_s = 0.05;           // reading at an ADC rail this long
  // the largest one-tick step (share of the sensor's span) in which a reading may reach its
  // rail and still count as saturation (5 %: 1400 N m/s on the MRR sensor, beyond any load's slew)
  double rail_jump_fraction = 0.05;
  double blocked_current_A = 3.0;      // |i_cmd| at least this ...
  double blocked_error_rad = 0.02;     // ... tracking error at least this ...
  double blocked_time_s = 0.2;         // ... with the joint at rest, this long
  double brake_torque_fraction = 0.5;  // blocked, the sensor reads less than this share of the motor's torque: the brake
  // --- tick-rate torque balance (friction and sensor offset, core/monitors/torque_balance.h) ---
  double balance_filter_s = 0.03;      // T_f of the low-pass every balance term passes
  double balance_time_constant_s = 0.5;  // forgetting of the fit the friction and drift detectors judge
  double min_balance_moving_s = 0.3;   // moving time in that fit needed to judge
  double min_balance_sigma_Nm = 0.05;  // floor of a tick's balance scatter over the sensor's noise [N m]
};

// The limits a monitor without commissioning must use on a unit known only within `tol`
// (StatedTolerances, core/plant/robot/robot_config.h):
// each swept detector's worn and defective limits move out by the bias the stated tolerances
// can put on its statistic (docs/monitor.md, "Without commissioning"). `robot` gives the
// nominal scales (quiescent power, bus voltage, resistance, friction).
MonitorConfig WidenedForTolerances(const MonitorConfig& config, const StatedTolerances& tol, const RobotConfig& robot);

// Parses a monitor JSON object (every key optional, unknown keys rejected); Validate()s it.
MonitorConfig MonitorConfigFromJson(const nlohmann::json& value, const std::string& pointer,
                                    const std::string& source);
nlohmann::json MonitorConfigToJson(const MonitorConfig& config);
// Every field in its range, and the fields that bound each other consistent (InputError naming
// `source` and the field's JSON pointer under `pointer`).
void Validate(const MonitorConfig& config, const std::string& pointer, const std::string& source);
// A sequential decision's target rate against the controller's rate: at most one alarm per
// tick (InputError naming `source` and "<pointer>/target_false_alarms_per_hour").
void ValidateDecisionRate(const MonitorConfig& config, double control_rate_Hz, const std::string& pointer,
                          const std::string& source);

}  // namespace armfault
