// Mass properties of the rigid bodies a robot is built from in ODE (one link body per joint,
// the payload lumped into the last; one rotor body per joint), and the physical floors every
// body must keep so that ODE never meets a body it asserts on (dMassCheck in dBodySetMass, or
// a quaternion that no longer normalises after a step with an absurd angular acceleration).
// The limits and their reasons: docs/assumptions.md, "Physical limits of the robot input".
//
// Used twice, on the same numbers: by Validate() (core/plant/robot/robot_config.h) so that a robot
// file with a body below a floor is an InputError naming the field, and by ArmModel on the
// model it actually hands to ODE (after a run's payload and tolerance draws).
#pragma once

#include <Eigen/Dense>

#include <string>

#include "core/plant/robot/robot_config.h"

namespace armfault {

// Lightest body: 1 g, the rotor body's token mass; no link of a robot arm weighs less.
constexpr double kMinBodyMass_kg = 1e-3;
// Smallest principal moment of inertia of any body: 1e-9 kg m^2 (0.01 g cm^2), below the rotor
// of the smallest catalogue micromotor (a 6 mm coreless motor has about 1.5e-9 kg m^2).
constexpr double kMinMoment_kg_m2 = 1e-9;
// The rotor body's token mass (simulation.h: the rotor's real mass belongs to the link masses).
constexpr double kRotorMass_kg = 1e-3;
// The rotor body's spin axis sits this far from its joint's axis (the planet of the gear,
// simulation.h). Only the ratio of the wheel radii matters to the dynamics; the offset keeps the
// gear row well scaled. With the token mass it moves the link's inertia by m e^2 = 2.5e-6 kg m^2
// and its gravity moment by 5e-4 N m: negligible.
constexpr double kRotorOffset_m = 0.05;

// A link's inertia about its centre of mass in zero-pose world axes: the given principal
// moments (about `dir`, then the joint axis made orthogonal to it, then their cross product),
// or a solid cylinder of the link's mass, radius and length. `dir` and `axis` are unit vectors.
Eigen::Matrix3d LinkInertia(const LinkParams& link, const Eigen::Vector3d& dir, const Eigen::Vector3d& axis);

// The mass properties of a body: mass, centre of mass (zero pose, world) and inertia about it.
struct BodyMass {
  double mass_kg = 0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();
};

// Link `link`'s body as ODE gets it, the link starting at `anchor_m` along the unit `dir`,
// turning about the unit `axis`; `payload_kg` (> 0 on the last link only) is a point mass at
// the link's end, lumped into the body by the parallel-axis theorem.
BodyMass LinkBody(const LinkParams& link, const Eigen::Vector3d& anchor_m, const Eigen::Vector3d& dir,
                  const Eigen::Vector3d& axis, double payload_kg);

// Body `joint` of a robot in the general form (robot.bodies), `payload_kg` (> 0 on the last
// body only) lumped in as a point mass at robot.payload_point_m.
BodyMass BodyOfJoint(const RobotConfig& robot, int joint, double payload_kg);

// The robot in the general form: `bodies` derived from `links` as ArmModel builds them (payload
// excluded; joint names "joint_1", ...; link frames with the world's axes at the joint
// anchors), payload_point_m the end of the last link; a robot already in it is returned as is.
RobotConfig WithBodies(const RobotConfig& robot);

// Why ODE must not be given this body, or "" when it may: every number finite, the mass at
// least kMinBodyMass_kg, the inertia symmetric and its smallest eigenvalue at least
// kMinMoment_kg_m2 (less one part in a million for the rounding of rotating principal moments
// that sit exactly on the floor). The text names the values and reads after "the body's"
// ("smallest principal moment of inertia 5e-10 kg m^2 is below 1e-09 kg m^2").
std::string BodyMassProblem(double mass_kg, const Eigen::Matrix3d& inertia_kg_m2);

}  // namespace armfault
