#include "core/plant/engine/joint_space_dynamics.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace armfault {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr int kN = kMaxEngineJoints;
using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kN, 1>;

// Rotation by `angle` about the unit `a` (Rodrigues).
Matrix3d Rotation(const Vector3d& a, double angle) {
  const double c = std::cos(angle), s = std::sin(angle), v = 1 - c;
  const double x = a.x(), y = a.y(), z = a.z();
  Matrix3d R;
  R << c + v * x * x, v * x * y - s * z, v * x * z + s * y,  //
      v * x * y + s * z, c + v * y * y, v * y * z - s * x,   //
      v * x * z - s * y, v * y * z + s * x, c + v * z * z;
  return R;
}

// The chain at one pose, world coordinates: joint i's axis z_i, anchor p_i, s_i's linear part
// p_i × z_i, link i's spatial inertia about O (mass m, first moment h = m c, inertia I_O about
// O; the rotor's token mass lumped in) and rotor i's token mass alone (mr, hr, Ir).
struct Pose {
  Vector3d z[kN], p[kN], pz[kN];
  double m[kN];
  Vector3d h[kN];
  Matrix3d I[kN];
  double mr[kN];
  Vector3d hr[kN];
  Matrix3d Ir[kN];
};


void MakePose(const JointSpaceModel& model, const double* q, Pose* pose) {
  Matrix3d R = Matrix3d::Identity();
  Vector3d p = Vector3d::Zero();
  for (int i = 0; i < model.joint_count; ++i) {
    const JointSpaceJoint& j = model.joints[i];
    p += R * j.offset_m;
    pose->z[i] = R * j.axis;
    pose->p[i] = p;
    pose->pz[i] = p.cross(pose->z[i]);
    R = R * Rotation(j.axis, q[i]);
    const Vector3d c = p + R * j.com_m;
    pose->m[i] = j.mass_kg;
    pose->h[i] = j.mass_kg * c;
    pose->I[i] = R * j.inertia_kg_m2 * R.transpose() + j.mass_kg * (c.squaredNorm() * Matrix3d::Identity() - c * c.transpose());
    const Vector3d cr = p + R * j.rotor_centre_m;
    pose->mr[i] = j.rotor_mass_kg;
    pose->hr[i] = j.rotor_mass_kg * cr;
    pose->Ir[i] = j.rotor_mass_kg * (cr.squaredNorm() * Matrix3d::Identity() - cr * cr.transpose());
  }
}

// Recursive Newton-Euler, spatial vectors about O: Q for q̈ (q̈ = 0 when `qdd` is null); with
// `sensor`, also what joint i's torque sensor carries (no rotor i spin, no token mass i).
void Rnea(const JointSpaceModel& model, const Pose& pose, const double* qd, const double* qdd, double* Q,
          double* sensor = nullptr) {
  const int n = model.joint_count;
  Vector3d wn[kN], wf[kN], rotor[kN];  // link i's wrench (moment about O, force); rotor i's moment
  Vector3d tn[kN], tf[kN];              // sensor: token mass i's wrench
  Vector3d w = Vector3d::Zero(), v = Vector3d::Zero();                    // V_{i-1}
  Vector3d dw = Vector3d::Zero(), dv = -model.gravity_m_s2;               // A_{i-1}, gravity up
  for (int i = 0; i < n; ++i) {
    const JointSpaceJoint& j = model.joints[i];
    const Vector3d& z = pose.z[i];
    const Vector3d& pz = pose.pz[i];
    const double a = qdd ? qdd[i] : 0.0;
    // Rotor i on link i-1: α_{i-1} + γ q̈_i z_i + γ q̇_i ω_{i-1} × z_i.
    rotor[i] = j.rotor_inertia_kg_m2 * (dw + j.ratio * a * z + j.ratio * qd[i] * w.cross(z));
    w += z * qd[i];
    v += pz * qd[i];
    // A_i = A_{i-1} + s_i q̈_i + V_i ×m s_i q̇_i.
    dw += z * a + w.cross(z) * qd[i];
    dv += pz * a + (v.cross(z) + w.cross(pz)) * qd[i];
    // f_i = I_i A_i + V_i ×f I_i V_i.
    const Vector3d H = pose.I[i] * w + pose.h[i].cross(v);
    const Vector3d L = pose.m[i] * v + w.cross(pose.h[i]);
    wn[i] = pose.I[i] * dw + pose.h[i].cross(dv) + w.cross(H) + v.cross(L);
    wf[i] = pose.m[i] * dv + dw.cross(pose.h[i]) + w.cross(L);
    if (sensor) {
      // Rotor i's token mass alone, moving with link i: kept apart to be taken off below.
      const Vector3d Hr = pose.Ir[i] * w + pose.hr[i].cross(v);
      const Vector3d Lr = pose.mr[i] * v + w.cross(pose.hr[i]);
      tn[i] = pose.Ir[i] * dw + pose.hr[i].cross(dv) + w.cross(Hr) + v.cross(Lr);
      tf[i] = pose.mr[i] * dv + dw.cross(pose.hr[i]) + w.cross(Lr);
    }
  }
  Vector3d Fn = Vector3d::Zero(), Ff = Vector3d::Zero();
  for (int i = n; i-- > 0;) {
    Fn += wn[i];
    Ff += wf[i];
    if (i + 1 < n) Fn += rotor[i + 1];  // rotor i+1 rides on link i
    Q[i] = pose.z[i].dot(Fn) + pose.pz[i].dot(Ff) + model.joints[i].ratio * pose.z[i].dot(rotor[i]);
    if (sensor) sensor[i] = pose.z[i].dot(Fn - tn[i]) + pose.pz[i].dot(Ff - tf[i]);
  }
}

// Composite rigid bodies about O, with the rotors' spin and its gear coupling; with `S`, also
// the sensors' matrix: M less, in row i, rotor i's spin (γ_i I_m,i z_i·z_l, γ_i² I_m,i) and
// token mass i (s_i' I_r,i s_l), l ≤ i: what joint i's generalised force has and its sensor not.
void Crba(const JointSpaceModel& model, const Pose& pose, JointMatrix* M, JointMatrix* S = nullptr) {
  const int n = model.joint_count;
  M->resize(n, n);
  double Cm = 0;
  Vector3d Ch = Vector3d::Zero();
  Matrix3d CI = Matrix3d::Zero();
  for (int i = n; i-- > 0;) {
    Cm += pose.m[i];
    Ch += pose.h[i];
    CI += pose.I[i];
    if (i + 1 < n) CI.diagonal().array() += model.joints[i + 1].rotor_inertia_kg_m2;
    const Vector3d& z = pose.z[i];
    // I^C_i s_i.
    const Vector3d H = CI * z + Ch.cross(pose.pz[i]);
    const Vector3d L = Cm * pose.pz[i] + z.cross(Ch);
    const double g = model.joints[i].ratio, Im = model.joints[i].rotor_inertia_kg_m2;
    for (int k = 0; k < i; ++k) {
      const double Mki = pose.z[k].dot(H) + pose.pz[k].dot(L) + g * Im * pose.z[k].dot(z);
      (*M)(k, i) = Mki;
      (*M)(i, k) = Mki;
    }
    (*M)(i, i) = z.dot(H) + pose.pz[i].dot(L) + g * g * Im;
  }
  if (!S) return;
  *S = *M;
  for (int i = 0; i < n; ++i) {
    const double g = model.joints[i].ratio, Im = model.joints[i].rotor_inertia_kg_m2;
    for (int l = 0; l <= i; ++l) {
      const Vector3d& z = pose.z[l];
      const Vector3d H = pose.Ir[i] * z + pose.hr[i].cross(pose.pz[l]);
      const Vector3d L = pose.mr[i] * pose.pz[l] + z.cross(pose.hr[i]);
      const double spin = l < i ? g * Im * pose.z[i].dot(z) : g * g * Im;
      (*S)(i, l) -= pose.z[i].dot(H) + pose.pz[i].dot(L) + spin;
    }
  }
}

}  // namespace

JointSpaceModel MakeJointSpaceModel(const RigidBodyModel& bodies) {
  const int n = static_cast<int>(bodies.joints.size());
  if (n < 1 || n > kMaxEngineJoints) {
    throw std::invalid_argument("joint-space engine: " + std::to_string(n) + " joints, needs 1 to " +
                                std::to_string(kMaxEngineJoints));
  }
  JointSpaceModel m;
  m.joint_count = n;
  m.gravity_m_s2 = bodies.gravity_m_s2;
  Vector3d parent = Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const RigidJoint& b = bodies.joints[i];
    JointSpaceJoint& j = m.joints[i];
    j.offset_m = b.anchor_m - parent;
    j.axis = b.axis.normalized();
    // The link and the rotor's token mass, one rigid body about frame i's origin.
    const double mass = b.mass_kg + b.rotor_mass_kg;
    const Vector3d cl = b.com_m - b.anchor_m, cr = b.rotor_centre_m - b.anchor_m;
    const Vector3d c = mass > 0 ? ((b.mass_kg * cl + b.rotor_mass_kg * cr) / mass).eval() : Vector3d::Zero();
    auto shift = [](double mk, const Vector3d& d) {
      return (mk * (d.squaredNorm() * Matrix3d::Identity() - d * d.transpose())).eval();
    };
    j.mass_kg = mass;
    j.com_m = c;
    j.inertia_kg_m2 = b.inertia_kg_m2 + shift(b.mass_kg, cl - c) + shift(b.rotor_mass_kg, cr - c);
    j.rotor_inertia_kg_m2 = b.rotor_inertia_kg_m2;
    j.ratio = b.ratio;
    j.rotor_mass_kg = b.rotor_mass_kg;
    j.rotor_centre_m = cr;
    parent = b.anchor_m;
  }
  return m;
}

void MassMatrix(const JointSpaceModel& model, const double* q, JointMatrix* M) {
  Pose pose;
  MakePose(model, q, &pose);
  Crba(model, pose, M);
}

void Bias(const JointSpaceModel& model, const double* q, const double* qd, double* b_Nm) {
  Pose pose;
  MakePose(model, q, &pose);
  Rnea(model, pose, qd, nullptr, b_Nm);
}

void MassMatrixAndBias(const JointSpaceModel& model, const double* q, const double* qd, JointMatrix* M, double* b_Nm) {
  Pose pose;
  MakePose(model, q, &pose);
  Crba(model, pose, M);
  Rnea(model, pose, qd, nullptr, b_Nm);
}

void MassMatrixBiasAndSensor(const JointSpaceModel& model, const double* q, const double* qd, JointMatrix* M, double* b_Nm,
                             JointMatrix* S, double* tau0_Nm) {
  Pose pose;
  MakePose(model, q, &pose);
  Crba(model, pose, M, S);
  Rnea(model, pose, qd, nullptr, b_Nm, tau0_Nm);
}

void InverseDynamics(const JointSpaceModel& model, const double* q, const double* qd, const double* qdd,
                     double* Q_Nm) {
  Pose pose;
  MakePose(model, q, &pose);
  Rnea(model, pose, qd, qdd, Q_Nm);
}

void ForwardDynamics(const JointSpaceModel& model, const double* q, const double* qd, const double* Q_Nm,
                     double* qdd) {
  const int n = model.joint_count;
  Pose pose;
  MakePose(model, q, &pose);
  JointMatrix M;
  Crba(model, pose, &M);
  double b[kN];
  Rnea(model, pose, qd, nullptr, b);
  JointVector x(n);
  for (int i = 0; i < n; ++i) x[i] = Q_Nm[i] - b[i];
  const Eigen::LLT<JointMatrix> llt(M);
  llt.solveInPlace(x);
  for (int i = 0; i < n; ++i) qdd[i] = x[i];
}

}  // namespace armfault
