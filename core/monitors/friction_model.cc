#include "core/monitors/friction_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/monitors/monitor_config.h"

namespace armfault {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A 2 x 2 symmetric solve: (a00 a01; a01 a11) x = b. False when singular.
bool Solve2(const std::array<double, 3>& a, const std::array<double, 2>& b, std::array<double, 2>* x,
            std::array<double, 3>* inverse) {
  const double det = a[0] * a[2] - a[1] * a[1];
  if (!(det > 0)) return false;
  (*inverse)[0] = a[2] / det;
  (*inverse)[1] = -a[1] / det;
  (*inverse)[2] = a[0] / det;
  (*x)[0] = (*inverse)[0] * b[0] + (*inverse)[1] * b[1];
  (*x)[1] = (*inverse)[1] * b[0] + (*inverse)[2] * b[1];
  return true;
}

// θ into 0 <= β_d <= β_v <= max.
std::array<double, 2> Project(std::array<double, 2> t, double max_slope) {
  t[0] = std::clamp(t[0], 0.0, max_slope);
  t[1] = std::clamp(t[1], 0.0, t[0]);
  return t;
}

// The winding's reading of joint j as a temperature over its commissioning, and its variance;
// false when it has not been read.
bool WindingReading(const MonitorConfig& c, const ArmJoint& joint, double winding_above_K, double* k, double* var) {
  if (std::isfinite(winding_above_K)) {
    *k = winding_above_K;
    *var = 1.0;  // a declared sensor: about 1 K
    return true;
  }
  // Until it converges, the averaged reading leans to the fit's first moments, which sit near
  // its prior (1) whatever the winding's temperature (a cold start at 1 degC read 0 K on a
  // winding 20 K cold when settled at 2 s), and its standard error does not say so: no
  // reading yet.
  const ElectricalEstimator& e = *joint.electrical;
  if (!(e.winding.judged_s >= c.winding_reading_converged_s)) return false;
  *k = (e.winding.reading - 1.0) / c.copper_resistance_per_K;
  *var = c.winding_reading_error_K * c.winding_reading_error_K;
  return true;
}

}  // namespace

double ViscousShare(double viscous_Nm, double coulomb_Nm, double stribeck_Nm) {
  const double v = std::fabs(viscous_Nm);
  const double total = v + std::fabs(coulomb_Nm) + std::fabs(stribeck_Nm);
  return total > 0 ? v / total : 0.0;
}

ArmFrictionModel::ArmFrictionModel(const MonitorConfig& c, int joints)
    : joint(static_cast<size_t>(joints)),
      gear(static_cast<size_t>(joints)),
      sums_(static_cast<size_t>(joints)),
      blocks_seen_(static_cast<size_t>(joints), 0),
      share_(static_cast<size_t>(joints), 0.5) {
  slopes = {0.5 * c.max_lubricant_slope_per_K, 0.5 * c.max_lubricant_slope_per_K};
}

void ArmFrictionModel::Update(const MonitorConfig& c, const std::vector<ArmJoint>& joints,
                              const std::vector<double>& winding_above_K, double elapsed_s, double dt_s) {
  const size_t n = joints.size();
  // 1. The windings' converged readings, and the arm's: their median.
  std::array<double, 64> reading_K{}, reading_var{}, settled{};
  std::array<bool, 64> has{};
  size_t n_settled = 0;
  for (size_t j = 0; j < n && j < 64; ++j) {
    has[j] = WindingReading(c, joints[j], winding_above_K[j], &reading_K[j], &reading_var[j]);
    if (has[j]) settled[n_settled++] = reading_K[j];
  }
  double arm_K = 0, arm_var = c.unread_temperature_sd_K * c.unread_temperature_sd_K;
  if (n_settled > 0) {
    std::sort(settled.begin(), settled.begin() + n_settled);
    arm_K = n_settled % 2 ? settled[n_settled / 2] : 0.5 * (settled[n_settled / 2 - 1] + settled[n_settled / 2]);
    const double spread = c.arm_temperature_spread_K;
    arm_var = spread * spread + c.winding_reading_error_K * c.winding_reading_error_K / static_cast<double>(n_settled);
  }
  // 2. Each gear's temperature: the start, combined by precision, then the lagged rise.
  const bool starting = elapsed_s < c.start_reading_s;
  for (size_t j = 0; j < n && j < 64; ++j) {
    GearTemperature& g = gear[j];
    double w = arm_K, w_var = arm_var;
    if (has[j]) {
      const double p = 1.0 / reading_var[j] + 1.0 / arm_var;
      w = (reading_K[j] / reading_var[j] + arm_K / arm_var) / p;
      w_var = 1.0 / p;
    }
    if (starting || !g.read) {
      g.start_K = w;
      g.start_var_K2 = w_var;
      g.lag_K = 0;
      g.read = has[j] || n_settled > 0;
    } else {
      g.lag_K += std::min(1.0, dt_s / c.gear_time_constant_s) * ((w - g.start_K) - g.lag_K);
    }
    g.gear_K = g.start_K + g.lag_K;
    // A converged reading's own error is the arm's too (every winding is read the same way) and
    // cancels through the slopes learned at those readings: counted is what an
    // unread start adds beyond it, and the gear's gap to its winding.
    const double err2 = c.winding_reading_error_K * c.winding_reading_error_K;
    const double gap = c.gear_winding_gap_sd * g.gear_K;
    g.gear_var_K2 = std::max(0.0, g.start_var_K2 - err2) + gap * gap;
  }
  // 3. The blocks completed since the last tick into each joint's sums; all forget.
  const double forget = std::exp(-dt_s / c.lubricant_forget_s);
  const double joint_var = c.friction_model_error * c.friction_model_error;
  const double block_var = c.friction_block_scatter * c.friction_block_scatter;
  for (size_t j = 0; j < n && j < 64; ++j) {
    Sums& m = sums_[j];
    m.w *= forget;
    m.wy *= forget;
    for (double& v : m.wx) v *= forget;
    for (double& v : m.wxx) v *= forget;
    for (double& v : m.wxy) v *= forget;
    const FrictionReference& f = *joints[j].friction;
    if (f.blocks == blocks_seen_[j]) continue;
    blocks_seen_[j] = f.blocks;
    share_[j] = f.last_block_share;
    if (f.blocks <= c.unconverged_friction_blocks || !f.last_block_teaches || !(f.last_block_median > 0)) continue;
    const double y = std::log(f.last_block_median);
    const double v = f.last_block_share;
    const double slope = v * slopes[0] + (1.0 - v) * slopes[1];
    const double w =
        1.0 / (f.last_block_log_se * f.last_block_log_se + block_var + slope * slope * gear[j].gear_var_K2);
    const double x0 = -gear[j].gear_K * v, x1 = -gear[j].gear_K * (1.0 - v);
    m.w += w;
    m.wy += w * y;
    m.wx[0] += w * x0;
    m.wx[1] += w * x1;
    m.wxx[0] += w * x0 * x0;
    m.wxx[1] += w * x0 * x1;
    m.wxx[2] += w * x1 * x1;
    m.wxy[0] += w * x0 * y;
    m.wxy[1] += w * x1 * y;
  }
  // 4. Each joint's information on θ, its blocks sharing its u_j (GLS with V = W⁻¹ + σ_u² 1 1').
  std::array<Information, 64> info;
  Information total;
  for (size_t j = 0; j < n && j < 64; ++j) {
    const Sums& m = sums_[j];
    const double shrink = joint_var / (1.0 + joint_var * m.w);
    Information& in = info[j];
    in.a[0] = m.wxx[0] - shrink * m.wx[0] * m.wx[0];
    in.a[1] = m.wxx[1] - shrink * m.wx[0] * m.wx[1];
    in.a[2] = m.wxx[2] - shrink * m.wx[1] * m.wx[1];
    in.b[0] = m.wxy[0] - shrink * m.wx[0] * m.wy;
    in.b[1] = m.wxy[1] - shrink * m.wx[1] * m.wy;
    for (int k = 0; k < 3; ++k) total.a[k] += in.a[k];
    for (int k = 0; k < 2; ++k) total.b[k] += in.b[k];
  }
  // 5. Each joint's reference from the others' information; the arm's slopes from all.
  const double prior_sd = c.lubricant_slope_prior_sd_per_K;
  const double prior_w = 1.0 / (prior_sd * prior_sd);
  const double prior_mean = 0.5 * c.max_lubricant_slope_per_K;
  auto fit = [&](const Information& data, std::array<double, 2>* theta, std::array<double, 3>* cov) {
    const std::array<double, 3> a = {prior_w + data.a[0], data.a[1], prior_w + data.a[2]};
    const std::array<double, 2> b = {prior_w * prior_mean + data.b[0], prior_w * prior_mean + data.b[1]};
    if (!Solve2(a, b, theta, cov)) {
      *theta = {prior_mean, prior_mean};
      *cov = {prior_sd * prior_sd, 0, prior_sd * prior_sd};
    }
    *theta = Project(*theta, c.max_lubricant_slope_per_K);
  };
  std::array<double, 3> cov{};
  fit(total, &slopes, &cov);
  for (size_t j = 0; j < n && j < 64; ++j) {
    Information others;
    for (int k = 0; k < 3; ++k) others.a[k] = total.a[k] - info[j].a[k];
    for (int k = 0; k < 2; ++k) others.b[k] = total.b[k] - info[j].b[k];
    std::array<double, 2> theta{};
    fit(others, &theta, &cov);
    const double v = share_[j];
    const double x0 = -gear[j].gear_K * v, x1 = -gear[j].gear_K * (1.0 - v);
    const double slope = v * theta[0] + (1.0 - v) * theta[1];
    const double log_r = x0 * theta[0] + x1 * theta[1];
    const double var = x0 * x0 * cov[0] + 2.0 * x0 * x1 * cov[1] + x1 * x1 * cov[2] + joint_var +
                       slope * slope * gear[j].gear_var_K2;
    joint[j].reference = std::exp(log_r);
    joint[j].log_sd = std::sqrt(std::max(0.0, var));
    if (!std::isfinite(joint[j].reference)) joint[j].reference = kInf;
  }
}

}  // namespace armfault
