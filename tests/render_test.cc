#include "finecap/geometry/render.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "finecap/util/error.h"
#include "test_meshes.h"

namespace finecap {
namespace {

Camera MakeCamera(int width, int height, double focal) {
  Camera camera;
  camera.name = "test";
  camera.width = width;
  camera.height = height;
  camera.K << focal, 0.0, 0.5 * (width - 1) + 0.3, 0.0, focal * 1.02, 0.5 * (height - 1) - 0.2, 0.0,
      0.0, 1.0;
  return camera;
}

// A camera at `center` looking at `target`, image y pointing along -`up`.
Camera LookAt(Camera camera, const Eigen::Vector3d& center, const Eigen::Vector3d& target,
              const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - center).normalized();
  const Eigen::Vector3d x = z.cross(up).normalized();
  camera.R.row(0) = x;
  camera.R.row(1) = z.cross(x);
  camera.R.row(2) = z;
  camera.t = -camera.R * center;
  return camera;
}

// Two triangles a-b-c, a-c-d.
Mesh MakeQuad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
              const Eigen::Vector3d& d) {
  Mesh mesh;
  mesh.vertices.resize(3, 4);
  mesh.vertices << a, b, c, d;
  mesh.faces.resize(3, 2);
  mesh.faces << 0, 0, 1, 2, 2, 3;
  return mesh;
}

// World point where the ray through pixel (x, y) of `camera` meets the plane n . X = offset.
Eigen::Vector3d RayPlaneHit(const Camera& camera, double x, double y, const Eigen::Vector3d& n,
                            double offset) {
  const Eigen::Vector3d direction =
      camera.R.transpose() * (camera.K.inverse() * Eigen::Vector3d(x, y, 1.0));
  const Eigen::Vector3d center = camera.Center();
  return center + (offset - n.dot(center)) / n.dot(direction) * direction;
}

RenderOptions Plain() {
  RenderOptions options;
  options.supersampling = 1;
  return options;
}

TEST(RenderTest, DepthOfTiltedPlaneMatchesRayIntersection) {
  const Camera camera = MakeCamera(160, 120, 150.0);
  // Plane z = 2 + 0.4 x, much larger than the view.
  auto on_plane = [](double x, double y) { return Eigen::Vector3d(x, y, 2.0 + 0.4 * x); };
  const Mesh plane = MakeQuad(on_plane(-3, -3), on_plane(-3, 3), on_plane(3, 3), on_plane(3, -3));
  const DepthMap map = RenderDepth(camera, plane);
  const Eigen::Vector3d normal = Eigen::Vector3d(-0.4, 0.0, 1.0);
  for (int y = 0; y < camera.height; y += 7) {
    for (int x = 0; x < camera.width; x += 5) {
      ASSERT_GE(map.triangle_ids.at<int>(y, x), 0) << x << "," << y;
      const Eigen::Vector3d hit = RayPlaneHit(camera, x, y, normal, 2.0);
      EXPECT_NEAR(map.depth.at<float>(y, x), camera.Depth(hit), 1e-5) << x << "," << y;
    }
  }
}

TEST(RenderTest, DepthOfSphereMatchesAnalyticIntersection) {
  const Camera camera = LookAt(MakeCamera(200, 200, 300.0), Eigen::Vector3d(0.3, -0.2, 0.0),
                               Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d(0, -1, 0));
  const Eigen::Vector3d center(0.0, 0.0, 3.0);
  const double radius = 0.5;
  const Mesh sphere = testing_meshes::SphereMesh(center, radius, 200, 400);
  const DepthMap map = RenderDepth(camera, sphere);
  int checked = 0;
  for (int y = 0; y < camera.height; y += 3) {
    for (int x = 0; x < camera.width; x += 3) {
      const Eigen::Vector3d direction =
          (camera.R.transpose() * (camera.K.inverse() * Eigen::Vector3d(x, y, 1.0))).normalized();
      const Eigen::Vector3d to_center = center - camera.Center();
      const double along = direction.dot(to_center);
      const double miss2 = to_center.squaredNorm() - along * along;
      if (miss2 > radius * radius * 0.8) continue;  // Keep away from the grazing silhouette.
      const Eigen::Vector3d hit =
          camera.Center() + (along - std::sqrt(radius * radius - miss2)) * direction;
      ASSERT_GE(map.triangle_ids.at<int>(y, x), 0);
      EXPECT_NEAR(map.depth.at<float>(y, x), camera.Depth(hit), 2e-4) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_TRUE(std::isinf(map.depth.at<float>(0, 0)));
  EXPECT_EQ(map.triangle_ids.at<int>(0, 0), -1);
}

TEST(RenderTest, VertexIsDrawnWhereCameraProjectPutsIt) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Camera camera = LookAt(
        MakeCamera(120, 100, 130.0), Eigen::Vector3d(jitter(rng), jitter(rng), -2.0),
        Eigen::Vector3d(0.2 * jitter(rng), 0.2 * jitter(rng), 0.0), Eigen::Vector3d::UnitY());
    // A fan of six triangles around vertex 0, in a random plane through a random point.
    const Eigen::Vector3d hub(0.3 * jitter(rng), 0.3 * jitter(rng), 0.3 * jitter(rng));
    const Eigen::Matrix3d frame =
        Eigen::AngleAxisd(0.5 * jitter(rng),
                          Eigen::Vector3d(jitter(rng), jitter(rng), 1.0).normalized())
            .toRotationMatrix();
    Mesh fan;
    fan.vertices.resize(3, 7);
    fan.vertices.col(0) = hub;
    fan.faces.resize(3, 6);
    for (int k = 0; k < 6; ++k) {
      const double angle = M_PI / 3.0 * k;
      fan.vertices.col(k + 1) =
          hub + frame * Eigen::Vector3d(0.1 * std::cos(angle), 0.1 * std::sin(angle), 0.0);
      fan.faces.col(k) << 0, k + 1, (k + 1) % 6 + 1;
    }
    const Eigen::Vector2d pixel = camera.Project(hub);
    const int x = static_cast<int>(std::lround(pixel.x()));
    const int y = static_cast<int>(std::lround(pixel.y()));
    const DepthMap map = RenderDepth(camera, fan);
    // Independently: the sector of the fan that the pixel centre's ray meets.
    const Eigen::Vector3d normal = frame.col(2);
    const Eigen::Vector3d local =
        frame.transpose() * (RayPlaneHit(camera, x, y, normal, normal.dot(hub)) - hub);
    double angle = std::atan2(local.y(), local.x());
    if (angle < 0) angle += 2.0 * M_PI;
    const int sector = static_cast<int>(angle / (M_PI / 3.0));
    const double within = angle - sector * M_PI / 3.0;
    if (within < 1e-3 || within > M_PI / 3.0 - 1e-3) continue;  // On a shared edge: either wins.
    EXPECT_EQ(map.triangle_ids.at<int>(y, x), sector) << "trial " << trial;
    ++checked;
  }
  EXPECT_GT(checked, 15);
}

TEST(RenderTest, NearerTriangleOccludesWhateverTheOrder) {
  const Camera camera = MakeCamera(64, 64, 60.0);
  auto square = [](double z) {
    return MakeQuad(Eigen::Vector3d(-1, -1, z), Eigen::Vector3d(-1, 1, z), Eigen::Vector3d(1, 1, z),
                    Eigen::Vector3d(1, -1, z));
  };
  const Mesh near = square(2.0);
  const Mesh far = square(3.0);
  for (bool near_first : {true, false}) {
    Mesh both;
    const Mesh& first = near_first ? near : far;
    const Mesh& second = near_first ? far : near;
    both.vertices.resize(3, 8);
    both.vertices << first.vertices, second.vertices;
    both.faces.resize(3, 4);
    both.faces << first.faces, (second.faces.array() + 4).matrix();
    const DepthMap map = RenderDepth(camera, both);
    const int expected_first_face = near_first ? 0 : 2;
    const int id = map.triangle_ids.at<int>(32, 32);
    EXPECT_TRUE(id == expected_first_face || id == expected_first_face + 1) << id;
    EXPECT_NEAR(map.depth.at<float>(32, 32), 2.0, 1e-6);
  }
}

TEST(RenderTest, TriangleCrossingTheNearPlaneIsClipped) {
  const Camera camera = MakeCamera(80, 60, 70.0);
  // The floor y = 0.5 running from behind the camera to far ahead.
  Mesh floor = MakeQuad(Eigen::Vector3d(-50, 0.5, -5), Eigen::Vector3d(-50, 0.5, 20),
                        Eigen::Vector3d(50, 0.5, 20), Eigen::Vector3d(50, 0.5, -5));
  const DepthMap map = RenderDepth(camera, floor);
  int drawn = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.K.inverse() * Eigen::Vector3d(x, y, 1.0);
      const bool sees_floor = ray.y() > 0.5 / 20.0 + 1e-3;
      if (ray.y() > 0.5 / 20.0 - 1e-3 && !sees_floor) continue;  // The far edge.
      ASSERT_EQ(map.triangle_ids.at<int>(y, x) >= 0, sees_floor) << x << "," << y;
      if (!sees_floor) continue;
      EXPECT_NEAR(map.depth.at<float>(y, x), 0.5 / ray.y(), 1e-4);
      ++drawn;
    }
  }
  EXPECT_GT(drawn, 1000);
}

TEST(RenderTest, BackFacesAreCulledOnlyOnRequest) {
  const Camera camera = MakeCamera(32, 32, 30.0);
  // Counter-clockwise seen from +z: its front faces away from the camera at the origin.
  const Mesh away = MakeQuad(Eigen::Vector3d(-1, -1, 2), Eigen::Vector3d(1, -1, 2),
                             Eigen::Vector3d(1, 1, 2), Eigen::Vector3d(-1, 1, 2));
  RenderOptions options;
  EXPECT_GE(RenderDepth(camera, away, options).triangle_ids.at<int>(16, 16), 0);
  options.cull_back_faces = true;
  EXPECT_EQ(RenderDepth(camera, away, options).triangle_ids.at<int>(16, 16), -1);
  const Mesh toward = MakeQuad(Eigen::Vector3d(-1, -1, 2), Eigen::Vector3d(-1, 1, 2),
                               Eigen::Vector3d(1, 1, 2), Eigen::Vector3d(1, -1, 2));
  EXPECT_GE(RenderDepth(camera, toward, options).triangle_ids.at<int>(16, 16), 0);
}

cv::Mat MakeChecker(int cells, int cell_size) {
  cv::Mat texture(cells * cell_size, cells * cell_size, CV_8UC3);
  for (int y = 0; y < texture.rows; ++y) {
    for (int x = 0; x < texture.cols; ++x) {
      const bool white = ((x / cell_size) + (y / cell_size)) % 2 == 0;
      texture.at<cv::Vec3b>(y, x) = white ? cv::Vec3b(255, 255, 255) : cv::Vec3b(0, 0, 0);
    }
  }
  return texture;
}

TEST(RenderTest, TextureIsInterpolatedPerspectiveCorrectly) {
  const Camera camera = MakeCamera(200, 200, 180.0);
  // A square strongly tilted away from the camera: u runs along x, v along the receding depth.
  const Eigen::Vector3d origin(-0.8, 0.3, 1.2);
  const Eigen::Vector3d u_axis(1.6, 0.0, 0.0);
  const Eigen::Vector3d v_axis(0.0, -1.2, 4.0);
  const Mesh quad = MakeQuad(origin, origin + u_axis, origin + u_axis + v_axis, origin + v_axis);
  SurfaceAppearance appearance;
  appearance.corner_uvs.resize(2, 6);
  appearance.corner_uvs << 0, 1, 1, 0, 1, 0,  //
      0, 0, 1, 0, 1, 1;
  const int cells = 8;
  const int cell_size = 16;
  appearance.texture = MakeChecker(cells, cell_size);
  const cv::Mat image = RenderColor(camera, quad, appearance, Plain());
  const Eigen::Vector3d normal = u_axis.cross(v_axis).normalized();
  int checked = 0;
  int affine_would_fail = 0;
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d local = RayPlaneHit(camera, x, y, normal, normal.dot(origin)) - origin;
      const double u = local.dot(u_axis) / u_axis.squaredNorm();
      const double v = local.dot(v_axis) / v_axis.squaredNorm();
      if (u < 0.01 || u > 0.99 || v < 0.01 || v > 0.99) continue;
      const double tu = u * cells * cell_size;
      const double tv = v * cells * cell_size;
      const auto near_edge = [&](double t) {
        const double r = std::fmod(t, cell_size);
        return r < 1.5 || r > cell_size - 1.5;
      };
      if (near_edge(tu) || near_edge(tv)) continue;
      const bool white =
          (static_cast<int>(tu / cell_size) + static_cast<int>(tv / cell_size)) % 2 == 0;
      ASSERT_EQ(image.at<cv::Vec3b>(y, x)[1], white ? 255 : 0) << x << "," << y;
      ++checked;
      // Screen-space (affine) interpolation along v would pick a different row of cells here.
      const double v_near = camera.Project(origin).y();
      const double v_far = camera.Project(origin + v_axis).y();
      const double affine_v = (y - v_near) / (v_far - v_near);
      if (std::abs(affine_v - v) * cells > 1.0) ++affine_would_fail;
    }
  }
  EXPECT_GT(checked, 2000);
  EXPECT_GT(affine_would_fail, 500);
}

TEST(RenderTest, SupersamplingAveragesCoverage) {
  const Camera camera = MakeCamera(40, 40, 40.0);
  // A white square whose left edge crosses pixel column 25 through its centre.
  const double edge_x = (25.0 - camera.K(0, 2)) / camera.K(0, 0) * 2.0;
  const Mesh square = MakeQuad(Eigen::Vector3d(edge_x, -5, 2), Eigen::Vector3d(edge_x, 5, 2),
                               Eigen::Vector3d(5, 5, 2), Eigen::Vector3d(5, -5, 2));
  SurfaceAppearance white;
  white.vertex_colors = Eigen::Matrix3Xd::Ones(3, 4);
  RenderOptions options;
  options.supersampling = 4;
  const cv::Mat image = RenderColor(camera, square, white, options);
  EXPECT_NEAR(image.at<cv::Vec3b>(20, 25)[0], 127.5, 1.0);
  EXPECT_EQ(image.at<cv::Vec3b>(20, 27)[0], 255);
  EXPECT_EQ(image.at<cv::Vec3b>(20, 23)[0], 0);
}

Mesh FacingSquare(double z) {
  return MakeQuad(Eigen::Vector3d(-5, -5, z), Eigen::Vector3d(-5, 5, z), Eigen::Vector3d(5, 5, z),
                  Eigen::Vector3d(5, -5, z));
}

TEST(RenderTest, LambertianShadingFollowsTheLightAngle) {
  const Camera camera = MakeCamera(16, 16, 20.0);
  SurfaceAppearance grey;
  grey.vertex_colors = Eigen::Matrix3Xd::Constant(3, 4, 0.8);
  RenderOptions options = Plain();
  options.shade = true;
  options.ambient = 0.2;
  options.diffuse = 0.7;
  options.light_direction = Eigen::Vector3d(0.0, 1.0, -1.0);  // 45 degrees off the normal.
  const cv::Mat image = RenderColor(camera, FacingSquare(2.0), grey, options);
  const double expected = 255.0 * 0.8 * (0.2 + 0.7 * std::cos(M_PI / 4.0));
  EXPECT_NEAR(image.at<cv::Vec3b>(8, 8)[2], expected, 0.51);
}

TEST(RenderTest, NormalsAreColourCodedInCameraSpace) {
  Camera camera = MakeCamera(16, 16, 20.0);
  // Rotating the camera must not change the colour: the normal is expressed in its coordinates.
  camera.R = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Mesh square = FacingSquare(2.0);
  const cv::Mat image = RenderNormals(camera, square, Plain());
  const Eigen::Vector3d normal = camera.R * Eigen::Vector3d(0, 0, -1);
  const cv::Vec3b bgr = image.at<cv::Vec3b>(8, 8);
  for (int channel = 0; channel < 3; ++channel) {
    EXPECT_NEAR(bgr[2 - channel], 255.0 * (normal(channel) + 1.0) / 2.0, 0.51);
  }
}

TEST(RenderTest, SensorNoiseHasTheRequestedSpreadAndIsRepeatable) {
  const Camera camera = MakeCamera(128, 128, 100.0);
  SurfaceAppearance grey;
  grey.vertex_colors = Eigen::Matrix3Xd::Constant(3, 4, 0.5);
  RenderOptions options = Plain();
  options.noise_sigma = 4.0;
  options.noise_seed = 11;
  const cv::Mat a = RenderColor(camera, FacingSquare(2.0), grey, options);
  const cv::Mat b = RenderColor(camera, FacingSquare(2.0), grey, options);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  options.noise_sigma = 0.0;
  const cv::Mat clean = RenderColor(camera, FacingSquare(2.0), grey, options);
  cv::Mat difference;
  cv::subtract(a, clean, difference, cv::noArray(), CV_32FC3);
  cv::Scalar mean, stddev;
  cv::meanStdDev(difference.reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 0.0, 0.1);
  EXPECT_NEAR(stddev[0], 4.0, 0.2);
}

TEST(RenderTest, BadInputIsRefusedWithAReason) {
  const Camera camera = MakeCamera(16, 16, 20.0);
  const Mesh square = FacingSquare(2.0);
  RenderOptions options;
  options.supersampling = 0;
  try {
    RenderDepth(camera, square, options);
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("supersampling"), std::string::npos);
  }
  SurfaceAppearance wrong;
  wrong.vertex_colors = Eigen::Matrix3Xd::Ones(3, 3);
  try {
    RenderColor(camera, square, wrong);
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("number of vertex colours"), std::string::npos);
  }
  SurfaceAppearance no_texture;
  no_texture.corner_uvs = Eigen::Matrix2Xd::Zero(2, 6);
  EXPECT_THROW(RenderColor(camera, square, no_texture), Error);
}

}  // namespace
}  // namespace finecap
