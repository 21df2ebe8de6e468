// Optical flow and the flow evaluation against answers known by construction: an image and its
// copy shifted by a known number of pixels, and a textured plane moved sideways by a known
// distance in front of a pinhole camera.
#include "finecap/eval/optical_flow.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "finecap/eval/flow_evaluation.h"
#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;

// Smooth random texture: every pixel has structure at a scale the flow methods lock onto.
cv::Mat RandomTexture(int width, int height) {
  cv::Mat noise(height, width, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat texture;
  cv::GaussianBlur(noise, texture, cv::Size(0, 0), 1.5);
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  return texture;
}

// `image` moved by (dx, dy) pixels, the border replicated.
cv::Mat Shifted(const cv::Mat& image, double dx, double dy) {
  const cv::Mat move = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat shifted;
  cv::warpAffine(image, shifted, move, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return shifted;
}

// Every pixel at least `margin` from the border.
cv::Mat InteriorMask(cv::Size size, int margin) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(margin, margin, size.width - 2 * margin, size.height - 2 * margin)).setTo(255);
  return mask;
}

void ExpectFlowOfAShift(const std::string& method) {
  const cv::Mat image = RandomTexture(128, 128);
  OpticalFlowOptions options;
  ASSERT_TRUE(StringToEnum(method, &options.method));
  const cv::Mat flow = ComputeOpticalFlow(image, Shifted(image, 3.0, -2.0), options, "shift");
  ASSERT_EQ(flow.type(), CV_32FC2);
  ASSERT_EQ(flow.size(), image.size());
  const cv::Mat mask = InteriorMask(image.size(), 16);
  const FlowMagnitudeSum sum = SumFlowMagnitude(flow, mask, "shift");
  EXPECT_EQ(sum.count, 96 * 96);
  EXPECT_NEAR(sum.mean_px(), std::hypot(3.0, 2.0), 0.25) << method;
  const cv::Scalar mean_vector = cv::mean(flow, mask);  // Pixel (x, y) is seen at (x+3, y-2).
  EXPECT_NEAR(mean_vector[0], 3.0, 0.25) << method;
  EXPECT_NEAR(mean_vector[1], -2.0, 0.25) << method;
}

TEST(OpticalFlowTest, DisFindsAKnownShift) { ExpectFlowOfAShift("dis"); }

TEST(OpticalFlowTest, DeepFlowFindsAKnownShift) { ExpectFlowOfAShift("deepflow"); }

TEST(OpticalFlowTest, AnImageAgainstItselfHasNoFlow) {
  const cv::Mat image = RandomTexture(96, 64);
  const cv::Mat flow = ComputeOpticalFlow(image, image, OpticalFlowOptions(), "same");
  EXPECT_LT(SumFlowMagnitude(flow, InteriorMask(image.size(), 0), "same").mean_px(), 0.05);
}

TEST(OpticalFlowTest, MagnitudeSumCountsMaskedFiniteVectorsOnly) {
  cv::Mat flow(2, 3, CV_32FC2, cv::Vec2f(3.0f, 4.0f));  // Length 5 everywhere...
  flow.at<cv::Vec2f>(0, 1) = cv::Vec2f(0.0f, -1.0f);    // ... but 1 here,
  flow.at<cv::Vec2f>(1, 1) = cv::Vec2f(NAN, 0.0f);      // unknown here,
  cv::Mat mask(2, 3, CV_8UC1, cv::Scalar(1));
  mask.at<unsigned char>(1, 2) = 0;  // and not counted here.
  const FlowMagnitudeSum sum = SumFlowMagnitude(flow, mask, "hand");
  EXPECT_EQ(sum.count, 4);
  EXPECT_DOUBLE_EQ(sum.sum_px, 5.0 + 1.0 + 5.0 + 5.0);
  EXPECT_DOUBLE_EQ(sum.mean_px(), 4.0);
  FlowMagnitudeSum pooled;
  EXPECT_TRUE(std::isnan(pooled.mean_px()));
  pooled.Add(sum);
  pooled.Add(FlowMagnitudeSum{2.0, 1});
  EXPECT_DOUBLE_EQ(pooled.mean_px(), 18.0 / 5.0);
}

TEST(OpticalFlowTest, ImprovementIsThePapersPercentage) {
  EXPECT_DOUBLE_EQ(FlowImprovementPercent(2.0, 1.5), 25.0);
  EXPECT_DOUBLE_EQ(FlowImprovementPercent(2.0, 3.0), -50.0);
  EXPECT_TRUE(std::isnan(FlowImprovementPercent(0.0, 1.0)));
  EXPECT_TRUE(std::isnan(FlowImprovementPercent(NAN, 1.0)));
}

TEST(OpticalFlowTest, RefusesBadOptionsAndImages) {
  const cv::Mat image = RandomTexture(32, 32);
  OpticalFlowOptions options;
  options.method = static_cast<FlowMethod>(5);
  ExpectErrorMentions([&] { ComputeOpticalFlow(image, image, options, "pair"); },
                      {"OpticalFlowOptions::method", "not a valid choice"});
  options = OpticalFlowOptions();
  options.dis_preset = static_cast<DisPreset>(-1);
  ExpectErrorMentions([&] { options.Check(); }, {"OpticalFlowOptions::dis_preset"});
  ExpectErrorMentions(
      [&] { ComputeOpticalFlow(image, RandomTexture(32, 16), OpticalFlowOptions(), "cam0/7"); },
      {"cam0/7", "differ in size"});
  ExpectErrorMentions([&] { ComputeOpticalFlow(cv::Mat(), image, OpticalFlowOptions(), "cam1/3"); },
                      {"cam1/3", "empty"});
  ExpectErrorMentions(
      [&] { SumFlowMagnitude(cv::Mat(4, 4, CV_32FC2), cv::Mat(4, 5, CV_8UC1), "sum"); },
      {"sum", "mask"});
}

// A square plane of side `side` metres at depth `depth`, centred on the optical axis, split into
// n x n cells of two triangles, facing the camera (normals along -z).
Mesh FacingPlane(double side, double depth, int n) {
  Mesh mesh;
  mesh.vertices.resize(3, (n + 1) * (n + 1));
  for (int row = 0; row <= n; ++row) {
    for (int col = 0; col <= n; ++col) {
      mesh.vertices.col(row * (n + 1) + col) << side * (col / double(n) - 0.5),
          side * (row / double(n) - 0.5), depth;
    }
  }
  mesh.faces.resize(3, 2 * n * n);
  int f = 0;
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const int a = row * (n + 1) + col;
      mesh.faces.col(f++) << a, a + n + 1, a + 1;
      mesh.faces.col(f++) << a + 1, a + n + 1, a + n + 2;
    }
  }
  return mesh;
}

Camera PinholeCamera(int size, double focal) {
  Camera camera;
  camera.name = "front";
  camera.width = size;
  camera.height = size;
  camera.K << focal, 0, (size - 1) / 2.0, 0, focal, (size - 1) / 2.0, 0, 0, 1;
  return camera;
}

// A 1 m plane at 2 m in front of a 128 x 128 camera (f = 100 px, so 50 px wide), textured from
// a random image by that camera, which sees every vertex.
struct TexturedPlane {
  Camera camera = PinholeCamera(128, 100.0);
  Mesh plane = FacingPlane(1.0, 2.0, 8);
  cv::Mat image = RandomTexture(128, 128);
  ProjectiveTexture texture =
      MakeProjectiveTexture(plane, ComputeVertexNormals(plane), {camera}, {image},
                            {std::vector<unsigned char>(plane.num_vertices(), 1)});
};

TEST(FlowEvaluationTest, TextureFromTheImageRendersTheImageBack) {
  const TexturedPlane scene;
  const ProjectiveTexture& texture = scene.texture;
  EXPECT_EQ(texture.atlas.size(), scene.image.size());
  EXPECT_EQ(std::count(texture.textured.begin(), texture.textured.end(), 1),
            scene.plane.num_faces());
  cv::Mat difference;
  cv::absdiff(RenderTexturedOverImage(scene.camera, scene.plane, texture, scene.image), scene.image,
              difference);
  EXPECT_LE(cv::norm(difference, cv::NORM_INF), 2.0);  // Bilinear sampling at texel centres.
}

TEST(FlowEvaluationTest, APlaneMovedSidewaysFlowsByItsImageShift) {
  // Textured at x = 0, seen in a later "frame" whose image shows it unmoved: the input mesh is
  // 6 cm off to the side (3 px at 2 m with f = 100 px), the refined mesh is right.
  const TexturedPlane scene;
  const Mesh& plane = scene.plane;
  Mesh moved = plane;
  moved.vertices.row(0).array() += 0.06;
  std::vector<int> all(plane.num_vertices());
  for (int v = 0; v < plane.num_vertices(); ++v) all[v] = v;
  const FlowComparison flow =
      CompareFlow(scene.camera, scene.image, moved, scene.texture, plane, scene.texture,
                  FacesToMeasure(plane, scene.texture, all), OpticalFlowOptions(), "plane");
  // The union of both footprints is 53 px wide, 50 of which show the texture 3 px off.
  EXPECT_NEAR(flow.coarse.mean_px(), 3.0 * 50.0 / 53.0, 0.35);
  EXPECT_LT(flow.refined.mean_px(), 0.2);
  EXPECT_GT(FlowImprovementPercent(flow.coarse.mean_px(), flow.refined.mean_px()), 90.0);
  EXPECT_NEAR(flow.coarse.count, 53 * 50, 150);
  EXPECT_EQ(flow.coarse.count, flow.refined.count);  // The same pixels for both.
}

TEST(FlowEvaluationTest, OnlyTexturedFacesOfChosenVerticesAreMeasured) {
  const Mesh plane = FacingPlane(1.0, 2.0, 2);  // 9 vertices, 8 faces.
  std::vector<std::vector<unsigned char>> seen = {std::vector<unsigned char>(9, 1)};
  seen[0][8] = 0;  // The far corner is unseen: its one face gets no texture.
  const ProjectiveTexture texture = MakeProjectiveTexture(
      plane, ComputeVertexNormals(plane), {PinholeCamera(64, 50.0)}, {RandomTexture(64, 64)}, seen);
  EXPECT_EQ(std::count(texture.textured.begin(), texture.textured.end(), 1), 7);
  EXPECT_FALSE(texture.textured[7]);
  // Vertex 0 (a corner) belongs to the first face only.
  EXPECT_EQ(FacesToMeasure(plane, texture, {0}),
            std::vector<unsigned char>({1, 0, 0, 0, 0, 0, 0, 0}));
  const std::vector<unsigned char> centre = FacesToMeasure(plane, texture, {4});
  EXPECT_EQ(std::count(centre.begin(), centre.end(), 1), 6);
  ExpectErrorMentions([&] { FacesToMeasure(plane, texture, {9}); }, {"out of range"});
}

TEST(FlowEvaluationTest, UntexturedFacesTakeTheFallbacksTexture) {
  const Mesh plane = FacingPlane(1.0, 2.0, 2);  // 9 vertices, 8 faces.
  const Camera camera = PinholeCamera(64, 50.0);
  const cv::Mat image = RandomTexture(64, 64);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(plane);
  std::vector<std::vector<unsigned char>> seen = {std::vector<unsigned char>(9, 1)};
  const ProjectiveTexture fallback = MakeProjectiveTexture(plane, normals, {camera}, {image}, seen);
  seen[0][8] = 0;  // Its one face (the last) goes untextured.
  ProjectiveTexture texture = MakeProjectiveTexture(plane, normals, {camera}, {image}, seen);
  ASSERT_FALSE(texture.textured[7]);
  const Eigen::Matrix2Xd before = texture.corner_uvs;
  FillUntexturedFaces(fallback, &texture);
  EXPECT_EQ(texture.textured, fallback.textured);
  EXPECT_EQ(texture.corner_uvs.rightCols<3>(), fallback.corner_uvs.rightCols<3>());
  EXPECT_EQ(texture.corner_uvs.leftCols(21), before.leftCols(21));  // Textured faces keep theirs.
  const Mesh other = FacingPlane(1.0, 2.0, 3);
  const ProjectiveTexture wrong =
      MakeProjectiveTexture(other, ComputeVertexNormals(other), {camera}, {image},
                            {std::vector<unsigned char>(other.num_vertices(), 1)});
  ExpectErrorMentions([&] { FillUntexturedFaces(wrong, &texture); }, {"another mesh"});
}

}  // namespace
}  // namespace finecap
