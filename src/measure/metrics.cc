#include "finecap/measure/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>

#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr char kWhere[] = "metrics";

void RequireSameSize(Eigen::Index a, Eigen::Index b, const char* what) {
  Require(a == b, kWhere,
          std::string(what) + " have different sizes: " + std::to_string(a) + " and " +
              std::to_string(b));
}

ErrorStats StatsOfAbsoluteErrors(std::vector<double> absolute_errors) {
  ErrorStats stats;
  stats.count = static_cast<int>(absolute_errors.size());
  if (stats.empty()) return stats;
  double sum = 0.0, sum_of_squares = 0.0;
  for (double e : absolute_errors) {
    sum += e;
    sum_of_squares += e * e;
  }
  stats.rms = std::sqrt(sum_of_squares / stats.count);
  stats.mean_abs = sum / stats.count;
  stats.max_abs = *std::max_element(absolute_errors.begin(), absolute_errors.end());
  stats.p95_abs = Percentile(std::move(absolute_errors), 95.0);
  return stats;
}

// Appends |estimate(i) - truth(i)| when both are finite.
void AppendAbsoluteError(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth,
                         Eigen::Index i, std::vector<double>* absolute_errors) {
  const double error = estimate(i) - truth(i);
  if (std::isfinite(error)) absolute_errors->push_back(std::abs(error));
}

bool IsUsableDirection(const Eigen::Vector3d& v) { return v.allFinite() && v.squaredNorm() > 0.0; }

}  // namespace

double Percentile(std::vector<double> values, double percent) {
  Require(percent >= 0.0 && percent <= 100.0, kWhere,
          "percentile " + std::to_string(percent) + " is outside [0, 100]");
  values.erase(
      std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
      values.end());
  if (values.empty()) return kNaN;
  const double rank = percent / 100.0 * static_cast<double>(values.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(rank));
  const size_t above = std::min(below + 1, values.size() - 1);
  // Two partial selections instead of a full sort: eval runs this on every vertex of every frame.
  std::nth_element(values.begin(), values.begin() + below, values.end());
  const double low = values[below];
  const double high =
      above == below ? low : *std::min_element(values.begin() + below + 1, values.end());
  return low + (rank - static_cast<double>(below)) * (high - low);
}

ErrorStats ComputeErrorStats(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth) {
  RequireSameSize(estimate.size(), truth.size(), "estimate and truth");
  std::vector<double> absolute_errors;
  absolute_errors.reserve(estimate.size());
  for (Eigen::Index i = 0; i < estimate.size(); ++i) {
    AppendAbsoluteError(estimate, truth, i, &absolute_errors);
  }
  return StatsOfAbsoluteErrors(std::move(absolute_errors));
}

ErrorStats ComputeErrorStats(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth,
                             const std::vector<int>& indices) {
  RequireSameSize(estimate.size(), truth.size(), "estimate and truth");
  std::vector<double> absolute_errors;
  absolute_errors.reserve(indices.size());
  for (int i : indices) {
    Require(i >= 0 && i < estimate.size(), kWhere,
            "region index " + std::to_string(i) + " is outside [0, " +
                std::to_string(estimate.size()) + ")");
    AppendAbsoluteError(estimate, truth, i, &absolute_errors);
  }
  return StatsOfAbsoluteErrors(std::move(absolute_errors));
}

SignedErrors SignedErrorsOf(const Eigen::VectorXd& k, const Eigen::VectorXd& k_true,
                            const Eigen::VectorXd& coarse_error) {
  RequireSameSize(k.size(), k_true.size(), "displacement and true displacement");
  RequireSameSize(k.size(), coarse_error.size(), "displacement and coarse error");
  const auto where_refined = [&](const Eigen::VectorXd& error) -> Eigen::VectorXd {
    return k.array().isFinite().select(error, kNaN);
  };
  return {where_refined(-coarse_error), where_refined(-k_true), k - k_true};
}

ErrorStats ComputeFlicker(const Eigen::VectorXd& before, const Eigen::VectorXd& now,
                          const std::vector<int>& indices) {
  return ComputeErrorStats(now, before, indices);
}

FlickerStats ComputeFlickers(const SignedErrors& before, const SignedErrors& now,
                             const std::vector<int>& indices) {
  if (before.empty() || now.empty()) return {};
  return {ComputeFlicker(before.coarse, now.coarse, indices),
          ComputeFlicker(before.subdivided, now.subdivided, indices),
          ComputeFlicker(before.refined, now.refined, indices)};
}

double DetailRecovered(double rms_refined, double rms_coarse) {
  if (!std::isfinite(rms_coarse) || rms_coarse <= 0.0) return kNaN;
  return 1.0 - rms_refined / rms_coarse;
}

double MeanAngularErrorDegrees(const Eigen::Matrix3Xd& estimate, const Eigen::Matrix3Xd& truth) {
  RequireSameSize(estimate.cols(), truth.cols(), "normal sets");
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index i = 0; i < estimate.cols(); ++i) {
    const Eigen::Vector3d a = estimate.col(i), b = truth.col(i);
    if (!IsUsableDirection(a) || !IsUsableDirection(b)) continue;
    // atan2 of |a x b| and a.b keeps small angles accurate, where acos of a dot product does not.
    sum += std::atan2(a.cross(b).norm(), a.dot(b));
    ++count;
  }
  if (count == 0) return kNaN;
  return sum / count * 180.0 / M_PI;
}

}  // namespace finecap
