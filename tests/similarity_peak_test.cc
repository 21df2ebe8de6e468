// Does the energy peak at the true surface? A textured plane is rendered flat (the reference
// frame) and with one sinusoidal fold; the energy of the flat input mesh displaced by
// a * fold is evaluated over the amplitude a. The default similarity's best a must lie within
// 20 % of the true amplitude; the paper's E_sim is printed beside it for comparison.
#include <cstdio>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "energy_fixture.h"
#include "finecap/geometry/render.h"
#include "finecap/refine/refine.h"

namespace finecap {
namespace {

constexpr double kAmplitude = 0.006;  // Metres.
constexpr double kWavelength = 0.12;  // Metres.
constexpr int kGrid = 61;             // Vertices per side, 5 mm apart: a 30 cm square.
constexpr double kSpacing = 0.005;

// The fold's displacement along the mesh normal (-z, towards the cameras) at x.
double Fold(double x) { return std::sin(2.0 * M_PI * x / kWavelength); }

// A colourful cloth-like texture: smoothed random colour blobs.
cv::Mat MakeTexture() {
  cv::Mat noise(64, 64, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat texture;
  cv::resize(noise, texture, cv::Size(512, 512), 0, 0, cv::INTER_CUBIC);
  return texture;
}

SurfaceAppearance PlaneAppearance(const Mesh& mesh) {
  SurfaceAppearance appearance;
  appearance.texture = MakeTexture();
  appearance.corner_uvs.resize(2, 3 * mesh.num_faces());
  const double half = 0.5 * (kGrid - 1) * kSpacing;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      const Eigen::Vector3d p = mesh.vertices.col(mesh.faces(corner, f));
      appearance.corner_uvs.col(3 * f + corner) =
          Eigen::Vector2d((p.x() + half) / (2 * half), (p.y() + half) / (2 * half));
    }
  }
  return appearance;
}

FrameInput Render(const Mesh& flat, const Mesh& shown, const std::vector<Camera>& cameras) {
  FrameInput input;
  input.coarse = flat;
  input.cameras = cameras;
  RenderOptions options;
  options.supersampling = 3;
  options.background = Eigen::Vector3d(0.1, 0.1, 0.1);
  for (const Camera& camera : cameras) {
    input.images.push_back(RenderColor(camera, shown, PlaneAppearance(flat), options));
  }
  return input;
}

// The amplitude a in [0, 2 kAmplitude] where the similarity of the flat plane displaced by
// a * shape(x) is largest, the images showing the flat plane displaced by kAmplitude * shape(x).
// The reference frame shows the flat plane (exact reference colours) unless
// `folded_reference`: then it shows the same folds as the frame, as in a real capture, where the
// input mesh of the reference frame is as coarse as any other.
template <typename Shape>
double BestAmplitude(const RefineOptions& options, const Mesh& flat,
                     const std::vector<Camera>& cameras, const Shape& shape_of_x,
                     bool folded_reference = false) {
  const SequenceModel model(flat, {}, options, "plane");
  Mesh shown = flat;
  for (int v = 0; v < shown.num_vertices(); ++v) {
    shown.vertices(2, v) -= kAmplitude * shape_of_x(shown.vertices(0, v));
  }
  const ReferenceColors colors =
      ComputeSequenceColors(model, Render(flat, folded_reference ? shown : flat, cameras), options);
  PreparedFrame frame = PrepareFrame(model, colors, Render(flat, shown, cameras), options);
  const FrameEnergy& energy = *frame.energy;
  Eigen::VectorXd shape(energy.num_parameters());
  for (int s = 0; s < shape.size(); ++s) shape[s] = shape_of_x(energy.surface().base(0, s));
  double best_amplitude = 0.0, best = -1e300;
  for (int step = -20; step <= 40; ++step) {
    const double amplitude = 2.0 * kAmplitude * step / 40;
    const double value = energy.data_term(0).Evaluate(amplitude * shape, nullptr);
    if (value > best) best = value, best_amplitude = amplitude;
  }
  return best_amplitude;
}

class SimilarityPeakTest : public ::testing::Test {
 protected:
  SimilarityPeakTest() : flat_(GridMesh(kGrid, kGrid, kSpacing, 0.0)) {
    for (double tilt : {-0.45, 0.0, 0.45}) cameras_.push_back(LookAtOrigin(1.0, tilt, 900.0, 400));
    for (size_t c = 0; c < cameras_.size(); ++c) cameras_[c].name = "cam" + std::to_string(c);
    ours_.subdivision_levels = 0;
    ours_.sigma_hat = 0.004;
    paper_ = ours_;
    paper_.energy.similarity = SimilarityType::kPaper;
    paper_.reference_colors = ReferenceColorSource::kPixels;
    paper_.image.color_space = ColorSpace::kHsv;
    paper_.image.min_leaf_size = 4;
    consensus_ = ours_;
    consensus_.energy.similarity = SimilarityType::kConsensus;
    consensus_.image.color_space = ColorSpace::kNormalizedRgb;
  }

  Mesh flat_;
  std::vector<Camera> cameras_;
  RefineOptions ours_, paper_, consensus_;
};

// The plane moved as a whole along its normal: both similarities must find the offset.
TEST_F(SimilarityPeakTest, BothSimilaritiesPeakAtTheTrueOffset) {
  const auto offset = [](double) { return 1.0; };
  EXPECT_NEAR(BestAmplitude(ours_, flat_, cameras_, offset), kAmplitude, 0.1 * kAmplitude);
  EXPECT_NEAR(BestAmplitude(paper_, flat_, cameras_, offset), kAmplitude, 0.1 * kAmplitude);
}

TEST_F(SimilarityPeakTest, DefaultSimilarityPeaksAtTheTrueFoldAmplitude) {
  const double ours = BestAmplitude(ours_, flat_, cameras_, Fold);
  const double papers = BestAmplitude(paper_, flat_, cameras_, Fold);
  std::printf(
      "true fold amplitude %.1f mm: surface_color peaks at %.2f mm, paper's E_sim at "
      "%.2f mm\n",
      1000 * kAmplitude, 1000 * ours, 1000 * papers);
  EXPECT_NEAR(ours, kAmplitude, 0.2 * kAmplitude);
}

// With folds already in the reference frame, reference colours belong to the wrong surface
// points; the consensus similarity uses none and must still find the fold.
TEST_F(SimilarityPeakTest, ConsensusPeaksAtTheFoldWithoutAnExactReferenceFrame) {
  const double consensus = BestAmplitude(consensus_, flat_, cameras_, Fold, true);
  const double surface_color = BestAmplitude(ours_, flat_, cameras_, Fold, true);
  std::printf(
      "folds in the reference frame, true amplitude %.1f mm: consensus peaks at %.2f mm, "
      "surface_color at %.2f mm\n",
      1000 * kAmplitude, 1000 * consensus, 1000 * surface_color);
  EXPECT_NEAR(consensus, kAmplitude, 0.2 * kAmplitude);
  EXPECT_NEAR(BestAmplitude(
                  consensus_, flat_, cameras_, [](double) { return 1.0; }, true),
              kAmplitude, 0.1 * kAmplitude);
}

}  // namespace
}  // namespace finecap
