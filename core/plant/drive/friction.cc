#include "core/plant/drive/friction.h"

#include <cmath>

namespace armfault {

double BreakawayFrictionNm(const FrictionParams& p, double factor, double qd) {
  return factor * (p.coulomb_Nm + p.static_Nm * std::exp(-p.stribeck_s2_per_rad2 * qd * qd));
}

double ViscousFrictionNm(const FrictionParams& p, double factor, double qd) {
  return factor * p.viscous_Nm_s_per_rad * qd;
}

double FrictionTorqueNm(const FrictionParams& p, double factor, double qd) {
  double sat = qd > 0 ? 1.0 : (qd < 0 ? -1.0 : 0.0);
  return ViscousFrictionNm(p, factor, qd) + BreakawayFrictionNm(p, factor, qd) * sat;
}

}  // namespace armfault
