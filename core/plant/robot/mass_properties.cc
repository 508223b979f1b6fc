#include "core/plant/robot/mass_properties.h"

#include <cmath>

#include "core/base/json_input.h"

namespace armfault {

Eigen::Matrix3d LinkInertia(const LinkParams& l, const Eigen::Vector3d& dir, const Eigen::Vector3d& axis) {
  double along, perp1, perp2;
  if (l.has_inertia) {
    along = l.inertia_kg_m2[0];
    perp1 = l.inertia_kg_m2[1];
    perp2 = l.inertia_kg_m2[2];
  } else {  // solid cylinder
    along = 0.5 * l.mass_kg * l.radius_m * l.radius_m;
    perp1 = perp2 = l.mass_kg * (3.0 * l.radius_m * l.radius_m + l.length_m * l.length_m) / 12.0;
  }
  // perp1 along the joint axis component orthogonal to the link, perp2 completes the frame.
  Eigen::Vector3d e1 = axis - axis.dot(dir) * dir;
  if (e1.norm() < 1e-9) e1 = dir.unitOrthogonal();
  e1.normalize();
  const Eigen::Vector3d e2 = dir.cross(e1);
  return along * dir * dir.transpose() + perp1 * e1 * e1.transpose() + perp2 * e2 * e2.transpose();
}

namespace {

Eigen::Matrix3d PointInertia(double mass, const Eigen::Vector3d& r) {
  return mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
}

// Lumps a point mass `mass_kg` at `at` into `b` (parallel-axis theorem): the payload at the tool.
void AddPointMass(double mass_kg, const Eigen::Vector3d& at, BodyMass* b) {
  const double m = b->mass_kg;
  const Eigen::Vector3d c = (m * b->com_m + mass_kg * at) / (m + mass_kg);
  b->inertia_kg_m2 += PointInertia(m, b->com_m - c) + PointInertia(mass_kg, at - c);
  b->mass_kg += mass_kg;
  b->com_m = c;
}

}  // namespace

BodyMass LinkBody(const LinkParams& l, const Eigen::Vector3d& anchor_m, const Eigen::Vector3d& dir,
                  const Eigen::Vector3d& axis, double payload_kg) {
  BodyMass b;
  const Eigen::Vector3d end = anchor_m + l.length_m * dir;
  b.com_m = anchor_m + l.com_fraction * l.length_m * dir;
  b.inertia_kg_m2 = LinkInertia(l, dir, axis);
  b.mass_kg = l.mass_kg;
  if (payload_kg > 0) AddPointMass(payload_kg, end, &b);
  return b;
}

BodyMass BodyOfJoint(const RobotConfig& robot, int joint, double payload_kg) {
  const JointBody& jb = robot.bodies.at(joint);
  BodyMass b;
  b.mass_kg = jb.mass_kg;
  b.com_m = Eigen::Vector3d(jb.com_m[0], jb.com_m[1], jb.com_m[2]);
  const auto& I = jb.inertia_kg_m2;
  b.inertia_kg_m2 << I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2];
  if (payload_kg > 0) {
    AddPointMass(payload_kg, Eigen::Vector3d(robot.payload_point_m[0], robot.payload_point_m[1], robot.payload_point_m[2]), &b);
  }
  return b;
}

RobotConfig WithBodies(const RobotConfig& robot) {
  if (!robot.bodies.empty()) return robot;
  RobotConfig r = robot;
  Eigen::Vector3d anchor(robot.base_position_m[0], robot.base_position_m[1], robot.base_position_m[2]);
  for (size_t i = 0; i < robot.links.size(); ++i) {
    const LinkParams& l = robot.links[i];
    const Eigen::Vector3d axis = Eigen::Vector3d(l.joint_axis[0], l.joint_axis[1], l.joint_axis[2]).normalized();
    const Eigen::Vector3d dir = Eigen::Vector3d(l.direction[0], l.direction[1], l.direction[2]).normalized();
    const BodyMass body = LinkBody(l, anchor, dir, axis, 0.0);
    JointBody b;
    b.joint_name = "joint_" + std::to_string(i + 1);
    b.anchor_m = b.frame_origin_m = {anchor.x(), anchor.y(), anchor.z()};
    b.axis = {axis.x(), axis.y(), axis.z()};
    b.mass_kg = body.mass_kg;
    b.com_m = {body.com_m.x(), body.com_m.y(), body.com_m.z()};
    const Eigen::Matrix3d& I = body.inertia_kg_m2;
    b.inertia_kg_m2 = {I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)};
    r.bodies.push_back(b);
    anchor += l.length_m * dir;
  }
  r.payload_point_m = {anchor.x(), anchor.y(), anchor.z()};
  r.links.clear();
  return r;
}

std::string BodyMassProblem(double mass_kg, const Eigen::Matrix3d& inertia) {
  if (!std::isfinite(mass_kg) || !inertia.allFinite()) {
    return "mass or inertia is not a finite number";
  }
  if (mass_kg < kMinBodyMass_kg) {
    return "mass " + FormatNumber(mass_kg) + " kg is below " + FormatNumber(kMinBodyMass_kg) + " kg";
  }
  if (!inertia.isApprox(inertia.transpose(), 1e-12)) return "inertia tensor is not symmetric";
  const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia, Eigen::EigenvaluesOnly).eigenvalues()(0);
  if (!(smallest >= kMinMoment_kg_m2 * (1 - 1e-6))) {
    return "smallest principal moment of inertia " + FormatNumber(smallest) + " kg m^2 is below " +
           FormatNumber(kMinMoment_kg_m2) + " kg m^2";
  }
  return "";
}

}  // namespace armfault
