#include "core/plant/ode_world.h"

#include <cmath>
#include <mutex>

#include "core/plant/ode_runtime.h"
#include "core/plant/robot/mass_properties.h"

namespace armfault {

namespace {

Eigen::Vector3d ToEigen(const dReal* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

void SetBodyPose(dBodyID b, const Eigen::Vector3d& pos, const Eigen::Matrix3d& rot) {
  dBodySetPosition(b, pos.x(), pos.y(), pos.z());
  dMatrix3 R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[4 * r + c] = rot(r, c);
    R[4 * r + 3] = 0;
  }
  dBodySetRotation(b, R);
}

// The ODE side of one run: its own world and threading implementation; per joint a link
// body with its hinge to the parent, and a rotor body with its hinge to the link, its gear
// (transmission) to the parent and its dry-friction row (AMotor) against the parent.
// Owns a world (its bodies and joints) and the threading implementation it steps with: the
// first member of OdeWorld, so both are released even when ODE fails (OdeError,
// core/plant/ode_runtime.h) while OdeWorld's constructor is still building the bodies.
// A step that ODE left by an OdeError leaves the jobs it never ran queued in the threading
// implementation, whose destructor asserts that none are (~dxtemplateJobListContainer, an
// abort from a destructor): that implementation is not freed but kept (KeepInterrupted), with
// the step's 64 KiB memory arena its jobs hold. The world itself is destroyed (no ODE object
// refers to it; memory-safe under ASan). About 66 KB per such failure, a last resort.
void KeepInterrupted(dThreadingImplementationID threading) {
  // Held, not lost: a leak checker sees them as reachable.
  static std::mutex mutex;
  static auto* kept = new std::vector<dThreadingImplementationID>;
  std::lock_guard<std::mutex> lock(mutex);
  kept->push_back(threading);
}

double WrapPi(double a) { return std::remainder(a, 2.0 * M_PI); }

}  // namespace

struct OwnedWorld {
  dWorldID world = nullptr;
  dThreadingImplementationID threading = nullptr;
  bool stepping = false;  // inside dWorldStep: still true if it was left by an OdeError
  OwnedWorld() {
    EnsureOdeThreadData();
    world = dWorldCreate();
    threading = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(threading), threading);
  }
  ~OwnedWorld() {
    dWorldDestroy(world);  // destroys its bodies and joints
    if (stepping) KeepInterrupted(threading);
    else dThreadingFreeImplementation(threading);
  }
  void Step(double dt) {
    stepping = true;
    dWorldStep(world, dt);
    stepping = false;
  }
  OwnedWorld(const OwnedWorld&) = delete;
  OwnedWorld& operator=(const OwnedWorld&) = delete;
};

OdeWorld::OdeWorld(const ArmModel& model, const std::vector<double>& q0, const std::vector<double>& qd0)
    : owned_(std::make_unique<OwnedWorld>()), world_(owned_->world) {
  const double g = model.config().gravity_m_s2;
  dWorldSetGravity(world_, 0, 0, -g);
  dWorldSetCFM(world_, model.config().constraint_force_mixing);
  // Joint 1's stator and sun wheel: the world, as a body the transmission can attach to.
  ground_ = dBodyCreate(world_);
  dBodySetKinematic(ground_);

  const int n = model.joint_count();
  bodies_.resize(n);
  rotors_.resize(n);
  joints_.resize(n);
  rotor_hinges_.resize(n);
  drags_.resize(n);
  rotor_feedback_.resize(n);
  drag_feedback_.resize(n);
  // Forward kinematics at the initial angles: X_i = X_{i-1} o (rotation about joint i).
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  Eigen::Vector3d trans = Eigen::Vector3d::Zero();
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> anchors(n), axes(n);
  for (int i = 0; i < n; ++i) {
    const JointModel& jm = model.joint(i);
    anchors[i] = rot * jm.anchor_m + trans;
    axes[i] = rot * jm.axis;
    const Eigen::Matrix3d q_rot = Eigen::AngleAxisd(q0[i], jm.axis).toRotationMatrix();
    trans = rot * (jm.anchor_m - q_rot * jm.anchor_m) + trans;
    rot = rot * q_rot;
    omega += qd0[i] * axes[i];
    auto velocity_at = [&](const Eigen::Vector3d& p) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (int k = 0; k <= i; ++k) v += qd0[k] * axes[k].cross(p - anchors[k]);
      return v;
    };
    dBodyID parent = i == 0 ? ground_ : bodies_[i - 1];

    dBodyID b = dBodyCreate(world_);
    dMass mass;
    const Eigen::Matrix3d& I = jm.inertia_kg_m2;
    dMassSetParameters(&mass, jm.mass_kg, 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
    dBodySetMass(b, &mass);
    const Eigen::Vector3d com = rot * jm.com_m + trans;
    SetBodyPose(b, com, rot);
    const Eigen::Vector3d v = velocity_at(com);
    dBodySetLinearVel(b, v.x(), v.y(), v.z());
    dBodySetAngularVel(b, omega.x(), omega.y(), omega.z());
    bodies_[i] = b;

    dJointID j = dJointCreateHinge(world_, nullptr);
    // Child first: the hinge rate is then (omega_child - omega_parent) . axis.
    dJointAttach(j, b, i == 0 ? nullptr : bodies_[i - 1]);
    dJointSetHingeAnchor(j, anchors[i].x(), anchors[i].y(), anchors[i].z());
    dJointSetHingeAxis(j, axes[i].x(), axes[i].y(), axes[i].z());
    joints_[i] = j;

    // Rotor: isotropic I_m (no gyroscopic torque), spinning gamma q_dot relative to the
    // parent, i.e. (gamma - 1) q_dot relative to the link that carries it.
    dBodyID r = dBodyCreate(world_);
    dMass rm;
    const double im = jm.rotor_inertia_kg_m2;
    dMassSetParameters(&rm, kRotorMass_kg, 0, 0, 0, im, im, im, 0, 0, 0);
    dBodySetMass(r, &rm);
    const Eigen::Vector3d centre = rot * jm.rotor_centre_m + trans;
    SetBodyPose(r, centre, rot);
    const Eigen::Vector3d vr = velocity_at(centre);
    const Eigen::Vector3d wr = omega + (jm.ratio - 1.0) * qd0[i] * axes[i];
    dBodySetLinearVel(r, vr.x(), vr.y(), vr.z());
    dBodySetAngularVel(r, wr.x(), wr.y(), wr.z());
    rotors_[i] = r;

    dJointID rh = dJointCreateHinge(world_, nullptr);
    dJointAttach(rh, r, b);  // rotor first: feedback f2/t2 is the rotor's wrench on the link
    dJointSetHingeAnchor(rh, centre.x(), centre.y(), centre.z());
    dJointSetHingeAxis(rh, axes[i].x(), axes[i].y(), axes[i].z());
    dJointSetFeedback(rh, &rotor_feedback_[i]);
    rotor_hinges_[i] = rh;

    // Planet (rotor, radius e/gamma) on a sun wheel fixed to the parent (radius
    // e (gamma-1)/gamma) centred on the joint axis.
    dJointID gear = dJointCreateTransmission(world_, nullptr);
    dJointAttach(gear, r, parent);
    dJointSetTransmissionMode(gear, dTransmissionParallelAxes);
    dJointSetTransmissionRatio(gear, 1.0 / (jm.ratio - 1.0));
    dJointSetTransmissionAxis(gear, axes[i].x(), axes[i].y(), axes[i].z());
    dJointSetTransmissionAnchor1(gear, centre.x(), centre.y(), centre.z());
    dJointSetTransmissionAnchor2(gear, anchors[i].x(), anchors[i].y(), anchors[i].z());

    // Dry friction on the rotor shaft: rate (omega_rotor - omega_parent) . z, target 0.
    dJointID drag = dJointCreateAMotor(world_, nullptr);
    dJointAttach(drag, r, parent);
    dJointSetAMotorMode(drag, dAMotorUser);
    dJointSetAMotorNumAxes(drag, 1);
    dJointSetAMotorAxis(drag, 0, 2, axes[i].x(), axes[i].y(), axes[i].z());  // fixed in the parent
    dJointSetAMotorParam(drag, dParamVel, 0.0);
    dJointSetAMotorParam(drag, dParamFMax, 0.0);
    dJointSetFeedback(drag, &drag_feedback_[i]);
    drags_[i] = drag;
  }
  gravity_m_s2_ = g;
  q_initial_ = q0;
  step_axis_.assign(n, Eigen::Vector3d::UnitZ());
  readout_.resize(n);
  for (int i = 0; i < n; ++i) {
    readout_[i].q_rad = q0[i];
    readout_[i].qd_rad_s = qd0[i];
    readout_[i].rotor_rate_rad_s = model.joint(i).ratio * qd0[i];
  }
}

OdeWorld::~OdeWorld() = default;

void OdeWorld::SetJoint(int j, double couple_Nm, double dry_bound_Nm) {
  dJointSetAMotorParam(drags_[j], dParamFMax, dry_bound_Nm);
  dVector3 axis;
  dJointGetHingeAxis(joints_[j], axis);
  step_axis_[j] = ToEigen(axis);
  const Eigen::Vector3d couple = couple_Nm * step_axis_[j];
  dBodyAddTorque(rotors_[j], couple.x(), couple.y(), couple.z());
  if (dBodyID stator = parent(j)) dBodyAddTorque(stator, -couple.x(), -couple.y(), -couple.z());
}

void OdeWorld::Step(double dt_s) {
  owned_->Step(dt_s);
  for (size_t j = 0; j < readout_.size(); ++j) {
    JointReadout& r = readout_[j];
    dJointID hinge = joints_[j];
    dVector3 axis_v, anchor_v;
    dJointGetHingeAxis(hinge, axis_v);
    dJointGetHingeAnchor(hinge, anchor_v);
    const Eigen::Vector3d axis = ToEigen(axis_v);
    r.qd_rad_s = dJointGetHingeAngleRate(hinge);
    const double raw = dJointGetHingeAngle(hinge);
    r.q_rad += WrapPi(raw - WrapPi(r.q_rad - q_initial_[j]));
    r.rotor_rate_rad_s = RotorRate(static_cast<int>(j), axis);
    // What the harmonic drive passes on to the link: the moment about the joint axis of the
    // rotor hinge's wrench on the link (the gear reaction through the planet's carrier).
    const dJointFeedback& rf = rotor_feedback_[j];
    const Eigen::Vector3d com = ToEigen(dBodyGetPosition(bodies_[j]));
    r.tau_transmitted_Nm = (ToEigen(rf.t2) + (com - ToEigen(anchor_v)).cross(ToEigen(rf.f2))).dot(axis);
    // The AMotor row is a pure torque on the rotor: the dry friction (motor side).
    r.dry_torque_Nm = ToEigen(drag_feedback_[j].t1).dot(step_axis_[j]);
  }
}

double OdeWorld::RotorRate(int i, const Eigen::Vector3d& axis) const {
  double w = axis.dot(ToEigen(dBodyGetAngularVel(rotors_[i])));
  if (i > 0) w -= axis.dot(ToEigen(dBodyGetAngularVel(bodies_[i - 1])));
  return w;
}

double OdeWorld::KineticEnergyOf(const std::vector<dBodyID>& bodies) {
  double e = 0;
  for (dBodyID b : bodies) {
    dMass m;
    dBodyGetMass(b, &m);
    const Eigen::Vector3d v = ToEigen(dBodyGetLinearVel(b));
    Eigen::Vector3d w_world = ToEigen(dBodyGetAngularVel(b));
    dVector3 w_body;
    dBodyVectorFromWorld(b, w_world.x(), w_world.y(), w_world.z(), w_body);
    Eigen::Matrix3d I;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) I(r, c) = m.I[4 * r + c];
    const Eigen::Vector3d wb = ToEigen(w_body);
    e += 0.5 * m.mass * v.squaredNorm() + 0.5 * wb.dot(I * wb);
  }
  return e;
}
double OdeWorld::PotentialEnergyOf(const std::vector<dBodyID>& bodies, double g) {
  double e = 0;
  for (dBodyID b : bodies) {
    dMass m;
    dBodyGetMass(b, &m);
    e += m.mass * g * dBodyGetPosition(b)[2];
  }
  return e;
}

}  // namespace armfault
