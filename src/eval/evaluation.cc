#include "finecap/eval/evaluation.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "finecap/util/error.h"

namespace finecap {
namespace {

void RequireIds(const std::vector<int>& ids, int size, const std::string& where) {
  for (int id : ids) {
    Require(id >= 0 && id < size, where,
            "vertex id " + std::to_string(id) + " is outside [0, " + std::to_string(size) + ")");
  }
}

// The columns `ids` of `matrix`.
Eigen::Matrix3Xd Columns(const Eigen::Matrix3Xd& matrix, const std::vector<int>& ids) {
  Eigen::Matrix3Xd picked(3, ids.size());
  for (size_t i = 0; i < ids.size(); ++i) picked.col(i) = matrix.col(ids[i]);
  return picked;
}

// The ids of `region` where both the refined and the true displacement are known: the vertices
// on which normals are compared, as the displacement errors are.
std::vector<int> Measured(const EvaluationSamples& samples, const std::vector<int>& region) {
  std::vector<int> measured;
  for (int v : region) {
    if (std::isfinite(samples.k_refined[v]) && std::isfinite(samples.k_true[v])) {
      measured.push_back(v);
    }
  }
  return measured;
}

RegionFigures RegionFiguresOf(const EvaluationSamples& samples, const std::vector<int>& region) {
  // The baselines are where they are (k = 0 from each), over the vertices the refinement gave a
  // value.
  const Eigen::VectorXd zero = samples.k_refined.array().isFinite().select(
      Eigen::VectorXd::Zero(samples.k_refined.size()), samples.k_refined);
  RegionFigures figures;
  figures.coarse = ComputeErrorStats(zero, samples.coarse_error, region);
  figures.subdivided = ComputeErrorStats(zero, samples.k_true, region);
  figures.refined = ComputeErrorStats(samples.k_refined, samples.k_true, region);
  figures.detail_recovered = DetailRecovered(figures.refined.rms, figures.coarse.rms);
  figures.flicker = ComputeFlickers(samples.errors_before, samples.Errors(), region);
  const std::vector<int> measured = Measured(samples, region);
  const Eigen::Matrix3Xd truth = Columns(samples.normals_true, measured);
  const auto normal_error = [&](const Eigen::Matrix3Xd& normals) {
    return MeanAngularErrorDegrees(Columns(normals, measured), truth);
  };
  figures.normal_error_coarse_deg = normal_error(samples.normals_coarse);
  figures.normal_error_subdivided_deg = normal_error(samples.normals_input);
  figures.normal_error_refined_deg = normal_error(samples.normals_refined);
  return figures;
}

Eigen::Matrix3Xd SideBySide(const Eigen::Matrix3Xd& first, const Eigen::Matrix3Xd& second) {
  Eigen::Matrix3Xd joined(3, first.cols() + second.cols());
  joined << first, second;
  return joined;
}

Eigen::VectorXd OneAfterTheOther(const Eigen::VectorXd& first, const Eigen::VectorXd& second) {
  Eigen::VectorXd joined(first.size() + second.size());
  joined << first, second;
  return joined;
}

// `errors` when it has `size` entries, else `size` unknowns: a frame without the frame before.
Eigen::VectorXd OrUnknown(const Eigen::VectorXd& errors, Eigen::Index size) {
  return errors.size() == size ? errors : Eigen::VectorXd::Constant(size, ErrorStats::kNoData);
}

// The errors before of `first` and then `second`, the unknown ones NaN.
SignedErrors ErrorsBeforeOfBoth(const EvaluationSamples& first, const EvaluationSamples& second) {
  const auto join = [&](Eigen::VectorXd SignedErrors::*surface) {
    return OneAfterTheOther(OrUnknown(first.errors_before.*surface, first.k_refined.size()),
                            OrUnknown(second.errors_before.*surface, second.k_refined.size()));
  };
  return {join(&SignedErrors::coarse), join(&SignedErrors::subdivided),
          join(&SignedErrors::refined)};
}

void AppendOffset(const std::vector<int>& ids, int offset, std::vector<int>* into) {
  for (int id : ids) into->push_back(id + offset);
}

}  // namespace

void EvaluationSamples::Append(const EvaluationSamples& other) {
  const int offset = static_cast<int>(k_refined.size());
  errors_before = ErrorsBeforeOfBoth(*this, other);
  AppendOffset(other.all, offset, &all);
  AppendOffset(other.textured, offset, &textured);
  AppendOffset(other.textureless, offset, &textureless);
  k_refined = OneAfterTheOther(k_refined, other.k_refined);
  k_true = OneAfterTheOther(k_true, other.k_true);
  coarse_error = OneAfterTheOther(coarse_error, other.coarse_error);
  normals_coarse = SideBySide(normals_coarse, other.normals_coarse);
  normals_input = SideBySide(normals_input, other.normals_input);
  normals_refined = SideBySide(normals_refined, other.normals_refined);
  normals_true = SideBySide(normals_true, other.normals_true);
}

SignedErrors EvaluationSamples::Errors() const {
  return SignedErrorsOf(k_refined, k_true, coarse_error);
}

EvaluationSamples MakeEvaluationSamples(const Mesh& coarse, const Mesh& input, const Mesh& refined,
                                        const Eigen::VectorXd& k_refined,
                                        const Eigen::VectorXd& k_true,
                                        const Eigen::VectorXd& coarse_error,
                                        const std::vector<int>& refined_vertices,
                                        const std::vector<int>& textureless_vertices,
                                        const std::string& where) {
  RequireSameTopology(input, coarse, where);
  RequireSameTopology(input, refined, where);
  const int n = input.num_vertices();
  Require(k_refined.size() == n && k_true.size() == n && coarse_error.size() == n, where,
          "expected " + std::to_string(n) + " displacements, got " +
              std::to_string(k_refined.size()) + " refined, " + std::to_string(k_true.size()) +
              " true and " + std::to_string(coarse_error.size()) + " of the coarse mesh");
  RequireIds(refined_vertices, n, where);
  RequireIds(textureless_vertices, n, where);

  EvaluationSamples samples;
  samples.k_refined = k_refined;
  samples.k_true = k_true;
  samples.coarse_error = coarse_error;
  samples.normals_coarse = ComputeVertexNormals(coarse);
  samples.normals_input = ComputeVertexNormals(input);
  samples.normals_refined = ComputeVertexNormals(refined);
  Mesh truth = input;
  const Eigen::VectorXd known = k_true.array().isFinite().select(k_true, 0.0);
  truth.vertices += samples.normals_input * known.asDiagonal();
  samples.normals_true = ComputeVertexNormals(truth);

  std::vector<bool> textureless(n, false);
  for (int v : textureless_vertices) textureless[v] = true;
  samples.all = refined_vertices;
  for (int v : refined_vertices)
    (textureless[v] ? samples.textureless : samples.textured).push_back(v);
  return samples;
}

EvaluationFigures ComputeEvaluationFigures(const EvaluationSamples& samples) {
  return {RegionFiguresOf(samples, samples.all), RegionFiguresOf(samples, samples.textured),
          RegionFiguresOf(samples, samples.textureless)};
}

Eigen::Matrix3Xd HeatMapColors(const Eigen::VectorXd& values, double max_value) {
  Require(
      std::isfinite(max_value) && max_value > 0.0, "HeatMapColors",
      "the top of the colour scale must be a positive number, got " + std::to_string(max_value));
  cv::Mat levels(1, static_cast<int>(values.size()), CV_8U);
  for (int i = 0; i < values.size(); ++i) {
    const double share = std::isfinite(values[i]) ? std::min(values[i] / max_value, 1.0) : 0.0;
    levels.at<uchar>(0, i) = cv::saturate_cast<uchar>(255.0 * std::max(share, 0.0));
  }
  cv::Mat bgr;
  if (values.size() > 0) cv::applyColorMap(levels, bgr, cv::COLORMAP_TURBO);
  Eigen::Matrix3Xd colors(3, values.size());
  for (int i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      colors.col(i).setConstant(0.5);
      continue;
    }
    const cv::Vec3b pixel = bgr.at<cv::Vec3b>(0, i);
    colors.col(i) << pixel[2] / 255.0, pixel[1] / 255.0, pixel[0] / 255.0;
  }
  return colors;
}

}  // namespace finecap
