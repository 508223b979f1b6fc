#include "core/plant/engine/mujoco/mujoco_arm.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>

#ifdef ARMFAULT_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace armfault {

namespace {

// Shortest text that reads back to the same double.
std::string Num(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

std::string Triple(const Eigen::Vector3d& v) { return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z()); }

}  // namespace

std::string MujocoArmXml(const JointSpaceModel& chain, double dt_s, const std::vector<double>& friction_loss_Nm) {
  std::ostringstream x;
  x << "<mujoco model=\"armfault-arm\">\n"
    << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
    << "  <option timestep=\"" << Num(dt_s) << "\" gravity=\"" << Triple(chain.gravity_m_s2)
    << "\" integrator=\"Euler\"/>\n"
    << "  <worldbody>\n";
  std::string indent = "    ";
  for (int i = 0; i < chain.joint_count; ++i) {
    const JointSpaceJoint& j = chain.joints[i];
    const Eigen::Matrix3d& I = j.inertia_kg_m2;
    const double loss = i < static_cast<int>(friction_loss_Nm.size()) ? friction_loss_Nm[i] : 0.0;
    x << indent << "<body name=\"link" << i + 1 << "\" pos=\"" << Triple(j.offset_m) << "\">\n"
      << indent << "  <joint name=\"joint" << i + 1 << "\" type=\"hinge\" pos=\"0 0 0\" axis=\"" << Triple(j.axis)
      << "\" armature=\"" << Num(j.ratio * j.ratio * j.rotor_inertia_kg_m2) << "\" frictionloss=\"" << Num(loss)
      << "\" damping=\"0\" limited=\"false\"/>\n"
      << indent << "  <inertial pos=\"" << Triple(j.com_m) << "\" mass=\"" << Num(j.mass_kg) << "\" fullinertia=\""
      << Num(I(0, 0)) << " " << Num(I(1, 1)) << " " << Num(I(2, 2)) << " " << Num(I(0, 1)) << " " << Num(I(0, 2)) << " "
      << Num(I(1, 2)) << "\"/>\n";
    indent += "  ";
  }
  for (int i = chain.joint_count; i-- > 0;) {
    indent.resize(indent.size() - 2);
    x << indent << "</body>\n";
  }
  x << "  </worldbody>\n</mujoco>\n";
  return x.str();
}

#ifdef ARMFAULT_HAVE_MUJOCO

bool MujocoBuiltIn() { return true; }

std::string MujocoVersion() {
  return mj_versionString();
}

struct MujocoArm::Loaded {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  ~Loaded() {
    if (data) mj_deleteData(data);
    if (model) mj_deleteModel(model);
  }
};

MujocoArm::MujocoArm(const JointSpaceModel& chain, double dt_s, const std::vector<double>& friction_loss_Nm)
    : loaded_(std::make_unique<Loaded>()) {
  const std::string xml = MujocoArmXml(chain, dt_s, friction_loss_Nm);
  const auto vfs = std::make_unique<mjVFS>();  // MuJoCo's file table is large: on the heap
  mj_defaultVFS(vfs.get());
  const char* name = "arm.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("MuJoCo: could not make its virtual file");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], xml.data(), xml.size());
  char error[1000] = "";
  loaded_->model = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!loaded_->model) throw std::runtime_error(std::string("MuJoCo refused the arm's model: ") + error);
  loaded_->data = mj_makeData(loaded_->model);
  if (!loaded_->data) throw std::runtime_error("MuJoCo: could not allocate its data");
}

MujocoArm::~MujocoArm() = default;

double MujocoArm::StepFromRest(long steps) {
  mjModel* m = loaded_->model;
  mjData* d = loaded_->data;
  mj_resetData(m, d);
  for (long s = 0; s < steps; ++s) mj_step(m, d);
  double checksum = 0;
  for (int j = 0; j < m->nq; ++j) checksum += d->qpos[j];
  return checksum;
}

void MujocoArm::MassAndBias(const double* q, const double* qd, std::vector<double>* M, std::vector<double>* bias_Nm) {
  mjModel* m = loaded_->model;
  mjData* d = loaded_->data;
  mj_resetData(m, d);
  const int n = m->nv;
  for (int j = 0; j < n; ++j) {
    d->qpos[j] = q[j];
    d->qvel[j] = qd[j];
  }
  mj_forward(m, d);
  M->assign(static_cast<size_t>(n) * n, 0.0);
  mj_fullM(m, M->data(), d->qM);
  bias_Nm->assign(d->qfrc_bias, d->qfrc_bias + n);
}

#else

bool MujocoBuiltIn() { return false; }
std::string MujocoVersion() { return ""; }

struct MujocoArm::Loaded {};

MujocoArm::MujocoArm(const JointSpaceModel&, double, const std::vector<double>&) {
  throw std::runtime_error("MuJoCo is not built in (libmujoco-dev was not found when armfault was configured)");
}
MujocoArm::~MujocoArm() = default;
double MujocoArm::StepFromRest(long) { return 0; }
void MujocoArm::MassAndBias(const double*, const double*, std::vector<double>*, std::vector<double>*) {}

#endif

}  // namespace armfault
