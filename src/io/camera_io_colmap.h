// What COLMAP's text and binary models share once parsed (not part of the public API): their
// records, and the one mapping from COLMAP's camera models and poses to finecap's cameras, so that
// both formats name, order and refuse cameras the same way.
#ifndef FINECAP_SRC_IO_CAMERA_IO_COLMAP_H_
#define FINECAP_SRC_IO_CAMERA_IO_COLMAP_H_

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/io/camera_io.h"

namespace finecap {
namespace internal {

// One camera (intrinsic calibration) as COLMAP stores it, parameters in COLMAP's order.
struct ColmapCameraRecord {
  std::string model;  // COLMAP's name, e.g. "OPENCV".
  long long width = 0;
  long long height = 0;
  std::vector<double> params;
  std::string where;  // The file (and line or record) it came from, for errors.
};

// One registered image: COLMAP's world-to-camera quaternion (QW QX QY QZ, as stored) and
// translation, its camera and its file name relative to COLMAP's image folder.
struct ColmapImageRecord {
  int image_id = 0;
  double quaternion[4] = {1.0, 0.0, 0.0, 0.0};
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  int camera_id = 0;
  std::string name;
  std::string where;
};

// COLMAP's camera models in the order of their ids (cameras.bin stores the id), with their
// parameter counts. Only the first few, and FULL_OPENCV, have an OpenCV equivalent.
struct ColmapModelInfo {
  const char* name;
  int num_params;
  bool has_opencv_equivalent;
};
const std::vector<ColmapModelInfo>& ColmapModels();

// The model called `name`, or null when COLMAP has none of that name.
const ColmapModelInfo* FindColmapModel(const std::string& name);

// The cameras of a parsed model, as ReadColmapTextModel documents them (named after their
// images, ordered by first IMAGE_ID, posed by the smallest). `images` in any order; camera ids
// unique. Throws Error naming the record's `where` for a model without an OpenCV equivalent, a
// wrong parameter count, a quaternion not of unit length, a camera id no camera has, or a camera
// that fails validation.
ColmapModel CamerasOfColmapRecords(const std::map<int, ColmapCameraRecord>& cameras,
                                   std::vector<ColmapImageRecord> images,
                                   const std::string& images_path);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_IO_CAMERA_IO_COLMAP_H_
