#include "campaigns/scoring/pod.h"

#include <algorithm>
#include <cmath>

#include "core/base/distributions.h"
#include "faults/fault.h"

namespace armfault {

namespace {

// The two-sided and one-sided 95 % normal quantiles (1.959963984540054, 1.6448536269514724).
const double kZ95Two = StandardNormalQuantile(0.975);
const double kZ95One = StandardNormalQuantile(0.95);

}  // namespace

std::string PodCategory(const nlohmann::json& fault) {
  for (const char* key : {"lead", "kind"}) {
    if (fault.is_object() && fault.contains(key) && fault[key].is_string()) return fault[key].get<std::string>();
  }
  return "";
}

nlohmann::json PodFitJson(const std::string& key, const std::vector<double>& severities, const std::vector<bool>& hits) {
  const PodFit pf = FitPod(severities, hits);
  nlohmann::json fit = {{"model", "logistic in log(severity), Firth"}, {"ok", pf.ok}};
  if (!pf.ok) {
    fit["reason"] = pf.reason;
    return fit;
  }
  const double lo = *std::min_element(severities.begin(), severities.end());
  const double hi = *std::max_element(severities.begin(), severities.end());
  nlohmann::json curve = nlohmann::json::array();
  const int n = 60;
  for (int i = 0; i <= n; ++i) {
    const double s = std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / n);
    curve.push_back({{"severity", s}, {"magnitude", FaultMagnitudeOfSeverity(key, s)}, {"pod", pf.Probability(s)},
                     {"low", pf.Bound(s, -kZ95Two)}, {"high", pf.Bound(s, kZ95Two)}});
  }
  fit["intercept"] = pf.intercept;
  fit["slope_per_log_severity"] = pf.slope;
  fit["curve"] = curve;
  // a90: where the fit reaches 0.9; a90/95: where its one-sided 95 % lower bound does.
  // Only within the tested severities: no extrapolation.
  auto first_at = [&](auto&& value) -> nlohmann::json {
    const int m = 2000;
    for (int i = 0; i <= m; ++i) {
      const double s = std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / m);
      if (value(s) >= 0.9) return {{"severity", s}, {"magnitude", FaultMagnitudeOfSeverity(key, s)}};
    }
    return nullptr;
  };
  fit["a90"] = pf.slope > 0 ? first_at([&](double s) { return pf.Probability(s); }) : nlohmann::json(nullptr);
  fit["a90_95"] = pf.slope > 0 ? first_at([&](double s) { return pf.Bound(s, -kZ95One); }) : nlohmann::json(nullptr);
  return fit;
}

double PodFit::Probability(double severity) const {
  return 1 / (1 + std::exp(-(intercept + slope * std::log(severity))));
}

double PodFit::Bound(double severity, double z) const {
  const double x = std::log(severity);
  const double eta = intercept + slope * x;
  const double var = cov[0][0] + 2 * x * cov[0][1] + x * x * cov[1][1];
  return 1 / (1 + std::exp(-(eta + z * std::sqrt(std::max(0.0, var)))));
}

PodFit FitPod(const std::vector<double>& severity, const std::vector<bool>& detected) {
  PodFit f;
  std::vector<double> x;
  for (double s : severity) x.push_back(std::log(s));
  const size_t n = x.size();
  if (n < 4 || *std::min_element(x.begin(), x.end()) == *std::max_element(x.begin(), x.end())) {
    f.reason = "needs at least 4 runs at 2 or more magnitudes";
    return f;
  }
  // Firth-penalised Newton iterations: score U_j = sum (y - p + h (1/2 - p)) x_j.
  double a = 0, b = 0;
  double inv[2][2] = {{0, 0}, {0, 0}};
  for (int iter = 0; iter < 200; ++iter) {
    double i00 = 0, i01 = 0, i11 = 0;
    std::vector<double> p(n), w(n);
    for (size_t i = 0; i < n; ++i) {
      p[i] = 1 / (1 + std::exp(-(a + b * x[i])));
      w[i] = std::max(1e-12, p[i] * (1 - p[i]));
      i00 += w[i];
      i01 += w[i] * x[i];
      i11 += w[i] * x[i] * x[i];
    }
    const double det = i00 * i11 - i01 * i01;
    if (!(det > 1e-300)) {
      f.reason = "singular information matrix";
      return f;
    }
    inv[0][0] = i11 / det, inv[0][1] = inv[1][0] = -i01 / det, inv[1][1] = i00 / det;
    double u0 = 0, u1 = 0;
    for (size_t i = 0; i < n; ++i) {
      const double h = w[i] * (inv[0][0] + 2 * x[i] * inv[0][1] + x[i] * x[i] * inv[1][1]);
      const double r = (detected[i] ? 1.0 : 0.0) - p[i] + h * (0.5 - p[i]);
      u0 += r;
      u1 += r * x[i];
    }
    double da = inv[0][0] * u0 + inv[0][1] * u1, db = inv[1][0] * u0 + inv[1][1] * u1;
    const double step = std::max(std::fabs(da), std::fabs(db));
    if (step > 5) da *= 5 / step, db *= 5 / step;  // damped: separation pushes far
    a += da;
    b += db;
    if (step < 1e-9) {
      f.ok = true;
      break;
    }
  }
  if (!f.ok) {
    f.reason = "did not converge";
    return f;
  }
  f.intercept = a;
  f.slope = b;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) f.cov[i][j] = inv[i][j];
  }
  return f;
}

}  // namespace armfault
