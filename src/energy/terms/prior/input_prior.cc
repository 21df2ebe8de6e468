#include "energy/terms/prior/input_prior.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace finecap {

Eigen::VectorXd DataCurvature(DataTerm* term, const Eigen::VectorXd& k) {
  return term->GaussNewtonDiagonal(k);
}

namespace {

// Surface Gaussian s and its regulariser neighbours, for each s.
std::vector<std::vector<int>> Neighbourhoods(int size, const Regularizer& regularizer) {
  std::vector<std::vector<int>> members(size);
  for (int s = 0; s < size; ++s) members[s].push_back(s);
  for (const Regularizer::Pair& pair : regularizer.pairs()) {
    if (pair.b < 0) continue;
    members[pair.a].push_back(pair.b);
    members[pair.b].push_back(pair.a);
  }
  return members;
}

double Median(std::vector<double>* values) {
  auto middle = values->begin() + values->size() / 2;
  std::nth_element(values->begin(), middle, values->end());
  return *middle;
}

}  // namespace

double MedianOfPositive(const Eigen::VectorXd& values) {
  std::vector<double> positive;
  for (double value : values) {
    if (value > 0.0) positive.push_back(value);
  }
  return positive.empty() ? 0.0 : Median(&positive);
}

namespace {

// Each entry replaced by the largest (`dilate`) or smallest of its neighbourhood's.
Eigen::VectorXd Morph(const Eigen::VectorXd& values, const std::vector<std::vector<int>>& members,
                      bool dilate) {
  Eigen::VectorXd result = values;
  for (int s = 0; s < values.size(); ++s) {
    for (int j : members[s]) {
      result[s] = dilate ? std::max(result[s], values[j]) : std::min(result[s], values[j]);
    }
  }
  return result;
}

// The mean without the largest tenth (at least the largest one).
double TrimmedMean(std::vector<double>* values) {
  const size_t kept = values->size() - std::max<size_t>(1, values->size() / 10);
  if (kept == 0) return 0.0;
  std::nth_element(values->begin(), values->begin() + kept, values->end());
  double sum = 0.0;
  for (size_t i = 0; i < kept; ++i) sum += (*values)[i];
  return sum / kept;
}

}  // namespace

Eigen::VectorXd ColorVariation(const SurfaceGaussians& surface, const Regularizer& regularizer) {
  const std::vector<std::vector<int>> members = Neighbourhoods(surface.size(), regularizer);
  Eigen::VectorXd variation(surface.size());
  std::vector<double> values;
  for (int s = 0; s < surface.size(); ++s) {
    Eigen::Vector3f center;
    for (int channel = 0; channel < 3; ++channel) {
      values.clear();
      for (int j : members[s]) values.push_back(surface.colors[j][channel]);
      center[channel] = static_cast<float>(Median(&values));
    }
    values.clear();
    for (int j : members[s]) values.push_back((surface.colors[j] - center).squaredNorm());
    variation[s] = TrimmedMean(&values);
  }
  return variation;
}

Eigen::VectorXd PlainCloth(const SurfaceGaussians& surface, const Regularizer& regularizer,
                           const EnergyOptions& options) {
  const Eigen::VectorXd variation = ColorVariation(surface, regularizer);
  // When most of the cloth is perfectly plain the median is 0, and so is the threshold: then
  // exactly the Gaussians without variation are plain.
  std::vector<double> values(variation.data(), variation.data() + variation.size());
  const double threshold = values.empty() ? 0.0 : options.confidence_threshold * Median(&values);
  Eigen::VectorXd plain(variation.size());
  for (int s = 0; s < variation.size(); ++s) {
    plain[s] = threshold > 0.0 ? std::exp(-variation[s] / threshold) : variation[s] == 0.0;
  }
  const std::vector<std::vector<int>> members = Neighbourhoods(surface.size(), regularizer);
  // Closing: a lone Gaussian inside plain cloth whose colour came out odd (a blend at a
  // silhouette in the reference view) would otherwise be left free to chase that colour.
  plain = Morph(Morph(plain, members, true), members, false);
  // Opening: a plain patch narrower than the opening is left to the regulariser, which
  // interpolates it from the texture around it; only wide plain regions are held.
  for (int i = 0; i < options.confidence_opening; ++i) plain = Morph(plain, members, false);
  for (int i = 0; i < options.confidence_opening; ++i) plain = Morph(plain, members, true);
  return plain;
}

Eigen::VectorXd Confidence(const SurfaceGaussians& surface, const Eigen::VectorXd& plain_cloth) {
  Eigen::VectorXd confidence = Eigen::VectorXd::Ones(surface.size()) - plain_cloth;
  if (surface.view_confidence.empty()) return confidence;
  for (int s = 0; s < surface.size(); ++s) confidence[s] *= surface.view_confidence[s];
  return confidence;
}

Eigen::VectorXd PriorCurvature(const std::function<double()>& typical_data_curvature,
                               const Eigen::VectorXd& confidence, int num_parameters,
                               const EnergyOptions& options) {
  const double u = options.RegUnitScale();
  Eigen::VectorXd prior = Eigen::VectorXd::Constant(num_parameters, 2.0 * options.w_prior * u * u);
  if (options.confidence_prior <= 0.0) return prior;
  const double typical = typical_data_curvature();
  if (typical <= 0.0) return prior;
  // Squared, so that a Gaussian the images nearly decide is hardly held: (1 - c)^2 is 0.01 at
  // c = 0.9, where a linear pull, 0.1, took detail that steep but sound views had found.
  prior += options.confidence_prior * typical * (1.0 - confidence.array()).square().matrix();
  return prior;
}

InputPriorTerm::InputPriorTerm(const TermContext& context)
    : curvature_(PriorCurvature(context.typical_data_curvature, context.confidence,
                                context.surface.size(), context.options)),
      target_(context.surface.input_offset.empty()
                  ? Eigen::VectorXd::Zero(context.surface.size())
                  : Eigen::Map<const Eigen::VectorXd>(context.surface.input_offset.data(),
                                                      context.surface.size())
                        .eval()) {}

void InputPriorTerm::AddPulls(Pulls* pulls) const { pulls->Add(curvature_, target_); }

}  // namespace finecap
