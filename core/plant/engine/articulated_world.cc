#include "core/plant/engine/articulated_world.h"

#include <algorithm>
#include <cmath>

#include "core/plant/robot/robot_config.h"

namespace armfault {

static_assert(kMaxArticulatedJoints == kMaxEngineJoints, "the robot's check and the engine's storage agree");

namespace {


enum class Row { kFree, kLower, kUpper, kFixed };

// Cholesky factor L (lower, row-major n × n in `L`) of the symmetric positive definite `a`
// (row-major n × n, stride kMaxEngineJoints), n ≤ 7: plain loops, no heap, no dispatch (Eigen's
// dynamic-size LLT costs more than the arithmetic at this size).
void Cholesky(const double* a, int n, double* L) {
  constexpr int s = kMaxEngineJoints;
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k <= i; ++k) {
      double sum = a[i * s + k];
      for (int m = 0; m < k; ++m) sum -= L[i * s + m] * L[k * s + m];
      L[i * s + k] = i == k ? std::sqrt(sum) : sum / L[k * s + k];
    }
  }
}

// Solves L L' x = b in place.
void CholeskySolve(const double* L, int n, double* x) {
  constexpr int s = kMaxEngineJoints;
  for (int i = 0; i < n; ++i) {
    double sum = x[i];
    for (int m = 0; m < i; ++m) sum -= L[i * s + m] * x[m];
    x[i] = sum / L[i * s + i];
  }
  for (int i = n; i-- > 0;) {
    double sum = x[i];
    for (int m = i + 1; m < n; ++m) sum -= L[m * s + i] * x[m];
    x[i] = sum / L[i * s + i];
  }
}

}  // namespace

ArticulatedModel MakeArticulatedModel(const RigidBodyModel& bodies, double constraint_force_mixing) {
  ArticulatedModel m;
  m.chain = MakeJointSpaceModel(bodies);
  m.bodies = bodies;
  m.constraint_force_mixing = constraint_force_mixing;
  return m;
}

// Primal active set: from λ = 0 (feasible), solve the free rows with the others at their
// bounds; a step that leaves the box stops at the first bound met and fixes that row there;
// at the working set's optimum, the bound row whose gradient most wants it inside is freed.
// Each release lowers the objective strictly, so no working set repeats: it ends after finitely
// many iterations (at most a few n here). The cap guards against rounding only.
int SolveBoxLcp(const JointMatrix& A, const double* c, const double* bound, double* lambda) {
  const int n = static_cast<int>(A.rows());
  Row row[kMaxEngineJoints];
  for (int i = 0; i < n; ++i) {
    lambda[i] = 0;
    row[i] = bound[i] > 0 ? Row::kFree : Row::kFixed;
  }
  const int cap = 8 * n + 8;
  int it = 0;
  for (; it < cap; ++it) {
    int free_index[kMaxEngineJoints];
    int nf = 0;
    for (int i = 0; i < n; ++i) {
      if (row[i] == Row::kFree) free_index[nf++] = i;
    }
    if (nf > 0) {
      // A_FF y = −c_F − A_FB λ_B.
      double Aff[kMaxEngineJoints * kMaxEngineJoints], L[kMaxEngineJoints * kMaxEngineJoints];
      double y[kMaxEngineJoints];
      for (int a = 0; a < nf; ++a) {
        const int i = free_index[a];
        double r = -c[i];
        for (int j = 0; j < n; ++j) {
          if (row[j] != Row::kFree) r -= A(i, j) * lambda[j];
        }
        y[a] = r;
        for (int b = 0; b < nf; ++b) Aff[a * kMaxEngineJoints + b] = A(i, free_index[b]);
      }
      Cholesky(Aff, nf, L);
      CholeskySolve(L, nf, y);
      double alpha = 1;
      int block = -1;
      for (int a = 0; a < nf; ++a) {
        const int i = free_index[a];
        const double d = y[a] - lambda[i];
        if (y[a] > bound[i] && d > 0) {
          const double s = (bound[i] - lambda[i]) / d;
          if (s < alpha) alpha = s, block = a;
        } else if (y[a] < -bound[i] && d < 0) {
          const double s = (-bound[i] - lambda[i]) / d;
          if (s < alpha) alpha = s, block = a;
        }
      }
      for (int a = 0; a < nf; ++a) {
        const int i = free_index[a];
        lambda[i] = block < 0 ? y[a] : lambda[i] + alpha * (y[a] - lambda[i]);
      }
      if (block >= 0) {
        const int i = free_index[block];
        row[i] = y[block] > bound[i] ? Row::kUpper : Row::kLower;
        lambda[i] = row[i] == Row::kUpper ? bound[i] : -bound[i];
        continue;
      }
    }
    // Optimal for this working set: does a bound row want in? Its gradient g = (Aλ + c)_i.
    int release = -1;
    double worst = 0;
    for (int i = 0; i < n; ++i) {
      if (row[i] != Row::kLower && row[i] != Row::kUpper) continue;
      double g = c[i], scale = std::fabs(c[i]);
      for (int j = 0; j < n; ++j) {
        g += A(i, j) * lambda[j];
        scale += std::fabs(A(i, j) * lambda[j]);
      }
      // At the lower bound a negative gradient, at the upper a positive one, asks to move in.
      const double want = row[i] == Row::kLower ? -g : g;
      if (want > 1e-13 * scale && want > worst) worst = want, release = i;
    }
    if (release < 0) break;
    row[release] = Row::kFree;
  }
  return it;
}

ArticulatedWorld::ArticulatedWorld(const ArticulatedModel& model, const std::vector<double>& q0,
                                   const std::vector<double>& qd0)
    : model_(model), n_(model.chain.joint_count) {
  for (int j = 0; j < n_; ++j) {
    q_[j] = q0[j];
    qd_[j] = qd0[j];
  }
}

void ArticulatedWorld::SetJoint(int j, double couple_Nm, double dry_bound_Nm) {
  couple_Nm_[j] = couple_Nm;
  bound_Nm_[j] = dry_bound_Nm;
}

void ArticulatedWorld::Step(double dt_s) {
  constexpr int s = kMaxEngineJoints;
  const int n = n_;
  JointMatrix M, S;
  double b[kMaxEngineJoints], tau0[kMaxEngineJoints];
  MassMatrixBiasAndSensor(model_.chain, q_, qd_, &M, b, &S, tau0);
  // M⁻¹ column by column from its Cholesky factor (row-major, symmetric).
  double m[s * s] = {}, L[s * s], Minv[s * s];  // m zeroed: the compiler cannot see n ≤ 7
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) m[i * s + k] = M(i, k);
  }
  Cholesky(m, n, L);
  for (int k = 0; k < n; ++k) {
    double e[s] = {};
    e[k] = 1;
    CholeskySolve(L, n, e);
    for (int i = 0; i < n; ++i) Minv[i * s + k] = e[i];
  }
  double gamma[s], f[s], a_free[s];
  for (int j = 0; j < n; ++j) {
    gamma[j] = model_.chain.joints[j].ratio;
    f[j] = gamma[j] * couple_Nm_[j] - b[j];
  }
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += Minv[i * s + k] * f[k];
    a_free[i] = sum;
  }
  // The friction rows: A = dt Γ M⁻¹ Γ + ε E, c = Γ (q̇ + dt a_free).
  JointMatrix A(n, n);
  double c[s] = {};
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) A(i, k) = dt_s * gamma[i] * gamma[k] * Minv[i * s + k];
    A(i, i) += model_.constraint_force_mixing;
    c[i] = gamma[i] * (qd_[i] + dt_s * a_free[i]);
  }
  SolveBoxLcp(A, c, bound_Nm_, lambda_Nm_);
  double gl[s], qdd[s];
  for (int j = 0; j < n; ++j) gl[j] = gamma[j] * lambda_Nm_[j];
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += Minv[i * s + k] * gl[k];
    qdd[i] = a_free[i] + sum;
  }
  // The sensor's truth over the step: from the start state with the step's acceleration.
  for (int i = 0; i < n; ++i) {
    double sum = tau0[i];
    for (int k = 0; k < n; ++k) sum += S(i, k) * qdd[k];
    tau_Nm_[i] = sum;
  }
  for (int j = 0; j < n; ++j) {
    qd_[j] += dt_s * qdd[j];
    q_[j] += dt_s * qd_[j];
  }
}

JointReadout ArticulatedWorld::Joint(int j) const {
  JointReadout r;
  r.q_rad = q_[j];
  r.qd_rad_s = qd_[j];
  r.rotor_rate_rad_s = model_.chain.joints[j].ratio * qd_[j];
  r.tau_transmitted_Nm = tau_Nm_[j];
  r.dry_torque_Nm = lambda_Nm_[j];
  return r;
}

double ArticulatedWorld::KineticEnergy_J() const {
  JointMatrix M;
  MassMatrix(model_.chain, q_, &M);
  double e = 0;
  for (int i = 0; i < n_; ++i) {
    for (int k = 0; k < n_; ++k) e += 0.5 * qd_[i] * M(i, k) * qd_[k];
  }
  return e;
}

// The links' and the rotors' token masses at the current pose: X_i = X_{i-1} ∘ (rotation about
// joint i), the zero pose's world axes (as ODE's bodies are placed).
double ArticulatedWorld::PotentialEnergy_J() const {
  const RigidBodyModel& m = model_.bodies;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double e = 0;
  for (int i = 0; i < n_; ++i) {
    const RigidJoint& j = m.joints[i];
    const Eigen::Matrix3d Rq = Eigen::AngleAxisd(q_[i], j.axis).toRotationMatrix();
    t = R * (j.anchor_m - Rq * j.anchor_m) + t;
    R = R * Rq;
    const Eigen::Vector3d com = R * j.com_m + t, centre = R * j.rotor_centre_m + t;
    e -= j.mass_kg * m.gravity_m_s2.dot(com) + j.rotor_mass_kg * m.gravity_m_s2.dot(centre);
  }
  return e;
}

}  // namespace armfault
