// Randomized confounders ("variation/confounders", docs/campaign-format.md): each robot unit
// draws its gearbox group (core/plant/parts/gear_thermal.h) and torque ripple
// (core/plant/parts/torque_ripple.h) over ranges, so that a bench holds every combination a
// documented range allows rather than the values one drive type ships with. The "documented"
// preset is the class ranges of docs/assumptions.md, "Documented ranges of the confounders".
//
// What is drawn, and how often:
//  - per unit (one grease in every gear of the arm): the lubricant law's form (Vogel with C in
//    vogel_C_C, or Arrhenius, C = -273.15 degC, with probability arrhenius_fraction), its
//    steepness as the viscous friction's ratio R = f(-10 degC) / f(40 degC), so that
//      B = ln R / (1/(-10 - C) - 1/(40 - C)),
//    the reference temperature and the share of the dry friction that follows the law
//    (coulomb_exponent);
//  - per joint: load friction driving and back-driven, the torque sensor's offset drift (in %
//    of its full scale per K) and gain drift, each with its own sign, the gear's thermal
//    resistance, time constant, winding coupling and warm-start duty (as factors on the drive's
//    own values), and the ripple's kinematic-error lines, cogging and their phases.
// Ranges are [low, high], drawn uniformly.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"
#include "core/base/rng.h"

namespace armfault {

struct ConfounderRange {
  double low = 0;
  double high = 0;
};

struct ConfounderRanges {
  // lubricant, per unit
  double arrhenius_fraction = 0.5;                   // probability of an Arrhenius law (else Vogel)
  ConfounderRange cold_to_warm_ratio{2.0, 3.5};      // R = f(-10 degC) / f(40 degC) of the viscous part
  ConfounderRange vogel_C_C{-200, -100};             // C of a Vogel law [degC]
  ConfounderRange reference_C{15, 30};               // where the drive's friction values hold [degC]
  ConfounderRange coulomb_exponent{0.3, 0.9};        // dry friction scales with f^n
  // gear and sensor, per joint
  ConfounderRange load_friction_driving{0.02, 0.15};
  ConfounderRange load_friction_backdriven{0.02, 0.15};
  ConfounderRange sensor_offset_fs_per_K{0.0001, 0.0005};  // |offset drift| / full scale per K; sign per joint
  ConfounderRange sensor_gain_per_K{0.00005, 0.0002};       // |gain drift| per K; sign per joint
  ConfounderRange thermal_resistance_factor{0.75, 1.35};    // x the drive's R_g
  ConfounderRange thermal_time_constant_factor{0.45, 1.25}; // x the drive's R_g C_g
  ConfounderRange winding_coupling_factor{0.5, 1.7};        // x the drive's G_wg
  ConfounderRange warm_duty_factor{0.7, 1.4};               // x the drive's warm-start losses
  // ripple, per joint
  ConfounderRange kinematic_error_2x_arcmin{0.1, 1.0};
  ConfounderRange kinematic_error_1x_arcmin{0.0, 0.3};
  ConfounderRange cogging_Nm{0.0, 0.03};
};

// The "documented" preset: the class ranges of docs/assumptions.md.
ConfounderRanges DocumentedConfounderRanges();

// Parses "variation/confounders": "documented", or an object of [low, high] ranges
// (optionally with "preset": "documented" and "arrhenius_fraction"); unknown keys, ranges
// outside the plant's accepted values, low > high: InputError at `pointer`'s key.
ConfounderRanges ParseConfounderRanges(const nlohmann::json& value, const std::string& pointer);

// Every module of `robot` must carry a gearbox group (the draw scales its thermal values):
// InputError at `pointer` naming the first joint without one.
void RequireGearboxGroups(const RobotConfig& robot, const std::string& pointer);

// One joint's draw: its gearbox group and ripple as they will be simulated.
struct ConfounderDraw {
  GearboxParams gearbox;
  RippleParams ripple;
};

// Draws a unit's confounders for every module of `robot` from `rng` (the unit's own stream,
// campaigns/spec/cases.cc), in the order of the header comment.
std::vector<ConfounderDraw> DrawConfounders(const ConfounderRanges& ranges, const RobotConfig& robot, Rng* rng);

// What a run's record shows of its draw (`variation/confounders`): per key one value per joint.
nlohmann::json ConfounderDrawsToJson(const std::vector<ConfounderDraw>& draws);

}  // namespace armfault
