#include "finecap/model/surface_gaussians.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "finecap/model/visibility.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "model/image_color.h"
#include "model/surface_projection.h"

namespace finecap {
namespace {

// Mean of the pixels of `image` (CV_32FC3) under a Gaussian of standard deviation `sigma` pixels
// centred at `mean`, weighted by the Gaussian, out to two standard deviations.
bool GaussianWeightedMean(const cv::Mat& image, const Eigen::Vector2d& mean, double sigma,
                          Eigen::Vector3f* color) {
  const double radius = std::max(2.0 * sigma, 1.0);
  const int x0 = std::max(0, static_cast<int>(std::floor(mean.x() - radius)));
  const int x1 = std::min(image.cols - 1, static_cast<int>(std::ceil(mean.x() + radius)));
  const int y0 = std::max(0, static_cast<int>(std::floor(mean.y() - radius)));
  const int y1 = std::min(image.rows - 1, static_cast<int>(std::ceil(mean.y() + radius)));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  for (int y = y0; y <= y1; ++y) {
    const cv::Vec3f* row = image.ptr<cv::Vec3f>(y);
    for (int x = x0; x <= x1; ++x) {
      const double d2 = (Eigen::Vector2d(x, y) - mean).squaredNorm();
      if (d2 > radius * radius) continue;
      const double weight = std::exp(-0.5 * d2 / (sigma * sigma));
      sum += weight * Eigen::Vector3d(row[x][0], row[x][1], row[x][2]);
      weight_sum += weight;
    }
  }
  if (weight_sum <= 0.0) return false;
  *color = (sum / weight_sum).cast<float>();
  return true;
}

// The paper's colouring skeleton: for each vertex the best-aligned camera that sees it, where
// `sample(camera, vertex, projected, &colour)` reads the colour.
template <typename Sample>
ReferenceColors ColorFromBestCameras(const Eigen::Matrix3Xd& vertices,
                                     const Eigen::Matrix3Xd& normals,
                                     const std::vector<Camera>& cameras,
                                     const std::vector<std::vector<unsigned char>>& visible,
                                     ColorSpace color_space, double sigma_hat,
                                     const Sample& sample) {
  ReferenceColors result;
  result.color_space = color_space;
  result.sigma_hat = sigma_hat;
  const int n = static_cast<int>(vertices.cols());
  result.colors.assign(n, Eigen::Vector3f::Zero());
  result.valid.assign(n, 0);
#pragma omp parallel for schedule(dynamic, 256)
  for (int v = 0; v < n; ++v) {
    const int c = MostFrontalCamera(vertices.col(v), normals.col(v), cameras,
                                    [&](int camera) { return visible[camera][v] != 0; });
    if (c < 0) continue;
    const ProjectedGaussian projected =
        ProjectSurfaceGaussian(cameras[c], vertices.col(v), normals.col(v), 0.0, sigma_hat);
    result.valid[v] = sample(c, projected, &result.colors[v]);
  }
  return result;
}

}  // namespace

ReferenceColors ComputeReferenceColors(const Eigen::Matrix3Xd& vertices,
                                       const Eigen::Matrix3Xd& normals,
                                       const std::vector<Camera>& cameras,
                                       const std::vector<cv::Mat>& images,
                                       const std::vector<std::vector<unsigned char>>& visible,
                                       ColorSpace color_space, double sigma_hat) {
  std::vector<cv::Mat> converted(images.size());
  for (size_t c = 0; c < images.size(); ++c) {
    converted[c] = ConvertImage(images[c], color_space, cameras[c].name);
  }
  return ColorFromBestCameras(
      vertices, normals, cameras, visible, color_space, sigma_hat,
      [&](int c, const ProjectedGaussian& projected, Eigen::Vector3f* color) {
        return GaussianWeightedMean(converted[c], projected.mean, projected.sigma, color);
      });
}

ReferenceColors ComputeModelReferenceColors(const Eigen::Matrix3Xd& vertices,
                                            const Eigen::Matrix3Xd& normals,
                                            const std::vector<Camera>& cameras,
                                            const std::vector<ImageGaussians>& images,
                                            const std::vector<std::vector<unsigned char>>& visible,
                                            double sigma_hat, OverlapForm form,
                                            double reach_sigmas) {
  ReferenceColors colors = ColorFromBestCameras(
      vertices, normals, cameras, visible, images.front().color_space(), sigma_hat,
      [&](int c, const ProjectedGaussian& projected, Eigen::Vector3f* color) {
        *color = ImageColorAround(images[c], projected, form, reach_sigmas).cast<float>();
        return true;
      });
  colors.method = ReferenceColorSource::kImageModel;
  return colors;
}

void WriteReferenceColors(const std::string& path, const ReferenceColors& colors) {
  std::ostringstream text;
  text
      << "# finecap reference colours: one line per mesh vertex, 'valid c0 c1 c2' with the colour\n"
      << "# embedded in the colour space below (docs/method.md); valid = 0 where no camera saw\n"
      << "# the vertex in the reference frame.\n"
      << "color_space " << ColorSpaceName(colors.color_space) << "\n"
      << std::setprecision(9) << "sigma_hat " << colors.sigma_hat << "\n"
      << "method " << EnumToString(colors.method) << "\n";
  if (!colors.recipe.empty()) text << "recipe " << colors.recipe << "\n";
  text << "vertices " << colors.colors.size() << "\n";
  for (size_t v = 0; v < colors.colors.size(); ++v) {
    const Eigen::Vector3f& c = colors.colors[v];
    text << int(colors.valid[v]) << " " << c(0) << " " << c(1) << " " << c(2) << "\n";
  }
  WriteTextFileAtomically(path, text.str());
}

ReferenceColors ReadReferenceColors(const std::string& path, int expected_vertices) {
  std::ifstream stream(path);
  Require(stream.is_open(), path, "cannot open the reference colours");
  std::string line, word, space_name;
  ReferenceColors colors;
  int count = -1;
  const auto next_line = [&] {
    while (std::getline(stream, line) && (line.empty() || line[0] == '#')) {
    }
  };
  const auto read_header = [&](const std::string& key, auto* value, bool read_line = true) {
    if (read_line) next_line();
    std::istringstream fields(line);
    Require(static_cast<bool>(fields >> word >> *value) && word == key, path,
            "expected '" + key + " <value>', got '" + line + "'");
  };
  read_header("color_space", &space_name);
  colors.color_space = ParseColorSpace(space_name, path);
  read_header("sigma_hat", &colors.sigma_hat);
  std::string method_name;
  read_header("method", &method_name);
  Require(
      StringToEnum(method_name, &colors.method), path,
      "unknown method '" + method_name + "'; expected " + JoinedEnumNames<ReferenceColorSource>());
  next_line();
  const std::string recipe_key = "recipe ";
  if (line.compare(0, recipe_key.size(), recipe_key) == 0) {  // Absent from older files.
    colors.recipe = line.substr(recipe_key.size());
    next_line();
  }
  read_header("vertices", &count, false);
  Require(count >= 0, path, "negative vertex count");
  Require(expected_vertices < 0 || count == expected_vertices, path,
          "made for " + std::to_string(count) + " vertices, but the mesh has " +
              std::to_string(expected_vertices));
  colors.colors.resize(count);
  colors.valid.resize(count);
  for (int v = 0; v < count; ++v) {
    int valid = 0;
    Eigen::Vector3f& c = colors.colors[v];
    Require(static_cast<bool>(stream >> valid >> c(0) >> c(1) >> c(2)) && c.allFinite(), path,
            "malformed or missing line for vertex " + std::to_string(v));
    colors.valid[v] = valid != 0;
  }
  return colors;
}

SurfaceGaussians MakeSurfaceGaussians(const Eigen::Matrix3Xd& vertices,
                                      const Eigen::Matrix3Xd& normals,
                                      const std::vector<int>& vertex_ids,
                                      const ReferenceColors& colors) {
  SurfaceGaussians surface;
  surface.color_space = colors.color_space;
  surface.sigma_hat = colors.sigma_hat;
  for (int v : vertex_ids) {
    if (colors.valid[v] && normals.col(v).squaredNorm() > 0.5) surface.vertex_ids.push_back(v);
  }
  const int n = surface.size();
  surface.base.resize(3, n);
  surface.normals.resize(3, n);
  surface.colors.resize(n);
  for (int s = 0; s < n; ++s) {
    const int v = surface.vertex_ids[s];
    surface.base.col(s) = vertices.col(v);
    surface.normals.col(s) = normals.col(v);
    surface.colors[s] = colors.colors[v];
  }
  return surface;
}

}  // namespace finecap
