#include "core/plant/robot/rigid_body_dynamics.h"

#include <cmath>

#include "core/plant/robot/mass_properties.h"

namespace armfault {

namespace {

Eigen::Vector3d Vec(const std::array<double, 3>& a) { return Eigen::Vector3d(a[0], a[1], a[2]); }

// Every body's motion at one state: joint i's axis z_i and anchor p_i (current pose, world),
// link i's rotation R_i and translation t_i from the zero pose, its angular velocity and
// acceleration, and the linear acceleration of p_i less gravity (the base accelerates up).
struct Kinematics {
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::Vector3d> t, z, p, w, dw, a_p;
};

void ForwardPass(const RigidBodyModel& m, const double* q, const double* qd, const double* qdd, Kinematics* k) {
  const size_t n = m.joints.size();
  k->R.resize(n), k->t.resize(n), k->z.resize(n), k->p.resize(n), k->w.resize(n), k->dw.resize(n), k->a_p.resize(n);
  Eigen::Matrix3d Rp = Eigen::Matrix3d::Identity();
  Eigen::Vector3d tp = Eigen::Vector3d::Zero(), wp = Eigen::Vector3d::Zero(), dwp = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_prev = -m.gravity_m_s2, p_prev = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const RigidJoint& j = m.joints[i];
    const Eigen::Vector3d p = Rp * j.anchor_m + tp;
    const Eigen::Vector3d z = Rp * j.axis;
    const Eigen::Matrix3d Rq = Eigen::AngleAxisd(q[i], j.axis).toRotationMatrix();
    // p_i is a point of the parent body: its acceleration from the parent's anchor.
    const Eigen::Vector3d d = p - p_prev;
    const Eigen::Vector3d a_p = a_prev + dwp.cross(d) + wp.cross(wp.cross(d));
    k->R[i] = Rp * Rq;
    k->t[i] = Rp * (j.anchor_m - Rq * j.anchor_m) + tp;
    k->z[i] = z;
    k->p[i] = p;
    k->w[i] = wp + z * qd[i];
    k->dw[i] = dwp + z * qdd[i] + wp.cross(z) * qd[i];
    k->a_p[i] = a_p;
    Rp = k->R[i], tp = k->t[i], wp = k->w[i], dwp = k->dw[i], a_prev = a_p, p_prev = p;
  }
}

// Angular acceleration of rotor i: α_{i-1} + γ q̈_i z_i + γ q̇_i ω_{i-1} × z_i.
Eigen::Vector3d RotorAcceleration(const RigidBodyModel& m, const Kinematics& k, const double* qd, const double* qdd,
                                  size_t i) {
  const Eigen::Vector3d wp = i == 0 ? Eigen::Vector3d::Zero() : k.w[i - 1];
  const Eigen::Vector3d dwp = i == 0 ? Eigen::Vector3d::Zero() : k.dw[i - 1];
  const double g = m.joints[i].ratio;
  return dwp + g * qdd[i] * k.z[i] + g * qd[i] * wp.cross(k.z[i]);
}

}  // namespace

RigidBodyModel MakeRigidBodyModel(const RobotConfig& robot, double payload_kg) {
  RigidBodyModel m;
  m.gravity_m_s2 = Eigen::Vector3d(0, 0, -robot.gravity_m_s2);
  Eigen::Vector3d anchor = Vec(robot.base_position_m);
  const int n = static_cast<int>(robot.modules.size());
  const bool general = !robot.bodies.empty();
  for (int i = 0; i < n; ++i) {
    const ModuleParams& mod = robot.modules[i];
    RigidJoint j;
    const double payload = i == n - 1 ? payload_kg : 0.0;
    BodyMass body;
    Eigen::Vector3d dir = Eigen::Vector3d::Zero();
    if (general) {  // the general form (a URDF robot): the bodies as given
      const JointBody& jb = robot.bodies[i];
      j.axis = Vec(jb.axis).normalized();
      anchor = Vec(jb.anchor_m);
      body = BodyOfJoint(robot, i, payload);
    } else {  // the links shorthand: each link starts where the last one ended
      j.axis = Vec(robot.links[i].joint_axis).normalized();
      dir = Vec(robot.links[i].direction).normalized();
      body = LinkBody(robot.links[i], anchor, dir, j.axis, payload);
    }
    j.anchor_m = anchor;
    j.mass_kg = body.mass_kg;
    j.com_m = body.com_m;
    j.inertia_kg_m2 = body.inertia_kg_m2;
    j.ratio = mod.drive.ratio;
    j.rotor_inertia_kg_m2 = mod.motor.rotor_inertia_kg_m2;
    j.rotor_mass_kg = kRotorMass_kg;
    j.rotor_centre_m = anchor + kRotorOffset_m * j.axis.unitOrthogonal();
    m.joints.push_back(j);
    if (!general) anchor = anchor + robot.links[i].length_m * dir;
  }
  return m;
}

void TransmittedTorques(const RigidBodyModel& m, const double* q, const double* qd, const double* qdd, double* tau_Nm) {
  const size_t n = m.joints.size();
  thread_local Kinematics k;
  ForwardPass(m, q, qd, qdd, &k);
  // Backward: force F and moment N (about p_i) that the bodies beyond drive i need.
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), N = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_next = Eigen::Vector3d::Zero();
  for (size_t ii = n; ii-- > 0;) {
    const RigidJoint& j = m.joints[ii];
    const Eigen::Vector3d& p = k.p[ii];
    // Moves the outer bodies' resultant from p_{i+1} to p_i.
    N += (p_next - p).cross(F);
    // Link i.
    const Eigen::Vector3d c = k.R[ii] * j.com_m + k.t[ii];
    const Eigen::Vector3d rc = c - p;
    const Eigen::Vector3d a_c = k.a_p[ii] + k.dw[ii].cross(rc) + k.w[ii].cross(k.w[ii].cross(rc));
    const Eigen::Matrix3d I = k.R[ii] * j.inertia_kg_m2 * k.R[ii].transpose();
    const Eigen::Vector3d f = j.mass_kg * a_c;
    F += f;
    N += I * k.dw[ii] + k.w[ii].cross(I * k.w[ii]) + rc.cross(f);
    // Rotor i+1, carried by link i+1, is beyond drive i (not beyond its own).
    if (ii + 1 < n) {
      const RigidJoint& jr = m.joints[ii + 1];
      const size_t r = ii + 1;
      const Eigen::Vector3d centre = k.R[r] * jr.rotor_centre_m + k.t[r];
      const Eigen::Vector3d rr = centre - k.p[r];
      const Eigen::Vector3d a_r = k.a_p[r] + k.dw[r].cross(rr) + k.w[r].cross(k.w[r].cross(rr));
      const Eigen::Vector3d fr = jr.rotor_mass_kg * a_r;
      F += fr;
      // Isotropic: no gyroscopic term.
      N += jr.rotor_inertia_kg_m2 * RotorAcceleration(m, k, qd, qdd, r) + (centre - p).cross(fr);
    }
    tau_Nm[ii] = k.z[ii].dot(N);
    p_next = p;
  }
}

void RotorTorques(const RigidBodyModel& m, const double* q, const double* qd, const double* qdd, double* rotor_Nm) {
  thread_local Kinematics k;
  ForwardPass(m, q, qd, qdd, &k);
  for (size_t i = 0; i < m.joints.size(); ++i) {
    const RigidJoint& j = m.joints[i];
    // Spin, geared up by γ; and the token mass, carried by link i about its joint.
    const Eigen::Vector3d rr = k.R[i] * j.rotor_centre_m + k.t[i] - k.p[i];
    const Eigen::Vector3d a_r = k.a_p[i] + k.dw[i].cross(rr) + k.w[i].cross(k.w[i].cross(rr));
    rotor_Nm[i] = j.ratio * j.rotor_inertia_kg_m2 * k.z[i].dot(RotorAcceleration(m, k, qd, qdd, i)) +
                  k.z[i].dot(rr.cross(j.rotor_mass_kg * a_r));
  }
}

}  // namespace armfault
