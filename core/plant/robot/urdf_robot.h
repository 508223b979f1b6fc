// A robot from a URDF file plus its drives: {"urdf": "arm.urdf", "drives": {...}, ...}.
//
// The URDF is parsed with liburdfdom (its <transmission> elements, which urdfdom does not
// read, with the XML library urdfdom itself uses, TinyXML). What is read, per link: the
// inertial (mass, centre of mass with its rpy, the full inertia tensor); per joint: origin
// (xyz, rpy), axis, limits (lower, upper, velocity, effort) and dynamics (damping, friction).
// Visual and collision elements and mesh files are never opened.
//
// The chain: from the root link, every moving joint (revolute or continuous) begins a body
// made of its child link and every link hanging from it by fixed joints (their inertials
// merged, parallel-axis theorem). The links before the first moving joint are the base, fixed
// to the world at `base_position_m` (their mass is not needed and may be absent or zero).
// Errors (exit status 2, naming the file and the element): prismatic, floating and planar
// joints; a branching tree (two moving joints below one body); a moving body whose merged
// mass is not positive or whose inertia is not positive definite; more than 7 or no moving
// joints; a <transmission> whose reduction differs from the drive's ratio.
//
// Drives: "drives" maps every moving joint's name to a drive: a type name from the catalogue
// (ModuleDefaults) or an object {"type": ..., <group>: {overrides}} with the groups of a module
// (motor, inverter, drive, friction, brake, torque_sensor, encoder, controller). The joint's
// range comes from its URDF limits (continuous: +-360 deg) unless the entry gives
// min_angle_deg / max_angle_deg. A URDF <dynamics> with damping or friction above 0 sets the
// drive's friction (link side, divided by the ratio to the motor side) where the entry gives no
// "friction" group, and the controller's friction model with it (docs/robot-format.md).
// The payload sits at the tool frame: the origin of the last link reached through fixed joints
// from the last moving joint's child (when that chain does not branch), else that child's.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "core/plant/robot/robot_config.h"

namespace armfault {

// `value` is the robot object (with "urdf"), `pointer` its JSON pointer, `base_dir` the
// directory of the file that names it. Throws InputError (all errors found, together).
RobotConfig RobotFromUrdfJson(const nlohmann::json& value, const std::string& pointer, const std::string& base_dir);

// The same from a URDF text (`urdf_name` names it in messages) and a drives object.
RobotConfig RobotFromUrdfText(const std::string& urdf_text, const std::string& urdf_name, const nlohmann::json& drives,
                              const std::string& drives_pointer);

// The moving joints' names of a URDF text, base first (what "drives" must name). Throws
// InputError as RobotFromUrdfText does for the file itself.
std::vector<std::string> UrdfMovingJoints(const std::string& urdf_text, const std::string& urdf_name);

// The robot as a URDF (one link per body, its joint's frame at the joint's anchor with the
// world's axes at the zero pose; inertials exact; no visuals) and its drives object
// ({joint name: full module}), so that RobotFromUrdfText(UrdfText(r), DrivesJson(r)) builds the
// same plant.
std::string UrdfText(const RobotConfig& robot);
nlohmann::json DrivesJson(const RobotConfig& robot);

}  // namespace armfault
