// The arm's friction model: what a healthy gear's friction is at its present temperature, as one
// estimator for the whole arm with its own uncertainty (docs/monitor.md, "The arm's friction
// model"). Selected by `"friction_reference": "arm_model"`; the default "rules" is
// friction_reference.h.
//
// Per joint j, a thermal state: the gear's temperature against its commissioning, G_j [K], read
// from the winding (WindingThermometer, or a declared winding sensor) and from the arm:
//   W_j        the winding's converged reading, (ρ − 1) / α_Cu, with its error σ_r (none before
//              it converges: the averaged reading leans to the fit's first moments, at its prior)
//   μ_arm      the median of the joints' readings (the arm's temperature)
//   S_j        the start temperature: W_j and μ_arm combined by precision, μ_arm counted with
//              the arm's spread τ_arm (arm_temperature_spread_K); followed until the run is
//              start_reading_s old, then held
//   G_j(t)     = S_j + L[W_j − S_j], L a first-order lag of gear_time_constant_s (the gear warms
//              more slowly than its winding)
//   σ_G,j²     = max(0, σ_S,j² − σ_r²) + (gear_winding_gap_sd · G_j)², σ_r the converged reading's
//              error (winding_reading_error_K): every winding is read alike, so that error is the
//              arm's and cancels through the slopes learned at the same readings; counted is what
//              an unread start adds (the arm's reading in its place), and the gear's gap to its winding
// Friction: the fast fit's factor κ (against the commissioned curve), in blocks of 1 s of
// motion (FrictionReference's blocks), as y = ln κ; a block teaches only once the joint's
// sensor zero is found (before, the fit reads the smaller of two hypotheses, low). A lubricant
// thins when warm; its viscous part follows it more than the dry part, so with v the block's
// viscous share of the curve,
//   y_jk = −G_jk (v_jk β_v + (1 − v_jk) β_d) + u_j + e_jk
//   u_j ~ N(0, σ_u²)   the joint's own departure from its arm's law (its dry share, its gear's
//                      temperature, its commissioning): friction_model_error, one per joint
//   e_jk ~ N(0, σ_k²)  σ_k² = σ_κ,jk² + σ_b² + β̄² σ_G,jk² (the fit's error, the block scatter
//                      friction_block_scatter, the temperature's)
// with θ = (β_v, β_d) one lubricant's slopes for the whole arm, inside
// 0 ≤ β_d ≤ β_v ≤ max_lubricant_slope_per_K (catalogues), prior θ_0 = half of that each, sd
// lubricant_slope_prior_sd_per_K; β̄ the arm's present slope. A joint's blocks share its u_j,
// so a joint teaches θ at most as well as σ_u allows, however many blocks it shows (GLS with
// V_j = W⁻¹ + σ_u² 1 1'):
//   A_j = X'WX − σ_u² (X'W1)(1'WX) / (1 + σ_u² 1'W1),   b_j likewise with y,
// from forgetting sums (lubricant_forget_s) of w, w x, w x x', w x y, w y, x = −G [v, 1 − v].
// Joint j's reference leaves its own blocks out, so its wear never enters its own reference:
//   θ_−j = (A_0 + Σ_{i≠j} A_i)⁻¹ (A_0 θ_0 + Σ_{i≠j} b_i), projected into the bounds,
//   Σ_−j = (A_0 + Σ_{i≠j} A_i)⁻¹,
//   ln r_j = x_j' θ_−j,  x_j = −G_j [v_j, 1 − v_j] (v_j its latest block's share),
//   var ln r_j = x_j' Σ_−j x_j + σ_u² + (v_j β_v + (1 − v_j) β_d)² σ_G,j².
// A lone joint learns nothing from its arm: its reference is the prior's, with the prior's
// uncertainty.
//
// Inputs: every joint's FrictionReference (its blocks) and ElectricalEstimator (its winding),
// once per tick, from the state after the last tick, so the joints' update order changes nothing.
// Outputs per joint: `reference` (r_j) and `log_sd` (√var ln r_j). Units: K, 1/K, s.
#pragma once

#include <array>
#include <vector>

#include "core/monitors/friction_reference.h"

namespace armfault {

struct MonitorConfig;

// One joint's gear temperature as the model reads it.
struct GearTemperature {
  double start_K = 0;       // S_j
  double start_var_K2 = 0;  // σ_S,j²
  double lag_K = 0;         // L[W_j − S_j]
  double gear_K = 0;        // G_j
  double gear_var_K2 = 0;   // σ_G,j²
  bool read = false;        // a reading (own or the arm's) has been taken
};

struct ArmFrictionModel {
  ArmFrictionModel(const MonitorConfig& c, int joints);
  // Once per tick for the whole arm: `winding_above_K[j]`, a declared winding sensor's reading
  // over the calibration's (NaN without); `elapsed_s`, time since the run's first tick.
  void Update(const MonitorConfig& c, const std::vector<ArmJoint>& joints, const std::vector<double>& winding_above_K,
              double elapsed_s, double dt_s);

  struct Reference {
    double reference = 1;  // r_j
    double log_sd = 0;     // √var ln r_j
  };
  std::vector<Reference> joint;
  std::vector<GearTemperature> gear;
  std::array<double, 2> slopes{};  // θ of the whole arm (diagnostic, and β̄)

 private:
  // One joint's forgetting sums of its blocks: w, w x, w x x' (00 01 11), w x y, w y.
  struct Sums {
    double w = 0;
    std::array<double, 2> wx{};
    std::array<double, 3> wxx{};
    std::array<double, 2> wxy{};
    double wy = 0;
  };
  struct Information {
    std::array<double, 3> a{};  // 00 01 11
    std::array<double, 2> b{};
  };
  std::vector<Sums> sums_;
  std::vector<int> blocks_seen_;
  std::vector<double> share_;  // the latest block's viscous share per joint
};

// The viscous share of a calibrated curve's friction at this tick's filtered terms: |c_v F[q̇]|
// over the sum of the three terms' magnitudes (0 when there is no friction to share).
double ViscousShare(double viscous_Nm, double coulomb_Nm, double stribeck_Nm);

}  // namespace armfault
