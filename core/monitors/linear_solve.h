// Small dense solves of the monitor's normal equations, by cofactors: exact to the bit from run
// to run and thread to thread, and cheaper than a general solver at these sizes.
#pragma once

#include <array>
#include <cmath>

namespace armfault {

// Solves the 2x2 symmetric system (a11 a12; a12 a22) x = (b1, b2); `inv11`, `inv22` get the
// inverse's diagonal. Returns false if singular.
inline bool Solve2(double a11, double a12, double a22, double b1, double b2, double* x1, double* x2, double* inv11,
                   double* inv22) {
  const double det = a11 * a22 - a12 * a12;
  if (!(std::fabs(det) > 1e-300)) return false;
  *x1 = (a22 * b1 - a12 * b2) / det;
  *x2 = (a11 * b2 - a12 * b1) / det;
  *inv11 = a22 / det;
  *inv22 = a11 / det;
  return true;
}

// Solves the symmetric 3x3 system m θ = r (m: 00 01 02 11 12 22); `inv_diag` gets the
// inverse's diagonal. Returns false if singular or not positive definite.
inline bool Solve3(const std::array<double, 6>& m, const std::array<double, 3>& r, std::array<double, 3>* t,
                   std::array<double, 3>* inv_diag) {
  const double c00 = m[3] * m[5] - m[4] * m[4], c01 = m[2] * m[4] - m[1] * m[5], c02 = m[1] * m[4] - m[2] * m[3];
  const double c11 = m[0] * m[5] - m[2] * m[2], c12 = m[1] * m[2] - m[0] * m[4], c22 = m[0] * m[3] - m[1] * m[1];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  if (!(det > 0) || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  (*t)[0] = (c00 * r[0] + c01 * r[1] + c02 * r[2]) * inv;
  (*t)[1] = (c01 * r[0] + c11 * r[1] + c12 * r[2]) * inv;
  (*t)[2] = (c02 * r[0] + c12 * r[1] + c22 * r[2]) * inv;
  *inv_diag = {c00 * inv, c11 * inv, c22 * inv};
  return true;
}

}  // namespace armfault
