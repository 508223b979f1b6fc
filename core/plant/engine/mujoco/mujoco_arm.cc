#include "core/plant/engine/mujoco/mujoco_arm.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <stdexcept>

#ifdef ARMFAULT_HAVE_MUJOCO
#include <dlfcn.h>
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

namespace {

// MuJoCo's functions, from the library opened at the first use (dlopen): the binary does not
// need libmujoco to start, so an armfault built with it runs where it is not installed (the
// container image) and only the bench's MuJoCo line says it could not load it.
struct MujocoApi {
  std::string problem;  // empty when loaded
  void (*defaultVFS)(mjVFS*) = nullptr;
  int (*makeEmptyFileVFS)(mjVFS*, const char*, int) = nullptr;
  int (*findFileVFS)(const mjVFS*, const char*) = nullptr;
  void (*deleteVFS)(mjVFS*) = nullptr;
  mjModel* (*loadXML)(const char*, const mjVFS*, char*, int) = nullptr;
  mjData* (*makeData)(const mjModel*) = nullptr;
  void (*deleteData)(mjData*) = nullptr;
  void (*deleteModel)(mjModel*) = nullptr;
  void (*resetData)(const mjModel*, mjData*) = nullptr;
  void (*step)(const mjModel*, mjData*) = nullptr;
  void (*forward)(const mjModel*, mjData*) = nullptr;
  void (*fullM)(const mjModel*, mjtNum*, const mjtNum*) = nullptr;
  const char* (*versionString)() = nullptr;
};

template <typename F>
void Bind(void* library, const char* name, F* f, std::string* problem) {
  *f = reinterpret_cast<F>(dlsym(library, name));
  if (!*f && problem->empty()) *problem = std::string("MuJoCo: ") + ARMFAULT_MUJOCO_LIBRARY + " lacks " + name;
}

const MujocoApi& Api() {
  static const MujocoApi api = [] {
    MujocoApi a;
    void* library = dlopen(ARMFAULT_MUJOCO_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!library) {
      const char* why = dlerror();
      a.problem = std::string("MuJoCo could not be loaded (") + (why ? why : ARMFAULT_MUJOCO_LIBRARY) + ")";
      return a;
    }
    Bind(library, "mj_defaultVFS", &a.defaultVFS, &a.problem);
    Bind(library, "mj_makeEmptyFileVFS", &a.makeEmptyFileVFS, &a.problem);
    Bind(library, "mj_findFileVFS", &a.findFileVFS, &a.problem);
    Bind(library, "mj_deleteVFS", &a.deleteVFS, &a.problem);
    Bind(library, "mj_loadXML", &a.loadXML, &a.problem);
    Bind(library, "mj_makeData", &a.makeData, &a.problem);
    Bind(library, "mj_deleteData", &a.deleteData, &a.problem);
    Bind(library, "mj_deleteModel", &a.deleteModel, &a.problem);
    Bind(library, "mj_resetData", &a.resetData, &a.problem);
    Bind(library, "mj_step", &a.step, &a.problem);
    Bind(library, "mj_forward", &a.forward, &a.problem);
    Bind(library, "mj_fullM", &a.fullM, &a.problem);
    Bind(library, "mj_versionString", &a.versionString, &a.problem);
    return a;  // the library stays open for the process
  }();
  return api;
}

}  // namespace

bool MujocoBuiltIn() { return Api().problem.empty(); }

std::string MujocoVersion() { return MujocoBuiltIn() ? Api().versionString() : ""; }

std::string MujocoProblem() { return Api().problem; }

struct MujocoArm::Loaded {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  ~Loaded() {
    if (data) Api().deleteData(data);
    if (model) Api().deleteModel(model);
  }
};

MujocoArm::MujocoArm(const JointSpaceModel& chain, double dt_s, const std::vector<double>& friction_loss_Nm)
    : loaded_(std::make_unique<Loaded>()) {
  const MujocoApi& mj = Api();
  if (!mj.problem.empty()) throw std::runtime_error(mj.problem);
  const std::string xml = MujocoArmXml(chain, dt_s, friction_loss_Nm);
  const auto vfs = std::make_unique<mjVFS>();  // MuJoCo's file table is large: on the heap
  mj.defaultVFS(vfs.get());
  const char* name = "arm.xml";
  if (mj.makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("MuJoCo: could not make its virtual file");
  }
  std::memcpy(vfs->filedata[mj.findFileVFS(vfs.get(), name)], xml.data(), xml.size());
  char error[1000] = "";
  loaded_->model = mj.loadXML(name, vfs.get(), error, sizeof error);
  mj.deleteVFS(vfs.get());
  if (!loaded_->model) throw std::runtime_error(std::string("MuJoCo refused the arm's model: ") + error);
  loaded_->data = mj.makeData(loaded_->model);
  if (!loaded_->data) throw std::runtime_error("MuJoCo: could not allocate its data");
}

MujocoArm::~MujocoArm() = default;

double MujocoArm::StepFromRest(long steps) {
  mjModel* m = loaded_->model;
  mjData* d = loaded_->data;
  Api().resetData(m, d);
  for (long s = 0; s < steps; ++s) Api().step(m, d);
  double checksum = 0;
  for (int j = 0; j < m->nq; ++j) checksum += d->qpos[j];
  return checksum;
}

void MujocoArm::MassAndBias(const double* q, const double* qd, std::vector<double>* M, std::vector<double>* bias_Nm) {
  mjModel* m = loaded_->model;
  mjData* d = loaded_->data;
  Api().resetData(m, d);
  const int n = m->nv;
  for (int j = 0; j < n; ++j) {
    d->qpos[j] = q[j];
    d->qvel[j] = qd[j];
  }
  Api().forward(m, d);
  M->assign(static_cast<size_t>(n) * n, 0.0);
  Api().fullM(m, M->data(), d->qM);
  bias_Nm->assign(d->qfrc_bias, d->qfrc_bias + n);
}

#else

bool MujocoBuiltIn() { return false; }
std::string MujocoVersion() { return ""; }
std::string MujocoProblem() { return "not built in (libmujoco-dev was not found when armfault was configured)"; }

struct MujocoArm::Loaded {};

MujocoArm::MujocoArm(const JointSpaceModel&, double, const std::vector<double>&) {
  throw std::runtime_error("MuJoCo is " + MujocoProblem());
}
MujocoArm::~MujocoArm() = default;
double MujocoArm::StepFromRest(long) { return 0; }
void MujocoArm::MassAndBias(const double*, const double*, std::vector<double>*, std::vector<double>*) {}

#endif

}  // namespace armfault
