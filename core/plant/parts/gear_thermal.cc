#include "core/plant/parts/gear_thermal.h"

#include <cmath>

namespace armfault {

double LubricantFactor(const GearboxParams& p, double temperature_C) {
  if (p.vogel_B_K == 0) return 1.0;
  return std::exp(p.vogel_B_K / (temperature_C - p.vogel_C_C) - p.vogel_B_K / (p.reference_C - p.vogel_C_C));
}

void StepThermalNodes(double winding_R_K_per_W, double winding_tau_s, const GearboxParams& p, double ambient_C,
                      double p_copper_W, double p_friction_W, double dt_s, ThermalNodes* nodes) {
  const double to_gear_W = p.winding_coupling_W_per_K * (nodes->winding_C - nodes->gear_C);
  // tau dT/dt = T_amb + R (P_in) - T: the same form as the winding's node without the gearbox.
  nodes->winding_C += dt_s / winding_tau_s * (ambient_C + winding_R_K_per_W * (p_copper_W - to_gear_W) - nodes->winding_C);
  nodes->gear_C += dt_s / p.thermal_time_constant_s *
                   (ambient_C + p.thermal_resistance_K_per_W * (p_friction_W + to_gear_W) - nodes->gear_C);
}

ThermalNodes SteadyThermalNodes(double winding_R_K_per_W, const GearboxParams& p, double ambient_C,
                                double p_copper_W, double p_friction_W) {
  const double g = p.winding_coupling_W_per_K;
  const double rg = p.thermal_resistance_K_per_W;
  ThermalNodes out;
  if (winding_R_K_per_W == 0) {  // the winding is pinned at ambient
    out.winding_C = ambient_C;
    out.gear_C = ambient_C + p_friction_W / (1.0 / rg + g);
    return out;
  }
  // [1/R_w + G, -G; -G, 1/R_g + G] [x; y] = [P_c; P_f]
  const double a = 1.0 / winding_R_K_per_W + g, d = 1.0 / rg + g;
  const double det = a * d - g * g;
  out.winding_C = ambient_C + (d * p_copper_W + g * p_friction_W) / det;
  out.gear_C = ambient_C + (g * p_copper_W + a * p_friction_W) / det;
  return out;
}

ThermalNodes WarmSteadyState(double winding_R_K_per_W, const GearboxParams& p, double ambient_C) {
  if (!p.present) return ThermalNodes{ambient_C, ambient_C};
  return SteadyThermalNodes(winding_R_K_per_W, p, ambient_C, p.warm_copper_loss_W, p.warm_friction_loss_W);
}

double DriftedSensorInputNm(const GearboxParams& p, double gear_C, double gain_error, double offset_error_Nm,
                            double tau_Nm) {
  const double dT = gear_C - p.reference_C;
  return (1.0 + gain_error + p.sensor_gain_per_K * dT) * tau_Nm + offset_error_Nm + p.sensor_offset_Nm_per_K * dT;
}

}  // namespace armfault
