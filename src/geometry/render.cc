#include "finecap/geometry/render.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Geometry>

#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr char kWhere[] = "render";
// Rows of output pixels rendered together by one thread; small enough to balance the load over
// threads, large enough that a band holds many triangles.
constexpr int kBandPixelRows = 8;

// A triangle ready for rasterisation on the sample grid. Clipping may move its corners, so each
// corner carries its barycentric coordinates with respect to the original face.
struct RasterTriangle {
  int face = -1;
  std::array<Eigen::Vector2d, 3> pixel;
  std::array<double, 3> inverse_depth;
  std::array<Eigen::Vector3d, 3> barycentric;
};

struct ClipVertex {
  Eigen::Vector3d camera_point;
  Eigen::Vector3d barycentric;
};

// The visibility pass result for a band of sample rows [first_row, first_row + rows).
struct SampleBand {
  int width = 0;
  int first_row = 0;
  int rows = 0;
  std::vector<double> depth;
  std::vector<int> face;
  std::vector<Eigen::Vector3d> barycentric;

  void Reset(int band_width, int band_first_row, int band_rows) {
    width = band_width;
    first_row = band_first_row;
    rows = band_rows;
    const size_t size = static_cast<size_t>(width) * rows;
    depth.assign(size, std::numeric_limits<double>::infinity());
    face.assign(size, -1);
    barycentric.resize(size);
  }
  size_t Index(int x, int row) const { return static_cast<size_t>(row - first_row) * width + x; }
};

// Intrinsics that map onto a grid of s x s samples per pixel, sample centres at integer
// coordinates: pixel coordinate u becomes s * u + (s - 1) / 2.
Eigen::Matrix3d SampleGridIntrinsics(const Eigen::Matrix3d& K, int samples) {
  Eigen::Matrix3d grid = K;
  grid.topRows<2>() *= samples;
  grid(0, 2) += 0.5 * (samples - 1);
  grid(1, 2) += 0.5 * (samples - 1);
  return grid;
}

// Sutherland-Hodgman clipping of a triangle to z >= near. Returns the number of corners of the
// clipped polygon (0, 3 or 4) written to `out`.
int ClipToNearPlane(const std::array<ClipVertex, 3>& in, double near,
                    std::array<ClipVertex, 4>* out) {
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % 3];
    const bool a_inside = a.camera_point.z() >= near;
    const bool b_inside = b.camera_point.z() >= near;
    if (a_inside) (*out)[count++] = a;
    if (a_inside != b_inside) {
      const double s = (near - a.camera_point.z()) / (b.camera_point.z() - a.camera_point.z());
      (*out)[count++] = {a.camera_point + s * (b.camera_point - a.camera_point),
                         a.barycentric + s * (b.barycentric - a.barycentric)};
    }
  }
  return count;
}

void AppendRasterTriangles(int face, const std::array<ClipVertex, 3>& corners,
                           const Eigen::Matrix3d& K, double near,
                           std::vector<RasterTriangle>* triangles) {
  std::array<ClipVertex, 4> polygon;
  const int count = ClipToNearPlane(corners, near, &polygon);
  for (int fan = 1; fan + 1 < count; ++fan) {
    RasterTriangle triangle;
    triangle.face = face;
    const std::array<int, 3> picks = {0, fan, fan + 1};
    for (int c = 0; c < 3; ++c) {
      const ClipVertex& vertex = polygon[picks[c]];
      const Eigen::Vector3d projected = K * vertex.camera_point;
      triangle.pixel[c] = projected.head<2>() / projected.z();
      triangle.inverse_depth[c] = 1.0 / vertex.camera_point.z();
      triangle.barycentric[c] = vertex.barycentric;
    }
    triangles->push_back(triangle);
  }
}

std::vector<RasterTriangle> PrepareTriangles(const Camera& camera, const Eigen::Matrix3d& K,
                                             const Mesh& mesh, const RenderOptions& options) {
  const Eigen::Matrix3Xd camera_points = (camera.R * mesh.vertices).colwise() + camera.t;
  std::vector<RasterTriangle> triangles;
  triangles.reserve(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    std::array<ClipVertex, 3> corners;
    for (int c = 0; c < 3; ++c) {
      corners[c] = {camera_points.col(mesh.faces(c, f)), Eigen::Vector3d::Unit(c)};
    }
    if (options.cull_back_faces) {
      // The camera sits at the origin: the front side faces it when its normal points back at it.
      const Eigen::Vector3d normal = (corners[1].camera_point - corners[0].camera_point)
                                         .cross(corners[2].camera_point - corners[0].camera_point);
      if (normal.dot(corners[0].camera_point) >= 0.0) continue;
    }
    AppendRasterTriangles(f, corners, K, options.near_plane, &triangles);
  }
  return triangles;
}

double EdgeFunction(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double x, double y) {
  return (b.x() - a.x()) * (y - a.y()) - (b.y() - a.y()) * (x - a.x());
}

// Depth-tests every sample centre of `band` inside the triangle (edges included, so that shared
// edges leave no cracks).
void RasterizeIntoBand(const RasterTriangle& triangle, SampleBand* band) {
  const auto& p = triangle.pixel;
  const double area = EdgeFunction(p[0], p[1], p[2].x(), p[2].y());
  if (!(std::abs(area) > 1e-12)) return;
  const double inverse_area = 1.0 / area;
  const double min_x = std::min({p[0].x(), p[1].x(), p[2].x()});
  const double max_x = std::max({p[0].x(), p[1].x(), p[2].x()});
  const double min_y = std::min({p[0].y(), p[1].y(), p[2].y()});
  const double max_y = std::max({p[0].y(), p[1].y(), p[2].y()});
  const int x0 = std::max(0, static_cast<int>(std::ceil(std::max(min_x, -1.0))));
  const int x1 = std::min(band->width - 1, static_cast<int>(std::floor(std::min(max_x, 1e9))));
  const int y0 = std::max(band->first_row, static_cast<int>(std::ceil(std::max(min_y, -1.0))));
  const int y1 = std::min(band->first_row + band->rows - 1,
                          static_cast<int>(std::floor(std::min(max_y, 1e9))));
  // Screen-space barycentrics are affine in x: step them along the row.
  const std::array<double, 3> step_x = {-(p[2].y() - p[1].y()) * inverse_area,
                                        -(p[0].y() - p[2].y()) * inverse_area,
                                        -(p[1].y() - p[0].y()) * inverse_area};
  for (int y = y0; y <= y1; ++y) {
    std::array<double, 3> weight = {EdgeFunction(p[1], p[2], x0, y) * inverse_area,
                                    EdgeFunction(p[2], p[0], x0, y) * inverse_area,
                                    EdgeFunction(p[0], p[1], x0, y) * inverse_area};
    for (int x = x0; x <= x1; ++x) {
      if (weight[0] >= 0.0 && weight[1] >= 0.0 && weight[2] >= 0.0) {
        const std::array<double, 3> perspective = {weight[0] * triangle.inverse_depth[0],
                                                   weight[1] * triangle.inverse_depth[1],
                                                   weight[2] * triangle.inverse_depth[2]};
        const double inverse_depth = perspective[0] + perspective[1] + perspective[2];
        const double depth = 1.0 / inverse_depth;
        const size_t index = band->Index(x, y);
        if (depth < band->depth[index]) {
          band->depth[index] = depth;
          band->face[index] = triangle.face;
          band->barycentric[index] =
              (perspective[0] * triangle.barycentric[0] + perspective[1] * triangle.barycentric[1] +
               perspective[2] * triangle.barycentric[2]) *
              depth;
        }
      }
      for (int c = 0; c < 3; ++c) weight[c] += step_x[c];
    }
  }
}

// Rasterises `triangles` onto a width x height sample grid, band by band in parallel, and hands
// each finished band to `resolve` (called concurrently for different bands).
template <typename Resolve>
void RasterizeBands(const std::vector<RasterTriangle>& triangles, int width, int height,
                    int band_rows, const Resolve& resolve) {
  const int num_bands = (height + band_rows - 1) / band_rows;
  std::vector<std::vector<int>> bins(num_bands);
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    const auto& p = triangles[t].pixel;
    const double min_y = std::min({p[0].y(), p[1].y(), p[2].y()});
    const double max_y = std::max({p[0].y(), p[1].y(), p[2].y()});
    if (!(max_y >= 0.0) || !(min_y <= height - 1.0)) continue;
    // Clamp before converting: a triangle near the near plane can reach far off screen.
    const int first = static_cast<int>(std::ceil(std::max(min_y, 0.0))) / band_rows;
    const int last = static_cast<int>(std::floor(std::min(max_y, height - 1.0))) / band_rows;
    for (int b = first; b <= last; ++b) bins[b].push_back(t);
  }
#pragma omp parallel
  {
    SampleBand band;
#pragma omp for schedule(dynamic)
    for (int b = 0; b < num_bands; ++b) {
      band.Reset(width, b * band_rows, std::min(band_rows, height - b * band_rows));
      for (int t : bins[b]) RasterizeIntoBand(triangles[t], &band);
      resolve(band);
    }
  }
}

void ValidateInputs(const Camera& camera, const Mesh& mesh, const RenderOptions& options) {
  camera.Validate(kWhere);
  mesh.Validate(kWhere);
  options.Check();
}

// Colour of one visible sample, RGB in [0, 1], before shading.
class Painter {
 public:
  Painter(const Mesh& mesh, const SurfaceAppearance& appearance)
      : mesh_(mesh), appearance_(appearance) {}

  Eigen::Vector3d Albedo(int face, const Eigen::Vector3d& barycentric) const {
    if (appearance_.vertex_colors.cols() > 0) {
      Eigen::Vector3d color = Eigen::Vector3d::Zero();
      for (int c = 0; c < 3; ++c) {
        color += barycentric(c) * appearance_.vertex_colors.col(mesh_.faces(c, face));
      }
      return color;
    }
    const Eigen::Vector2d uv = appearance_.corner_uvs.middleCols<3>(3 * face) * barycentric;
    return SampleTexture(uv);
  }

 private:
  Eigen::Vector3d SampleTexture(const Eigen::Vector2d& uv) const {
    const cv::Mat& texture = appearance_.texture;
    const double x = uv.x() * texture.cols - 0.5;
    const double y = uv.y() * texture.rows - 0.5;
    const double fx = std::floor(x);
    const double fy = std::floor(y);
    const double ax = x - fx;
    const double ay = y - fy;
    const int x0 = Wrap(static_cast<long>(fx), texture.cols);
    const int y0 = Wrap(static_cast<long>(fy), texture.rows);
    const int x1 = (x0 + 1) % texture.cols;
    const int y1 = (y0 + 1) % texture.rows;
    const cv::Vec3b& c00 = texture.at<cv::Vec3b>(y0, x0);
    const cv::Vec3b& c01 = texture.at<cv::Vec3b>(y0, x1);
    const cv::Vec3b& c10 = texture.at<cv::Vec3b>(y1, x0);
    const cv::Vec3b& c11 = texture.at<cv::Vec3b>(y1, x1);
    Eigen::Vector3d rgb;
    for (int channel = 0; channel < 3; ++channel) {
      const int bgr = 2 - channel;
      rgb(channel) = ((1 - ay) * ((1 - ax) * c00[bgr] + ax * c01[bgr]) +
                      ay * ((1 - ax) * c10[bgr] + ax * c11[bgr])) /
                     255.0;
    }
    return rgb;
  }
  static int Wrap(long i, int n) { return static_cast<int>(((i % n) + n) % n); }

  const Mesh& mesh_;
  const SurfaceAppearance& appearance_;
};

void CheckAppearance(const Mesh& mesh, const SurfaceAppearance& appearance) {
  const bool by_vertex = appearance.vertex_colors.cols() > 0;
  const bool by_texture = appearance.corner_uvs.cols() > 0;
  Require(by_vertex != by_texture, kWhere,
          "give exactly one of per-vertex colours or corner UVs with a texture");
  if (by_vertex) {
    Require(appearance.vertex_colors.cols() == mesh.num_vertices(), kWhere,
            "the number of vertex colours differs from the number of vertices");
    return;
  }
  Require(appearance.corner_uvs.cols() == 3 * mesh.num_faces(), kWhere,
          "there must be one UV per triangle corner (3 per face)");
  Require(appearance.corner_uvs.allFinite(), kWhere, "a UV coordinate is not finite");
  Require(!appearance.texture.empty() && appearance.texture.type() == CV_8UC3, kWhere,
          "the texture must be a non-empty 8-bit 3-channel image");
}

// Multiplies the albedo by the Lambertian term of the interpolated normal, turned to the camera.
class Shader {
 public:
  Shader(const Camera& camera, const Mesh& mesh, const RenderOptions& options)
      : options_(options), light_(options.light_direction.normalized()), center_(camera.Center()) {
    if (options.shade) normals_ = ComputeVertexNormals(mesh);
  }

  Eigen::Vector3d Shade(const Mesh& mesh, int face, const Eigen::Vector3d& barycentric,
                        const Eigen::Vector3d& albedo) const {
    if (!options_.shade) return albedo;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    for (int c = 0; c < 3; ++c) {
      normal += barycentric(c) * normals_.col(mesh.faces(c, face));
      point += barycentric(c) * mesh.vertices.col(mesh.faces(c, face));
    }
    if (normal.dot(point - center_) > 0.0) normal = -normal;
    const double length = normal.norm();
    const double lambert = length > 0.0 ? std::max(0.0, normal.dot(light_) / length) : 0.0;
    return albedo * (options_.ambient + options_.diffuse * lambert);
  }

 private:
  const RenderOptions& options_;
  Eigen::Vector3d light_;
  Eigen::Vector3d center_;
  Eigen::Matrix3Xd normals_;
};

// Writes one output pixel: the mean of its samples, RGB in [0, 1], rounded and saturated to
// 8-bit BGR.
void WritePixel(const Eigen::Vector3f& mean_rgb, cv::Vec3b* bgr) {
  for (int channel = 0; channel < 3; ++channel) {
    (*bgr)[2 - channel] = cv::saturate_cast<uchar>(255.0f * mean_rgb(channel));
  }
}

}  // namespace

const OptionFields<RenderOptions>& RenderOptions::Fields() {
  static const OptionFields<RenderOptions> fields = [] {
    OptionFields<RenderOptions> f;
    f.AddInt("supersampling", &RenderOptions::supersampling,
             "Samples per pixel along each axis (anti-aliasing).", 1, 16);
    f.AddBool("cull_back_faces", &RenderOptions::cull_back_faces,
              "Skip triangles facing away from the camera (false: the inside of an open surface "
              "shows).");
    f.AddDouble("near_plane", &RenderOptions::near_plane,
                "Camera z of the near clipping plane, m (> 0).", 1e-9);
    f.AddBool("shade", &RenderOptions::shade,
              "Lambertian shading: colour * (ambient + diffuse * max(0, n . l)).");
    f.AddDouble("ambient", &RenderOptions::ambient, "Ambient term of the shading.", 0.0);
    f.AddDouble("diffuse", &RenderOptions::diffuse, "Diffuse term of the shading.", 0.0);
    f.AddCustom("light_direction",
                "Direction towards the light, world coordinates; non-zero, any length.");
    f.AddCustom("background", "Colour of pixels that see no surface, RGB in [0, 1].", 0.0, 1.0);
    f.AddDouble("noise_sigma", &RenderOptions::noise_sigma,
                "Standard deviation of Gaussian sensor noise, 8-bit grey levels.", 0.0, 255.0);
    f.AddCustom("noise_seed",
                "Mixed with synth.seed, the frame and the camera into each image's noise seed.");
    return f;
  }();
  return fields;
}

void RenderOptions::Check() const {
  const std::string where = "RenderOptions::";
  Fields().CheckValues(*this, where);
  Require(light_direction.allFinite() && light_direction.norm() > 0.0, where + "light_direction",
          "must be a finite non-zero vector");
  internal::CheckDeclaredNumbers(background.data(), 3, Fields().Field("background"),
                                 where + "background");
}

DepthMap RenderDepth(const Camera& camera, const Mesh& mesh, const RenderOptions& options) {
  ValidateInputs(camera, mesh, options);
  const std::vector<RasterTriangle> triangles = PrepareTriangles(camera, camera.K, mesh, options);
  DepthMap map;
  map.depth.create(camera.height, camera.width, CV_32F);
  map.triangle_ids.create(camera.height, camera.width, CV_32S);
  RasterizeBands(triangles, camera.width, camera.height, kBandPixelRows,
                 [&](const SampleBand& band) {
                   for (int y = band.first_row; y < band.first_row + band.rows; ++y) {
                     float* depth = map.depth.ptr<float>(y);
                     int* ids = map.triangle_ids.ptr<int>(y);
                     for (int x = 0; x < band.width; ++x) {
                       depth[x] = static_cast<float>(band.depth[band.Index(x, y)]);
                       ids[x] = band.face[band.Index(x, y)];
                     }
                   }
                 });
  return map;
}

cv::Mat RenderColor(const Camera& camera, const Mesh& mesh, const SurfaceAppearance& appearance,
                    const RenderOptions& options) {
  ValidateInputs(camera, mesh, options);
  CheckAppearance(mesh, appearance);
  const int s = options.supersampling;
  const std::vector<RasterTriangle> triangles =
      PrepareTriangles(camera, SampleGridIntrinsics(camera.K, s), mesh, options);
  const Painter painter(mesh, appearance);
  const Shader shader(camera, mesh, options);
  const Eigen::Vector3f background = options.background.cast<float>();
  cv::Mat image(camera.height, camera.width, CV_8UC3);
  const float inverse_samples = 1.0f / (s * s);
  RasterizeBands(
      triangles, camera.width * s, camera.height * s, kBandPixelRows * s,
      [&](const SampleBand& band) {
        for (int y = band.first_row / s; y < (band.first_row + band.rows) / s; ++y) {
          cv::Vec3b* row = image.ptr<cv::Vec3b>(y);
          for (int x = 0; x < camera.width; ++x) {
            Eigen::Vector3f sum = Eigen::Vector3f::Zero();
            for (int sy = y * s; sy < (y + 1) * s; ++sy) {
              for (int sx = x * s; sx < (x + 1) * s; ++sx) {
                const size_t index = band.Index(sx, sy);
                const int face = band.face[index];
                if (face < 0) {
                  sum += background;
                  continue;
                }
                const Eigen::Vector3d& barycentric = band.barycentric[index];
                sum += shader.Shade(mesh, face, barycentric, painter.Albedo(face, barycentric))
                           .cast<float>();
              }
            }
            WritePixel(sum * inverse_samples, &row[x]);
          }
        }
      });
  AddSensorNoise(options.noise_sigma, options.noise_seed, &image);
  return image;
}

void AddSensorNoise(double sigma, std::uint64_t seed, cv::Mat* image) {
  Require(std::isfinite(sigma) && sigma >= 0.0, kWhere, "the noise sigma must be >= 0");
  Require(image->depth() == CV_8U, kWhere, "sensor noise needs an 8-bit image");
  if (sigma == 0.0) return;
  const int values_per_row = image->cols * image->channels();
#pragma omp parallel for
  for (int y = 0; y < image->rows; ++y) {
    // One generator per row: the noise does not depend on how rows are shared among threads.
    cv::RNG rng(seed * 1000003ull + y + 1);
    uchar* row = image->ptr<uchar>(y);
    for (int i = 0; i < values_per_row; ++i) {
      row[i] = cv::saturate_cast<uchar>(row[i] + rng.gaussian(sigma));
    }
  }
}

cv::Mat RenderNormals(const Camera& camera, const Mesh& mesh, const RenderOptions& options) {
  RenderOptions plain = options;
  plain.shade = false;
  plain.noise_sigma = 0.0;
  SurfaceAppearance appearance;
  // (n + 1) / 2 is affine in n, so interpolating the mapped colour maps the interpolated normal.
  appearance.vertex_colors = ((camera.R * ComputeVertexNormals(mesh)).array() + 1.0) * 0.5;
  return RenderColor(camera, mesh, appearance, plain);
}

}  // namespace finecap
