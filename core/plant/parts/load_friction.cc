#include "core/plant/parts/load_friction.h"

#include <cmath>

namespace armfault {

PowerFlow PowerFlowOf(double tau_Nm, double qd_rad_s) {
  return tau_Nm * qd_rad_s < 0 ? PowerFlow::kBackDriven : PowerFlow::kDriving;
}

double LoadFrictionNm(const GearboxParams& p, double tau_Nm, double qd_rad_s, double ratio) {
  if (!p.present) return 0.0;
  const double mu =
      PowerFlowOf(tau_Nm, qd_rad_s) == PowerFlow::kDriving ? p.load_friction_driving : p.load_friction_backdriven;
  return mu * std::fabs(tau_Nm) / ratio;
}

}  // namespace armfault
