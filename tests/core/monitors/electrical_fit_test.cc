// The electrical balance as the monitor fits it: it recovers the K_T and resistance factors of
// a unit from its supply power, a magnet strengthens only as far as a cold winding allows, and
// the winding's reading follows the fit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/monitors/electrical_fit.h"
#include "core/monitors/monitor_config.h"

namespace armfault {
namespace {

constexpr double kDt = 0.002;

// Feeds `seconds` of a motion whose rotor power and copper loss are not collinear.
void Feed(ElectricalFit* fit, double n, double rho, double seconds) {
  for (int i = 0; i < static_cast<int>(seconds / kDt); ++i) {
    const double t = i * kDt;
    const double p_rotor = 60.0 * std::sin(2.0 * t);
    const double p_copper = 8.0 + 6.0 * std::cos(3.1 * t);
    fit->Add(n * p_rotor + rho * p_copper, p_rotor, p_copper);
  }
}

TEST(ElectricalFit, RecoversTheKtAndResistanceFactorsOfTheSupplyPower) {
  const MonitorConfig c;
  ElectricalFit fit(c, c.electrical_time_constant_s, kDt, c.constant_power_uncertainty_W);
  Feed(&fit, 0.85, 1.2, 10);
  EXPECT_NEAR(fit.n, 0.85, 2e-3);
  EXPECT_NEAR(fit.rho, 1.2, 5e-3);
  EXPECT_NEAR(fit.constant_W, 0.0, 0.05);
}

TEST(ElectricalFit, AMagnetStrengthensOnlyAsFarAsAColdWindingAllows) {
  const MonitorConfig c;
  const double s = c.max_magnet_kt_loss_per_K / c.copper_resistance_per_K;  // 0.305
  // More rotor power than K_T gives with a warm winding (rho 1.1): no magnet explains it, and
  // the fit stays on the bound n <= 1 + s max(0, 1 - rho) (the better of its two pieces).
  ElectricalFit warm(c, c.electrical_time_constant_s, kDt, c.constant_power_uncertainty_W);
  Feed(&warm, 1.05, 1.1, 10);
  EXPECT_LT(warm.n, 1.05);
  EXPECT_LE(warm.n, 1.0 + s * std::max(0.0, 1.0 - warm.rho) + 1e-12);
  // A winding 25 K cold (rho 0.90): a magnet that cold may give up to 1 + s 0.10.
  ElectricalFit cold(c, c.electrical_time_constant_s, kDt, c.constant_power_uncertainty_W);
  Feed(&cold, 1.0 + s * 0.10, 0.90, 10);
  EXPECT_NEAR(cold.n, 1.0 + s * 0.10, 2e-3);
  EXPECT_NEAR(cold.rho, 0.90, 5e-3);
  EXPECT_LE(cold.n, 1.0 + s * (1.0 - cold.rho) + 1e-12);
}

TEST(ElectricalFit, TheWindingReadingFollowsTheFitFirstThenSlowly) {
  MonitorConfig c;
  WindingThermometer w;
  for (int i = 0; i < static_cast<int>(c.winding_thermometer_time_constant_s / kDt); ++i) w.Update(c, 1.08, kDt);
  EXPECT_DOUBLE_EQ(w.rho, 1.08);  // the fit's own while it converges
  EXPECT_NEAR(w.reading, 1.08, 1e-9);
  // Then a jump of the fit (an abrupt K_T loss lifts it for seconds) moves the slow reading little.
  for (int i = 0; i < static_cast<int>(3.0 / kDt); ++i) w.Update(c, 1.20, kDt);
  EXPECT_NEAR(w.rho, 1.08 + 0.12 * (1 - std::exp(-3.0 / 60.0)), 2e-4);
  EXPECT_GT(w.reading, 1.08 + 0.12 * 0.2);  // the averaged reading (10 s) moves further
}

}  // namespace
}  // namespace armfault
