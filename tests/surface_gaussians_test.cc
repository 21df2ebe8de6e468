#include "finecap/model/surface_gaussians.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "energy_fixture.h"
#include "finecap/model/visibility.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

ReferenceColors SomeColors() {
  ReferenceColors colors;
  colors.color_space = ColorSpace::kChromaticity;
  colors.sigma_hat = 0.0055;
  colors.method = ReferenceColorSource::kImageModel;
  colors.colors = {Eigen::Vector3f(0.1f, 0.25f, 0.6f), Eigen::Vector3f(0.3f, 0.3f, 0.3f),
                   Eigen::Vector3f(0.0f, 0.0f, 0.0f)};
  colors.valid = {1, 1, 0};
  colors.recipe = "reference_frame=0 sigma_hat=0.0055 held_out=";
  return colors;
}

std::string TempPath(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / name).string();
}

TEST(ReferenceColorsTest, RoundTripKeepsEveryField) {
  const std::string path = TempPath("colors_round_trip.txt");
  const ReferenceColors written = SomeColors();
  WriteReferenceColors(path, written);
  const ReferenceColors read = ReadReferenceColors(path, 3);
  EXPECT_EQ(read.color_space, written.color_space);
  EXPECT_DOUBLE_EQ(read.sigma_hat, written.sigma_hat);
  EXPECT_EQ(read.method, ReferenceColorSource::kImageModel);
  EXPECT_EQ(read.recipe, written.recipe);
  EXPECT_EQ(read.valid, written.valid);
  for (int v = 0; v < 3; ++v) EXPECT_LT((read.colors[v] - written.colors[v]).norm(), 1e-7f);
}

// Cameras at 0.6, 0 and -0.3 radians about the point at the origin, whose normal faces -z tilted
// towards the first: the first sees it most frontally, unless it does not see it at all.
TEST(MostFrontalCameraTest, PicksTheCameraFacingTheNormalAmongThoseThatSeeThePoint) {
  const std::vector<Camera> cameras = {LookAtOrigin(1.0, 0.6, 400.0, 100),
                                       LookAtOrigin(1.0, 0.0, 400.0, 100),
                                       LookAtOrigin(1.0, -0.3, 400.0, 100)};
  const Eigen::Vector3d point = Eigen::Vector3d::Zero();
  const Eigen::Vector3d normal = Eigen::Vector3d(std::sin(0.5), 0.0, -std::cos(0.5));
  const auto all = [](int) { return true; };
  EXPECT_EQ(MostFrontalCamera(point, normal, cameras, all), 0);
  EXPECT_EQ(MostFrontalCamera(point, 3.0 * normal, cameras, all), 0);  // Only its direction.
  EXPECT_EQ(MostFrontalCamera(point, normal, cameras, [](int c) { return c != 0; }), 1);
  EXPECT_EQ(MostFrontalCamera(point, normal, cameras, [](int) { return false; }), -1);
  // Facing away from every camera still picks the least oblique of those that see it.
  EXPECT_EQ(MostFrontalCamera(point, -3.0 * normal, cameras, all), 2);
}

// A point at the origin facing the first of three cameras at 0, 1.2 and 1.45 radians about it (0,
// 68.8 and 83.1 degrees from its normal), all of which see it within the fallback angle.
class FrontalViewsTest : public ::testing::Test {
 protected:
  FrontalViewsTest()
      : cameras_({LookAtOrigin(1.0, 0.0, 400.0, 100), LookAtOrigin(1.0, 1.2, 400.0, 100),
                  LookAtOrigin(1.0, 1.45, 400.0, 100)}),
        points_(Eigen::Matrix3Xd::Zero(3, 1)),
        normals_(Eigen::Vector3d(0.0, 0.0, -1.0)) {}

  // Which cameras keep the point when it wants `wanted`.
  std::vector<int> Kept(int wanted) const {
    std::vector<std::vector<unsigned char>> visible(3, std::vector<unsigned char>(1, 1));
    KeepFrontalViews(cameras_, points_, normals_, wanted, options_, &visible);
    return Marked(visible);
  }
  // Which of the cameras `seen_by` marks keep the point when only the `count` most frontal do.
  std::vector<int> MostFrontal(int count, std::vector<unsigned char> seen_by = {1, 1, 1}) const {
    std::vector<std::vector<unsigned char>> visible;
    for (unsigned char seen : seen_by) visible.push_back({seen});
    KeepMostFrontalViews(cameras_, points_, normals_, count, &visible);
    return Marked(visible);
  }
  static std::vector<int> Marked(const std::vector<std::vector<unsigned char>>& visible) {
    std::vector<int> kept;
    for (int c = 0; c < 3; ++c) {
      if (visible[c][0]) kept.push_back(c);
    }
    return kept;
  }
  float Confidence(int wanted, std::vector<unsigned char> seen_by = {1, 1, 1}) const {
    std::vector<std::vector<unsigned char>> visible;
    for (unsigned char seen : seen_by) visible.push_back({seen});
    return ViewConfidence(cameras_, points_, normals_, wanted, options_, visible)[0];
  }

  std::vector<Camera> cameras_;
  Eigen::Matrix3Xd points_, normals_;
  VisibilityOptions options_;  // Within 60 degrees, and up to 85 for a point short of cameras.
};

TEST_F(FrontalViewsTest, APointShortOfCamerasTakesTheMostFrontalOthers) {
  EXPECT_EQ(Kept(0), std::vector<int>({0}));
  EXPECT_EQ(Kept(1), std::vector<int>({0}));
  EXPECT_EQ(Kept(2), std::vector<int>({0, 1}));
  EXPECT_EQ(Kept(3), std::vector<int>({0, 1, 2}));
}

TEST_F(FrontalViewsTest, OnlyTheMostFrontalViewsAreKeptWhateverTheirAngle) {
  EXPECT_EQ(MostFrontal(0), std::vector<int>({}));
  EXPECT_EQ(MostFrontal(1), std::vector<int>({0}));
  EXPECT_EQ(MostFrontal(2), std::vector<int>({0, 1}));
  EXPECT_EQ(MostFrontal(2, {0, 1, 1}), std::vector<int>({1, 2}));  // Only among those that see it.
  EXPECT_EQ(MostFrontal(5), std::vector<int>({0, 1, 2}));
}

TEST_F(FrontalViewsTest, ConfidenceFollowsTheWantedCamerasAngle) {
  const double full = std::cos(60.0 * M_PI / 180.0), none = std::cos(85.0 * M_PI / 180.0);
  EXPECT_FLOAT_EQ(Confidence(1), 1.0f);
  EXPECT_FLOAT_EQ(Confidence(2), static_cast<float>((std::cos(1.2) - none) / (full - none)));
  EXPECT_FLOAT_EQ(Confidence(3), static_cast<float>((std::cos(1.45) - none) / (full - none)));
  EXPECT_FLOAT_EQ(Confidence(2, {1, 0, 0}), 0.0f) << "one camera where two are wanted";
  EXPECT_FLOAT_EQ(Confidence(1, {0, 0, 1}),
                  static_cast<float>((std::cos(1.45) - none) / (full - none)));
  options_.fallback_view_angle_deg = options_.max_view_angle_deg;
  EXPECT_FLOAT_EQ(Confidence(2), 0.0f) << "no fallback: a view beyond the cap counts for nothing";
}

// The point at the origin seen by cameras at `tilts` (radians about it, all within 60 degrees of
// its normal), two of them wanted.
float PairedConfidence(const std::vector<double>& tilts, const VisibilityOptions& options = {}) {
  std::vector<Camera> cameras;
  for (double tilt : tilts) cameras.push_back(LookAtOrigin(1.0, tilt, 400.0, 100));
  const std::vector<std::vector<unsigned char>> visible(tilts.size(), {1});
  return ViewConfidence(cameras, Eigen::Matrix3Xd::Zero(3, 1),
                        Eigen::Matrix3Xd(Eigen::Vector3d(0.0, 0.0, -1.0)), 2, options, visible)[0];
}

TEST(PairConfidenceTest, TwoCamerasFarApartCountForLess) {
  const double full = std::cos(105.0 * M_PI / 180.0), none = std::cos(120.0 * M_PI / 180.0);
  EXPECT_FLOAT_EQ(PairedConfidence({-0.785, 0.785}), 1.0f) << "90 degrees apart";
  EXPECT_FLOAT_EQ(PairedConfidence({-1.0, 1.0}),
                  static_cast<float>((std::cos(2.0) - none) / (full - none)))
      << "115 degrees apart";
  EXPECT_FLOAT_EQ(PairedConfidence({-1.2, 1.2}), 0.0f) << "138 degrees: beyond the fallback";
  EXPECT_FLOAT_EQ(PairedConfidence({-1.0, 0.0, 1.0}), 1.0f)
      << "a third camera between them makes a narrow pair";
  VisibilityOptions any_pair;
  any_pair.max_pair_angle_deg = any_pair.fallback_pair_angle_deg = 180.0;
  EXPECT_FLOAT_EQ(PairedConfidence({-1.0, 1.0}, any_pair), 1.0f);
}

TEST(ReferenceColorsTest, WrongVertexCountAndTruncationAreNamed) {
  const std::string path = TempPath("colors_count.txt");
  WriteReferenceColors(path, SomeColors());
  try {
    ReadReferenceColors(path, 4);
    FAIL() << "expected an Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("colors_count.txt"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("made for 3 vertices"), std::string::npos);
  }
  std::string text;
  {
    std::ifstream stream(path);
    text.assign(std::istreambuf_iterator<char>(stream), {});
  }
  std::ofstream(path) << text.substr(0, text.size() - 12);  // Cut the last vertex line.
  EXPECT_THROW(ReadReferenceColors(path, 3), Error);
}

}  // namespace
}  // namespace finecap
