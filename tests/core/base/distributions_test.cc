// core/base/distributions.h: Boost.Math's standard normal against reference values computed
// independently (mpmath at 40 digits: sqrt(2) erfinv(2 p - 1) and ncdf of the same double
// argument), and its edges.
#include "core/base/distributions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace armfault {
namespace {

// Relative 1e-15: a few ulps (Boost documents its normal at about 1e-16 to 1e-15 relative; the
// references are of the double argument, 0.9 being 0.90000000000000002220).
void ExpectClose(double got, double want) { EXPECT_NEAR(got, want, 1e-15 * std::fabs(want)) << want; }

TEST(StandardNormalTest, QuantilesMatchHighPrecisionValues) {
  ExpectClose(StandardNormalQuantile(0.975), 1.959963984540053855604431);
  ExpectClose(StandardNormalQuantile(0.95), 1.644853626951472284276316);
  ExpectClose(StandardNormalQuantile(0.9), 1.281551565544600593487448);
  ExpectClose(StandardNormalQuantile(0.995), 2.575829303548900453857483);
  ExpectClose(StandardNormalQuantile(0.999), 3.090232306167813277758202);
  EXPECT_EQ(StandardNormalQuantile(0.5), 0.0);
  EXPECT_NEAR(StandardNormalQuantile(0.025), -StandardNormalQuantile(0.975), 1e-15);
  // Not a bisection's few-digit answer: Phi(quantile) gives the probability back.
  EXPECT_NEAR(StandardNormalCdf(StandardNormalQuantile(0.975)), 0.975, 2e-16);
}

TEST(StandardNormalTest, CdfAndUpperTailMatchHighPrecisionValues) {
  ExpectClose(StandardNormalCdf(0.3), 0.6179114221889526330722736);
  ExpectClose(StandardNormalCdf(-3), 0.001349898031630094526651815);
  EXPECT_EQ(StandardNormalCdf(0), 0.5);
  // The far tail keeps its relative accuracy (1 - Phi(10) would round to 0), to 2e-14: the
  // rounding of z / sqrt(2) inside erfc is amplified by about z^2 there.
  EXPECT_NEAR(StandardNormalUpperTail(10) / 7.619853024160526070429277e-24, 1.0, 2e-14);
  ExpectClose(StandardNormalUpperTail(3), 0.001349898031630094526651815);
  EXPECT_NEAR(StandardNormalUpperTail(1.2) + StandardNormalCdf(1.2), 1.0, 2.3e-16);
  // Round trip.
  for (double z : {-4.0, -1.5, 0.25, 2.0, 6.0}) EXPECT_NEAR(StandardNormalQuantile(StandardNormalCdf(z)), z, 1e-9 * (1 + z * z));
}

TEST(StandardNormalTest, ProbabilitiesOutsideTheOpenUnitIntervalThrow) {
  EXPECT_THROW(StandardNormalQuantile(1.5), std::domain_error);
  EXPECT_THROW(StandardNormalQuantile(-0.1), std::domain_error);
  EXPECT_THROW(StandardNormalQuantile(1.0), std::overflow_error);  // +infinity
  EXPECT_THROW(StandardNormalQuantile(0.0), std::overflow_error);
}

TEST(Distributions, PoissonIntervalsHaveTheirTabulatedValues) {
  // Garwood's exact 95 % interval for 2 events: 0.2422 to 7.2247 (half of chi2 0.025 at 4
  // degrees of freedom, 0.4844, and of chi2 0.975 at 6, 14.449).
  EXPECT_NEAR(PoissonLowerBound(2, 0.975), 0.24218, 1e-4);
  EXPECT_NEAR(PoissonUpperBound(2, 0.975), 7.22467, 1e-4);
  EXPECT_EQ(PoissonLowerBound(0, 0.975), 0.0);
  // A mean of 10: P(N <= 3) = 0.0103, P(N <= 4) = 0.0293; P(N > 16) = 0.0270, P(N > 17) = 0.0143.
  EXPECT_EQ(PoissonCountInterval(10.0, 0.95), std::make_pair(4L, 17L));
  EXPECT_EQ(PoissonCountInterval(0.01, 0.95), std::make_pair(0L, 0L));  // P(N > 0) = 0.00995
}

}  // namespace
}  // namespace armfault
