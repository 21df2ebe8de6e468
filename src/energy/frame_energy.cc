#include "finecap/energy/frame_energy.h"

#include "energy/consensus_similarity.h"
#include "energy/input_prior.h"
#include "energy/paper_similarity.h"
#include "energy/pixel_consensus_similarity.h"
#include "energy/surface_color_similarity.h"
#include "finecap/util/error.h"

namespace finecap {

PairOptions EnergyPairOptions(const EnergyOptions& options) {
  PairOptions pair_options;
  pair_options.k_max = options.k_max;
  pair_options.reach_sigmas = options.reach_sigmas;
  // The paper's similarity weighs pairs by colour agreement; the colour residual compares
  // colours itself and needs every pair in reach.
  pair_options.color_cutoff =
      options.similarity == SimilarityType::kPaper ? options.color_cutoff : 0.0;
  return pair_options;
}

namespace {

const EnergyOptions& Checked(const EnergyOptions& options) {
  options.Check();
  return options;
}

// The cameras' pair lists; only their cameras when the similarity reads surface samples.
std::vector<EnergyView> BuildViews(const SurfaceGaussians& surface,
                                   const std::vector<CameraInput>& cameras,
                                   const EnergyOptions& options, bool with_samples) {
  const PairOptions pair_options = EnergyPairOptions(options);
  std::vector<EnergyView> views(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    views[c].camera = cameras[c].camera;
    if (with_samples) continue;
    Require(cameras[c].visible.size() == static_cast<size_t>(surface.size()),
            cameras[c].camera.name, "visibility must have one flag per surface Gaussian");
    views[c].image = cameras[c].image;
    views[c].pairs = BuildCameraPairs(cameras[c].camera, *cameras[c].image, surface,
                                      cameras[c].visible, pair_options);
  }
  return views;
}

// For each surface Gaussian, the surface Gaussians at most `rings` edges away on the mesh (at most
// as far as the neighbourhoods reach).
std::vector<std::vector<int>> SurfaceRings(const SurfaceGaussians& surface,
                                           const VertexNeighbourhoods& neighbourhoods, int rings) {
  std::vector<int> surface_of_vertex(neighbourhoods.num_vertices(), -1);
  for (int s = 0; s < surface.size(); ++s) surface_of_vertex[surface.vertex_ids[s]] = s;
  std::vector<std::vector<int>> patches(surface.size());
  for (int s = 0; s < surface.size(); ++s) {
    const int v = surface.vertex_ids[s];
    for (int e = neighbourhoods.offsets[v]; e < neighbourhoods.offsets[v + 1]; ++e) {
      const int j = surface_of_vertex[neighbourhoods.neighbours[e]];
      if (neighbourhoods.edge_distances[e] <= rings && j >= 0) patches[s].push_back(j);
    }
  }
  return patches;
}

std::unique_ptr<SimilarityTerm> MakeSimilarity(const SurfaceGaussians& surface,
                                               const std::vector<EnergyView>& views,
                                               const VertexNeighbourhoods& neighbourhoods,
                                               const SurfaceSamples& samples,
                                               const std::vector<CameraInput>& sample_cameras,
                                               const EnergyOptions& options) {
  const OverlapForm form = options.overlap;
  if (samples.size() > 0) {
    Require(options.similarity == SimilarityType::kConsensus, "energy.similarity",
            "surface samples (energy.consensus.sample_spacing) need the consensus similarity");
    return std::make_unique<PixelConsensusSimilarity>(samples, sample_cameras, options.consensus);
  }
  if (options.similarity == SimilarityType::kPaper)
    return std::make_unique<PaperSimilarity>(surface, views, form);
  if (options.similarity == SimilarityType::kConsensus) {
    return std::make_unique<ConsensusSimilarity>(
        surface, views, SurfaceRings(surface, neighbourhoods, options.consensus.patch_rings), form,
        options.k_max, options.reach_sigmas, options.consensus);
  }
  return std::make_unique<SurfaceColorSimilarity>(surface, views, form);
}

}  // namespace

FrameEnergy::FrameEnergy(SurfaceGaussians surface, const std::vector<CameraInput>& cameras,
                         const VertexNeighbourhoods& neighbourhoods, const EnergyOptions& options,
                         SurfaceSamples samples)
    : surface_(std::move(surface)),
      options_(Checked(options)),
      samples_(std::move(samples)),
      sample_cameras_(samples_.size() > 0 ? cameras : std::vector<CameraInput>()),
      views_(BuildViews(surface_, cameras, options_, samples_.size() > 0)),
      similarity_(
          MakeSimilarity(surface_, views_, neighbourhoods, samples_, sample_cameras_, options_)),
      regularizer_(neighbourhoods, surface_.vertex_ids, options_.reg_rings,
                   options_.RegUnitScale()) {
  // The data curvature is measured once, at the input surface, so that the prior is a fixed
  // quadratic: the solvers see one energy throughout.
  confidence_ = Confidence(surface_, PlainCloth(surface_, regularizer_, options_));
  Eigen::VectorXd data_curvature;
  if (options_.confidence_prior > 0.0) {
    data_curvature = DataCurvature(similarity_.get(), Eigen::VectorXd::Zero(surface_.size()));
    typical_data_curvature_ = MedianOfPositive(data_curvature);
  }
  prior_curvature_ = PriorCurvature(data_curvature, confidence_, surface_.size(), options_);
  prior_target_ =
      surface_.input_offset.empty()
          ? Eigen::VectorXd::Zero(surface_.size())
          : Eigen::Map<const Eigen::VectorXd>(surface_.input_offset.data(), surface_.size()).eval();
  for (EnergyView& view : views_) {
    num_pairs_ += view.pairs.num_pairs();
    if (similarity_->ReadsPairLists()) continue;
    std::vector<int>().swap(view.pairs.image_ids);
    std::vector<float>().swap(view.pairs.color_weights);
    view.image = nullptr;  // Without the ids nothing leads to the image Gaussians.
  }
}

void FrameEnergy::AddPull(const Eigen::VectorXd& target, double weight) {
  Require(target.size() == surface_.size(), "FrameEnergy::AddPull",
          "one target per surface Gaussian expected");
  if (typical_data_curvature_ < 0.0) {
    typical_data_curvature_ =
        MedianOfPositive(DataCurvature(similarity_.get(), Eigen::VectorXd::Zero(surface_.size())));
  }
  const double p = weight * typical_data_curvature_;
  if (!(p > 0.0)) return;
  for (int s = 0; s < surface_.size(); ++s) {
    if (!std::isfinite(target[s])) continue;
    // Two quadratics in k_s are one: the curvatures add and the targets blend by them.
    const double sum = prior_curvature_[s] + p;
    prior_target_[s] = (prior_curvature_[s] * prior_target_[s] + p * target[s]) / sum;
    prior_curvature_[s] = sum;
  }
}

long FrameEnergy::num_pairs() const { return num_pairs_; }

double FrameEnergy::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient,
                             double* similarity, double* regularization) const {
  Eigen::VectorXd similarity_gradient, regularization_gradient;
  const double e_sim = similarity_->Evaluate(k, gradient ? &similarity_gradient : nullptr);
  const double e_reg = regularizer_.Evaluate(k, gradient ? &regularization_gradient : nullptr);
  if (gradient != nullptr) {
    *gradient = similarity_gradient - options_.w_reg * regularization_gradient -
                prior_curvature_.cwiseProduct(k - prior_target_);
  }
  if (similarity != nullptr) *similarity = e_sim;
  if (regularization != nullptr) *regularization = e_reg;
  const Eigen::VectorXd from_target = k - prior_target_;
  return e_sim - options_.w_reg * e_reg -
         0.5 * from_target.dot(prior_curvature_.cwiseProduct(from_target));
}

}  // namespace finecap
