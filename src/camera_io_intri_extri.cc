// The intri.yml / extri.yml pair of ZJU-MoCap and EasyMocap, read with cv::FileStorage.
#include <Eigen/Core>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include "finecap/camera_io.h"
#include "finecap/error.h"
#include "io_util.h"

namespace finecap {
namespace {

// YAML and XML are text: a NUL byte means a damaged or binary file. OpenCV 4.6's YAML parser reads
// NUL as the end of its buffer and can loop forever on such a file, so it never sees one.
void RequireNoNulByte(const std::string& path) {
  const std::string bytes = internal::ReadWholeFile(path);
  const size_t nul = bytes.find('\0');
  Require(
      nul == std::string::npos, path,
      "contains a NUL byte at offset " + std::to_string(nul) + ": not a text OpenCV YAML/XML file");
}

cv::FileStorage OpenStorage(const std::string& path) {
  RequireNoNulByte(path);
  try {
    cv::FileStorage storage(path, cv::FileStorage::READ);
    Require(storage.isOpened(), path, "cannot open as an OpenCV YAML/XML file");
    // Looking a key up in anything but a mapping is an assertion failure in OpenCV.
    Require(storage.root().isMap(), path, "the top level must be a mapping of keys");
    return storage;
  } catch (const Error&) {
    throw;
  } catch (const cv::Exception& error) {
    throw Error(path, "malformed OpenCV YAML/XML file: " + error.msg);
  } catch (const std::exception& error) {
    // OpenCV's parser lets library exceptions through on some damaged files (std::length_error
    // from a string it sizes from the file).
    throw Error(path, std::string("malformed OpenCV YAML/XML file: ") + error.what());
  }
}

std::string KeyLocation(const std::string& path, const std::string& key) {
  return path + " (key '" + key + "')";
}

// OpenCV allocates the size a matrix node declares before it reads the data, so a damaged `rows`
// or `cols` could ask for gigabytes: the declared size is checked first. A rig's matrices are at
// most 3x3 or 1x5.
void RequireSmallMatrixNode(const cv::FileNode& node, const std::string& where) {
  constexpr int kMaxSide = 16;
  Require(node.isMap(), where, "is not an OpenCV matrix (a map of rows, cols, dt, data)");
  const cv::FileNode rows = node["rows"];
  const cv::FileNode cols = node["cols"];
  Require(rows.isInt() && cols.isInt(), where, "the matrix's rows and cols must be integers");
  const int num_rows = static_cast<int>(rows);
  const int num_cols = static_cast<int>(cols);
  Require(num_rows >= 0 && num_rows <= kMaxSide && num_cols >= 0 && num_cols <= kMaxSide, where,
          "declares a " + std::to_string(num_rows) + "x" + std::to_string(num_cols) +
              " matrix; a camera's matrices have at most " + std::to_string(kMaxSide) +
              " rows and columns");
}

// The matrix stored under `key`, as doubles; empty when the key is absent.
cv::Mat ReadMatrix(const cv::FileStorage& storage, const std::string& key,
                   const std::string& path) {
  const cv::FileNode node = storage[key];
  if (node.empty() || node.isNone()) return cv::Mat();
  RequireSmallMatrixNode(node, KeyLocation(path, key));
  cv::Mat matrix;
  try {
    node >> matrix;
  } catch (const cv::Exception& error) {
    throw Error(KeyLocation(path, key), "is not an OpenCV matrix: " + error.msg);
  }
  Require(!matrix.empty() && matrix.channels() == 1, KeyLocation(path, key),
          "is not a one-channel matrix");
  matrix.convertTo(matrix, CV_64F);
  return matrix;
}

cv::Mat RequireMatrix(const cv::FileStorage& storage, const std::string& key, int rows, int cols,
                      const std::string& path) {
  const cv::Mat matrix = ReadMatrix(storage, key, path);
  Require(!matrix.empty(), KeyLocation(path, key), "missing key");
  Require(matrix.rows * matrix.cols == rows * cols && (matrix.rows == rows || matrix.rows == cols),
          KeyLocation(path, key),
          "must be " + std::to_string(rows) + "x" + std::to_string(cols) + ", is " +
              std::to_string(matrix.rows) + "x" + std::to_string(matrix.cols));
  return matrix.reshape(1, rows);
}

std::vector<std::string> ReadNames(const cv::FileStorage& storage, const std::string& path) {
  const cv::FileNode node = storage["names"];
  Require(node.isSeq() && node.size() > 0, KeyLocation(path, "names"),
          "missing or not a non-empty list of camera names");
  std::vector<std::string> names;
  for (const cv::FileNode& element : node) {
    if (element.isInt()) {
      names.push_back(std::to_string(static_cast<int>(element)));
    } else {
      Require(element.isString(), KeyLocation(path, "names"), "names must be strings");
      names.push_back(element.string());
    }
  }
  return names;
}

void ReadIntrinsics(const cv::FileStorage& intri, const std::string& path, Camera* camera) {
  const std::string& name = camera->name;
  cv::cv2eigen(RequireMatrix(intri, "K_" + name, 3, 3, path), camera->K);
  const cv::Mat dist = ReadMatrix(intri, "dist_" + name, path);
  if (!dist.empty()) {
    Require((dist.rows == 1 || dist.cols == 1) && dist.total() <= 5,
            KeyLocation(path, "dist_" + name), "must be a vector of at most 5 coefficients");
    for (size_t i = 0; i < dist.total(); ++i) camera->distortion[i] = dist.at<double>(i);
  }
  const cv::FileNode height = intri["H_" + name];
  const cv::FileNode width = intri["W_" + name];
  if (!height.empty() || !width.empty()) {
    Require(height.isInt() && width.isInt(), KeyLocation(path, "H_" + name),
            "H_" + name + " and W_" + name + " must both be integers");
    camera->height = static_cast<int>(height);
    camera->width = static_cast<int>(width);
  }
}

void ReadExtrinsics(const cv::FileStorage& extri, const std::string& path, Camera* camera) {
  const std::string& name = camera->name;
  const cv::Mat rotation_matrix = ReadMatrix(extri, "Rot_" + name, path);
  if (!rotation_matrix.empty()) {
    cv::cv2eigen(RequireMatrix(extri, "Rot_" + name, 3, 3, path), camera->R);
  } else {
    Require(!ReadMatrix(extri, "R_" + name, path).empty(), KeyLocation(path, "R_" + name),
            "missing key (neither R_" + name + " nor Rot_" + name + " is given)");
    cv::Mat rotation;
    cv::Rodrigues(RequireMatrix(extri, "R_" + name, 3, 1, path), rotation);
    cv::cv2eigen(rotation, camera->R);
  }
  cv::cv2eigen(RequireMatrix(extri, "T_" + name, 3, 1, path), camera->t);
}

}  // namespace

std::vector<Camera> ReadIntriExtri(const std::string& intri_path, const std::string& extri_path) {
  const cv::FileStorage intri = OpenStorage(intri_path);
  const cv::FileStorage extri = OpenStorage(extri_path);
  std::vector<Camera> cameras;
  try {
    for (const std::string& name : ReadNames(intri, intri_path)) {
      Camera camera;
      camera.name = name;
      ReadIntrinsics(intri, intri_path, &camera);
      ReadExtrinsics(extri, extri_path, &camera);
      internal::ValidateCameraExceptUnknownSize(camera, intri_path + " / " + extri_path);
      cameras.push_back(camera);
    }
  } catch (const cv::Exception& error) {
    // An OpenCV assertion that the checks above did not foresee still ends in one Error.
    throw Error(intri_path + " / " + extri_path, "malformed OpenCV YAML/XML file: " + error.msg);
  }
  internal::RequireUniqueCameraNames(cameras, intri_path);
  return cameras;
}

}  // namespace finecap
