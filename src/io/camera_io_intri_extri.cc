// The intri.yml / extri.yml pair of ZJU-MoCap and EasyMocap: files that OpenCV's FileStorage
// writes, read here with yaml-cpp. OpenCV 4.6's own YAML parser never returns on some damaged
// files (fuzzing found two, one of 20 plain ASCII bytes), and a parser that can hang cannot be
// guarded from outside; yaml-cpp, which reads every other YAML file of finecap, can be.
#include <algorithm>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "finecap/io/camera_io.h"
#include "finecap/util/error.h"
#include "io/camera_io_util.h"
#include "util/io_util.h"

namespace finecap {
namespace {

// A matrix of doubles as OpenCV writes it: a map of rows, cols, dt and data (row-major).
struct OpenCvMatrix {
  int rows = 0;
  int cols = 0;
  std::vector<double> data;

  bool empty() const { return data.empty(); }
};

// A YAML file is text: a NUL byte means a damaged or binary file.
void RequireNoNulByte(const std::string& path, const std::string& text) {
  const size_t nul = text.find('\0');
  Require(nul == std::string::npos, path,
          "contains a NUL byte at offset " + std::to_string(nul) + ": not a text YAML file");
}

// OpenCV starts its files with "%YAML:1.0", which is not a YAML directive ("%YAML 1.0"): that line
// is blanked (kept as an empty line, so that line numbers stay right) before yaml-cpp reads the
// rest.
YAML::Node LoadOpenCvYaml(const std::string& path) {
  std::string text = internal::ReadWholeFile(path);
  RequireNoNulByte(path, text);
  if (text.rfind("%YAML:", 0) == 0) text.erase(0, text.find('\n'));
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& error) {
    throw Error(path, "malformed OpenCV YAML file at line " + std::to_string(error.mark.line + 1) +
                          ": " + error.msg);
  } catch (const YAML::Exception& error) {
    throw Error(path, std::string("malformed OpenCV YAML file: ") + error.what());
  }
  Require(root.IsMap(), path, "the top level must be a mapping of keys");
  return root;
}

std::string KeyLocation(const std::string& path, const std::string& key) {
  return path + " (key '" + key + "')";
}

int ReadInt(const YAML::Node& node, const std::string& where, const std::string& what) {
  int value = 0;
  Require(node.IsScalar() && internal::ParseInt(node.Scalar(), &value), where,
          what + " must be an integer");
  return value;
}

// The matrix stored under `key`; empty when the key is absent. The declared size is checked
// before anything is read: a rig's matrices are at most 3x3 or 1x5, and a damaged `rows` or
// `cols` must not ask for gigabytes.
OpenCvMatrix ReadMatrix(const YAML::Node& root, const std::string& key, const std::string& path) {
  constexpr int kMaxSide = 16;
  const YAML::Node node = root[key];
  OpenCvMatrix matrix;
  if (!node || node.IsNull()) return matrix;
  const std::string where = KeyLocation(path, key);
  Require(node.IsMap(), where, "is not an OpenCV matrix (a map of rows, cols, dt, data)");
  matrix.rows = ReadInt(node["rows"], where, "the matrix's rows");
  matrix.cols = ReadInt(node["cols"], where, "the matrix's cols");
  Require(
      matrix.rows >= 1 && matrix.rows <= kMaxSide && matrix.cols >= 1 && matrix.cols <= kMaxSide,
      where,
      "declares a " + std::to_string(matrix.rows) + "x" + std::to_string(matrix.cols) +
          " matrix; a camera's matrices have at least 1 and at most " + std::to_string(kMaxSide) +
          " rows and columns");
  const YAML::Node data = node["data"];
  const size_t count = static_cast<size_t>(matrix.rows) * matrix.cols;
  Require(data.IsSequence() && data.size() == count, where,
          "data must be a list of " + std::to_string(count) + " numbers (rows x cols)");
  for (const YAML::Node& element : data) {
    double value = 0.0;
    Require(element.IsScalar() && internal::ParseDouble(element.Scalar(), &value), where,
            "data must be numbers");
    matrix.data.push_back(value);
  }
  return matrix;
}

// The matrix under `key`, which must hold rows x cols numbers (a vector may be stored either
// way round), row-major.
std::vector<double> RequireMatrix(const YAML::Node& root, const std::string& key, int rows,
                                  int cols, const std::string& path) {
  const OpenCvMatrix matrix = ReadMatrix(root, key, path);
  Require(!matrix.empty(), KeyLocation(path, key), "missing key");
  Require(matrix.rows * matrix.cols == rows * cols && (matrix.rows == rows || matrix.rows == cols),
          KeyLocation(path, key),
          "must be " + std::to_string(rows) + "x" + std::to_string(cols) + ", is " +
              std::to_string(matrix.rows) + "x" + std::to_string(matrix.cols));
  return matrix.data;
}

Eigen::Matrix3d RowMajor3x3(const std::vector<double>& values) {
  Eigen::Matrix3d matrix;
  for (int i = 0; i < 9; ++i) matrix(i / 3, i % 3) = values[i];
  return matrix;
}

std::vector<std::string> ReadNames(const YAML::Node& root, const std::string& path) {
  const YAML::Node node = root["names"];
  Require(node.IsSequence() && node.size() > 0, KeyLocation(path, "names"),
          "missing or not a non-empty list of camera names");
  std::vector<std::string> names;
  for (const YAML::Node& element : node) {
    Require(element.IsScalar(), KeyLocation(path, "names"), "names must be strings");
    names.push_back(element.Scalar());
  }
  return names;
}

void ReadIntrinsics(const YAML::Node& intri, const std::string& path, Camera* camera) {
  const std::string& name = camera->name;
  camera->K = RowMajor3x3(RequireMatrix(intri, "K_" + name, 3, 3, path));
  const OpenCvMatrix dist = ReadMatrix(intri, "dist_" + name, path);
  if (!dist.empty()) {
    const std::string where = KeyLocation(path, "dist_" + name);
    Require(dist.rows == 1 || dist.cols == 1, where, "must be a vector (1xN or Nx1)");
    // EasyMocap writes 1x5; fewer than 4 (k1 alone, say) means the rest are zero.
    std::vector<double> coefficients = dist.data;
    if (coefficients.size() < 4) coefficients.resize(4, 0.0);
    camera->distortion = internal::OpenCvDistortion(coefficients, where);
  }
  const YAML::Node height = intri["H_" + name];
  const YAML::Node width = intri["W_" + name];
  if (height || width) {
    const std::string where = KeyLocation(path, "H_" + name);
    const std::string what = "H_" + name + " and W_" + name;
    camera->height = ReadInt(height, where, what);
    camera->width = ReadInt(width, where, what);
  }
}

void ReadExtrinsics(const YAML::Node& extri, const std::string& path, Camera* camera) {
  const std::string& name = camera->name;
  if (!ReadMatrix(extri, "Rot_" + name, path).empty()) {
    camera->R = RowMajor3x3(RequireMatrix(extri, "Rot_" + name, 3, 3, path));
  } else {
    Require(!ReadMatrix(extri, "R_" + name, path).empty(), KeyLocation(path, "R_" + name),
            "missing key (neither R_" + name + " nor Rot_" + name + " is given)");
    const std::vector<double> r = RequireMatrix(extri, "R_" + name, 3, 1, path);
    camera->R = internal::RotationOfRodrigues(Eigen::Vector3d(r[0], r[1], r[2]));
  }
  const std::vector<double> t = RequireMatrix(extri, "T_" + name, 3, 1, path);
  camera->t = Eigen::Vector3d(t[0], t[1], t[2]);
}

}  // namespace

std::vector<Camera> ReadIntriExtri(const std::string& intri_path, const std::string& extri_path) {
  const YAML::Node intri = LoadOpenCvYaml(intri_path);
  const YAML::Node extri = LoadOpenCvYaml(extri_path);
  std::vector<Camera> cameras;
  try {
    for (const std::string& name : ReadNames(intri, intri_path)) {
      Camera camera;
      camera.name = name;
      ReadIntrinsics(intri, intri_path, &camera);
      ReadExtrinsics(extri, extri_path, &camera);
      cameras.push_back(camera);
    }
  } catch (const YAML::Exception& error) {
    // A yaml-cpp failure that the checks above did not foresee still ends in one Error.
    throw Error(intri_path + " / " + extri_path,
                std::string("malformed OpenCV YAML file: ") + error.what());
  }
  internal::MakeRotationsExact(&cameras, extri_path);
  for (const Camera& camera : cameras) {
    internal::ValidateCameraExceptUnknownSize(camera, intri_path + " / " + extri_path);
  }
  internal::RequireUniqueCameraNames(cameras, intri_path);
  return cameras;
}

}  // namespace finecap
