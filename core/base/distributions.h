// The standard normal distribution as the statistics use it (summary intervals, the monitor's
// verdict confidence, the boundary search's one-sided bound, the PoD bands, the diff's tests):
// Boost.Math's normal distribution (Debian libboost-math-dev, header-only here), not a
// hand-written erfc or a bisection on it. Boost's default policy: double arguments are
// evaluated in long double, and the results are within about 1e-15 relative of the exact
// values of the double argument (a few ulps; tests/core/base/distributions_test.cc); a
// probability outside [0, 1] throws std::domain_error, 0 or 1 std::overflow_error.
#pragma once

#include <boost/math/distributions/normal.hpp>

namespace armfault {

// Phi(z) = P(Z <= z), Z standard normal.
inline double StandardNormalCdf(double z) { return boost::math::cdf(boost::math::normal_distribution<double>(), z); }

// 1 - Phi(z) = P(Z > z), accurate in the far upper tail (no cancellation against 1).
inline double StandardNormalUpperTail(double z) {
  return boost::math::cdf(boost::math::complement(boost::math::normal_distribution<double>(), z));
}

// The z with Phi(z) = p, p in (0, 1) (p = 0.975: 1.959963984540054; p = 0.95: 1.6448536269514724).
inline double StandardNormalQuantile(double p) {
  return boost::math::quantile(boost::math::normal_distribution<double>(), p);
}

}  // namespace armfault
