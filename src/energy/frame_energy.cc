#include "finecap/energy/frame_energy.h"

#include "energy/term_registry.h"
#include "energy/terms/consensus/pixel_consensus_similarity.h"
#include "energy/terms/prior/input_prior.h"
#include "finecap/util/error.h"

namespace finecap {

PairOptions EnergyPairOptions(const EnergyOptions& options) {
  PairOptions pair_options;
  pair_options.k_max = options.k_max;
  pair_options.reach_sigmas = options.reach_sigmas;
  // A similarity that weighs pairs by colour agreement (the paper's) needs only the pairs within
  // the cut-off; the others compare colours themselves and need every pair in reach.
  pair_options.color_cutoff = internal::WeighsPairsByColor(options) ? options.color_cutoff : 0.0;
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

}  // namespace

FrameEnergy::FrameEnergy(SurfaceGaussians surface, const std::vector<CameraInput>& cameras,
                         const VertexNeighbourhoods& neighbourhoods, const EnergyOptions& options,
                         SurfaceSamples samples)
    : surface_(std::move(surface)),
      options_(Checked(options)),
      samples_(std::move(samples)),
      sample_cameras_(samples_.size() > 0 ? cameras : std::vector<CameraInput>()),
      views_(BuildViews(surface_, cameras, options_, samples_.size() > 0)),
      regularizer_(neighbourhoods, surface_.vertex_ids, options_.reg_rings,
                   options_.RegUnitScale()) {
  internal::DataTerms terms = internal::MakeDataTerms(
      {surface_, views_, neighbourhoods, regularizer_, samples_, sample_cameras_, options_});
  data_terms_ = std::move(terms.from_first_pass);
  last_pass_terms_ = std::move(terms.from_last_pass);
  confidence_ = Confidence(surface_, PlainCloth(surface_, regularizer_, options_));
  const TermContext context{surface_, options_, regularizer_, confidence_,
                            [this] { return TypicalDataCurvature(); }};
  quadratic_terms_ = internal::MakeQuadraticTerms(context);
  for (const auto& term : quadratic_terms_) term->AddDifferences(&differences_);
  GatherPulls();
  const bool keep_pair_lists = ReadsPairLists();
  for (EnergyView& view : views_) {
    num_pairs_ += view.pairs.num_pairs();
    if (keep_pair_lists) continue;
    std::vector<int>().swap(view.pairs.image_ids);
    std::vector<float>().swap(view.pairs.color_weights);
    view.image = nullptr;  // Without the ids nothing leads to the image Gaussians.
  }
}

SampledInput FrameEnergy::TakeSampledInput(std::unique_ptr<FrameEnergy> energy) {
  // The terms read the samples and the cameras: they go first.
  energy->data_terms_.clear();
  SampledInput input;
  input.samples = std::move(energy->samples_);
  for (CameraInput& camera : energy->sample_cameras_) {
    input.pixels.push_back(camera.pixels);
    input.samples_on_foreground.push_back(std::move(camera.samples_on_foreground));
  }
  return input;
}

double FrameEnergy::TypicalDataCurvature() {
  // Measured once, at the input surface, so that every pull in its units is a fixed quadratic:
  // the solvers see one energy throughout.
  if (typical_data_curvature_ < 0.0) {
    const Eigen::VectorXd input = Eigen::VectorXd::Zero(surface_.size());
    Eigen::VectorXd curvature = Eigen::VectorXd::Zero(surface_.size());
    for (const auto& term : data_terms_) curvature += DataCurvature(term.get(), input);
    typical_data_curvature_ = MedianOfPositive(curvature);
  }
  return typical_data_curvature_;
}

Eigen::VectorXd FrameEnergy::UnknownsAtVertices(const Eigen::VectorXd& per_vertex) const {
  const std::vector<int>& ids = surface_.vertex_ids;
  Eigen::VectorXd unknowns(static_cast<Eigen::Index>(ids.size()));
  for (size_t s = 0; s < ids.size(); ++s) unknowns[s] = per_vertex[ids[s]];
  return unknowns;
}

void FrameEnergy::StartLastPass() {
  for (const auto& make_term : last_pass_terms_) data_terms_.push_back(make_term());
  last_pass_terms_.clear();
}

void FrameEnergy::AddDataTerm(std::unique_ptr<DataTerm> term) {
  Require(term != nullptr, "FrameEnergy::AddDataTerm", "no term given");
  data_terms_.push_back(std::move(term));
}

bool FrameEnergy::IsLeastSquares() const {
  for (const auto& term : data_terms_) {
    if (!term->IsLeastSquares()) return false;
  }
  return true;
}

bool FrameEnergy::ReadsPairLists() const {
  for (const auto& term : data_terms_) {
    if (term->ReadsPairLists()) return true;
  }
  return false;
}

bool FrameEnergy::HasPassHooks() const {
  for (const auto& term : data_terms_) {
    if (term->pass_hook() != nullptr) return true;
  }
  return false;
}

void FrameEnergy::EndOfPass(const Eigen::VectorXd& k) {
  Require(k.size() == surface_.size(), "FrameEnergy::EndOfPass",
          "one displacement per surface Gaussian expected");
  for (const auto& term : data_terms_) {
    if (PassHook* hook = term->pass_hook()) hook->EndOfPass(k);
  }
}

void FrameEnergy::GatherPulls() {
  pulls_ = Pulls(surface_.size());
  for (const auto& term : quadratic_terms_) term->AddPulls(&pulls_);
}

void FrameEnergy::TakeFrameBefore(const Eigen::VectorXd& k_before) {
  Require(k_before.size() == surface_.size(), "FrameEnergy::TakeFrameBefore",
          "one displacement per surface Gaussian expected");
  bool changed = false;
  for (const auto& term : quadratic_terms_) changed = term->TakeFrameBefore(k_before) || changed;
  if (changed) GatherPulls();
}

double FrameEnergy::DifferenceEnergy(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  if (gradient != nullptr) *gradient = Eigen::VectorXd::Zero(k.size());
  double energy = 0.0;
  for (const auto& term : quadratic_terms_) energy += term->DifferenceEnergy(k, gradient);
  return energy;
}

Eigen::Matrix3Xd FrameEnergy::SampleAppearance(const Eigen::VectorXd& k) const {
  if (samples_.size() == 0) return {};
  Require(k.size() == surface_.size(), "FrameEnergy::SampleAppearance",
          "one displacement per surface Gaussian expected");
  return SeenAppearance(samples_, sample_cameras_, samples_.weights * k);
}

long FrameEnergy::num_pairs() const { return num_pairs_; }

double FrameEnergy::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient, double* data,
                             double* quadratic) const {
  Eigen::VectorXd data_gradient = Eigen::VectorXd::Zero(k.size()), term_gradient,
                  difference_gradient;
  double e_data = 0.0;
  for (const auto& term : data_terms_) {
    e_data += term->Evaluate(k, gradient != nullptr ? &term_gradient : nullptr);
    if (gradient != nullptr) data_gradient += term_gradient;
  }
  const double e_differences = DifferenceEnergy(k, gradient ? &difference_gradient : nullptr);
  const double e_pulls = PullEnergy(k);
  if (gradient != nullptr) {
    *gradient =
        data_gradient - difference_gradient - pulls_.curvature().cwiseProduct(k - pulls_.target());
  }
  if (data != nullptr) *data = e_data;
  if (quadratic != nullptr) *quadratic = e_differences + e_pulls;
  return e_data - e_differences - e_pulls;
}

}  // namespace finecap
