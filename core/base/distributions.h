// The standard normal distribution as the statistics use it (summary intervals, the monitor's
// verdict confidence, the boundary search's one-sided bound, the PoD bands, the diff's tests):
// Boost.Math's normal distribution (Debian libboost-math-dev, header-only here), not a
// hand-written erfc or a bisection on it. Boost's default policy: double arguments are
// evaluated in long double, and the results are within about 1e-15 relative of the exact
// values of the double argument (a few ulps; tests/core/base/distributions_test.cc); a
// probability outside [0, 1] throws std::domain_error, 0 or 1 std::overflow_error.
#pragma once

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/poisson.hpp>
#include <utility>

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

// The one-sided upper confidence bound on the mean of a Poisson count of which `count` (>= 0)
// were seen: the exact (Garwood) bound, half the chi-squared quantile at `confidence` with
// 2 (count + 1) degrees of freedom (count 0 at 95 %: 2.995732273553991, "the rule of three").
// Divided by the exposure (hours of operation), it bounds a rate of events per hour.
inline double PoissonUpperBound(long count, double confidence) {
  return 0.5 * boost::math::quantile(boost::math::chi_squared_distribution<double>(2.0 * (static_cast<double>(count) + 1)),
                                     confidence);
}

// The exact (Garwood) lower bound on a Poisson mean of which `count` were seen, at one-sided
// `confidence`: half the chi-squared quantile at 1 - confidence with 2 count degrees of freedom
// (0 when none were seen). With PoissonUpperBound at the same confidence, the central interval
// at 2 confidence - 1 (0.975: the 95 % interval).
inline double PoissonLowerBound(long count, double confidence) {
  if (count <= 0) return 0.0;
  return 0.5 * boost::math::quantile(boost::math::chi_squared_distribution<double>(2.0 * static_cast<double>(count)),
                                     1.0 - confidence);
}

// The central interval [lo, hi] of a Poisson count of mean `mean` > 0 holding at least
// `probability` of it: lo the largest count with P(N < lo) <= (1 - probability) / 2, hi the
// smallest with P(N > hi) <= (1 - probability) / 2.
inline std::pair<long, long> PoissonCountInterval(double mean, double probability) {
  const boost::math::poisson_distribution<double> n(mean);
  const double tail = 0.5 * (1.0 - probability);
  long lo = 0;
  while (boost::math::cdf(n, static_cast<double>(lo)) <= tail) ++lo;  // P(N <= lo) > tail: P(N < lo) <= tail
  long hi = lo;
  while (boost::math::cdf(boost::math::complement(n, static_cast<double>(hi))) > tail) ++hi;
  return {lo, hi};
}

}  // namespace armfault
