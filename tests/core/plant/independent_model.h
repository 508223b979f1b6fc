// An independent model of the plant's rigid bodies for cross-checks (as Pinocchio checks its ABA
// against its RNEA): the mass matrix from the bodies' Jacobians, the generalised gravity force,
// and the accelerations of the unpowered, frictionless arm with the Coriolis and centrifugal
// terms from M's derivatives. Written from simulation.h's description, not from the plant's code.
#pragma once

#include <Eigen/Dense>

#include <vector>

#include "core/plant/robot/mass_properties.h"
#include "core/plant/simulation.h"

namespace armfault {
namespace testing_support {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

// An independent model of the plant's rigid bodies: per joint the link body and the rotor
// (isotropic I_m, a token mass on the link at the rotor's centre, turning at
// omega_parent + gamma q_dot z), the mass matrix from the bodies' Jacobians and the generalised
// gravity force. Written from simulation.h's description, not from its code.
struct RigidModel {
  MatrixXd mass;
  VectorXd gravity;  // generalised force of gravity: M qdd = gravity at rest, unpowered
};

inline RigidModel Independent(const ArmModel& model, const std::vector<double>& q) {
  const int n = model.joint_count();
  const double g = model.config().gravity_m_s2;
  RigidModel out{MatrixXd::Zero(n, n), VectorXd::Zero(n)};
  // Rigid transforms of the zero-pose geometry: X_i = X_{i-1} o rotation by q_i about joint i.
  std::vector<Matrix3d> R(n);
  std::vector<Vector3d> t(n), z(n), p(n);
  Matrix3d Rp = Matrix3d::Identity();
  Vector3d tp = Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const JointModel& jm = model.joint(i);
    p[i] = Rp * jm.anchor_m + tp;
    z[i] = Rp * jm.axis;
    const Matrix3d Rq = Eigen::AngleAxisd(q[i], jm.axis).toRotationMatrix();
    R[i] = Rp * Rq;
    t[i] = Rp * (jm.anchor_m - Rq * jm.anchor_m) + tp;
    Rp = R[i];
    tp = t[i];
  }
  auto add_body = [&](double m, const Matrix3d& I, const MatrixXd& Jv, const MatrixXd& Jw) {
    out.mass += m * Jv.transpose() * Jv + Jw.transpose() * I * Jw;
    out.gravity += Jv.transpose() * (m * Vector3d(0, 0, -g));
  };
  for (int i = 0; i < n; ++i) {
    const JointModel& jm = model.joint(i);
    const Vector3d c = R[i] * jm.com_m + t[i];
    const Vector3d cr = R[i] * jm.rotor_centre_m + t[i];
    MatrixXd Jv = MatrixXd::Zero(3, n), Jw = MatrixXd::Zero(3, n), Jvr = MatrixXd::Zero(3, n), Jwr = MatrixXd::Zero(3, n);
    for (int k = 0; k <= i; ++k) {
      Jv.col(k) = z[k].cross(c - p[k]);
      Jw.col(k) = z[k];
      Jvr.col(k) = z[k].cross(cr - p[k]);
      Jwr.col(k) = k < i ? z[k] : Vector3d(jm.ratio * z[k]);
    }
    add_body(jm.mass_kg, R[i] * jm.inertia_kg_m2 * R[i].transpose(), Jv, Jw);
    add_body(kRotorMass_kg, jm.rotor_inertia_kg_m2 * Matrix3d::Identity(), Jvr, Jwr);
  }
  return out;
}

inline VectorXd Accelerations(const ArmModel& model, const VectorXd& q, const VectorXd& qd) {
  const int n = model.joint_count();
  auto mass = [&](const VectorXd& x) { return Independent(model, std::vector<double>(x.data(), x.data() + n)).mass; };
  const RigidModel here = Independent(model, std::vector<double>(q.data(), q.data() + n));
  // h = Mdot qd - 1/2 d(qd' M qd)/dq, with dM/dq_k by central differences.
  const double e = 1e-6;
  VectorXd h = VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    VectorXd up = q, down = q;
    up[k] += e;
    down[k] -= e;
    const MatrixXd dM = (mass(up) - mass(down)) / (2 * e);
    h += dM * qd * qd[k];
    h[k] -= 0.5 * qd.dot(dM * qd);
  }
  return here.mass.ldlt().solve(here.gravity - h);
}

}  // namespace testing_support
}  // namespace armfault
