// Reading and writing a calibrated camera rig in the formats capture set-ups use.
//
// Every reader returns cameras in finecap's convention (see camera.h): metres, x_cam = R*X + t,
// OpenCV axes, centre of the top-left pixel at (0, 0), OpenCV distortion (k1, k2, p1, p2, k3 and,
// where a file has them, k4, k5, k6, s1, s2, s3, s4). Every reader validates each camera and
// throws Error naming the file and the problem (and, where it applies, the camera and the key).
// A rotation matrix that is orthonormal only up to the rounding of the file (||R^T R - I|| <
// kRotationTolerance, see camera.h) is replaced by the nearest rotation, with one warning per file
// on stderr; anything further from a rotation is refused.
#ifndef FINECAP_CAMERA_IO_H_
#define FINECAP_CAMERA_IO_H_

#include <string>
#include <vector>

#include "finecap/geometry/camera.h"

namespace finecap {

// finecap's own cameras.yaml, cameras in file order. Its schema (every written file repeats it in
// a comment at its top):
//
//   cameras:
//     - name: cam0
//       width: 1004                        # pixels
//       height: 1004
//       K: [fx, s, cx, 0, fy, cy, 0, 0, 1] # row-major 3x3, pixels
//       R: [r00, r01, ..., r22]            # row-major world-to-camera rotation
//       t: [tx, ty, tz]                    # metres
//       distortion: [k1, k2, p1, p2, k3]   # optional, OpenCV order, default zeros
//
// `distortion` holds 4, 5, 8 or 12 coefficients, as OpenCV writes them (k1 k2 p1 p2 [k3 [k4 k5 k6
// [s1 s2 s3 s4]]]), or 14 whose last two (the tilted sensor) are zero. Unknown keys (the error
// lists the allowed ones), values of the wrong type or length, duplicate names and cameras that
// fail Camera::Validate are refused. The writer validates every camera first, prints doubles with
// 17 significant digits (reading the file back gives the same bits), the distortion as 5, 8 or 12
// coefficients (the fewest that hold it), and writes atomically.
std::vector<Camera> ReadCamerasYaml(const std::string& path);
void WriteCamerasYaml(const std::vector<Camera>& cameras, const std::string& path);

// A COLMAP model as finecap reads it: the cameras and, for each, the NAME of the image that posed
// it (relative to COLMAP's image folder, e.g. `cam03/000000.jpg` or `cam03.jpg`).
struct ColmapModel {
  std::vector<Camera> cameras;
  std::vector<std::string> image_names;  // One per camera.
};

// A COLMAP text model: `folder`/cameras.txt and `folder`/images.txt. Cameras of the models with an
// OpenCV equivalent are read: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV and
// FULL_OPENCV (whose k1 k2 p1 p2 k3 k4 k5 k6 are OpenCV's rational model); any other model
// (the fisheye ones, FOV, ...) is refused by name. COLMAP's pixel centres sit at +0.5 (the
// top-left pixel's centre is (0.5, 0.5)), which the reader subtracts from the principal point.
// The pose of an image is COLMAP's world-to-camera quaternion QW QX QY QZ and translation.
// A camera is named after its image: the image's folder when the NAME has one (`cam03/000000.jpg`
// -> `cam03`), else the file stem (`cam03.jpg` -> `cam03`). When several images share a camera
// name (several frames of one fixed camera), the one with the smallest IMAGE_ID gives the pose.
// Cameras are returned in order of their first IMAGE_ID.
ColmapModel ReadColmapTextModel(const std::string& folder);

// COLMAP's binary model, `folder`/cameras.bin and `folder`/images.bin (points3D.bin is not read),
// as COLMAP writes it (little-endian; model ids 0 to 11), giving what ReadColmapTextModel gives for
// the same model converted to text. A truncated file, an unknown model id, trailing bytes and
// duplicate ids are refused, naming the file and the record.
ColmapModel ReadColmapBinaryModel(const std::string& folder);

// The pair intri.yml / extri.yml of ZJU-MoCap and EasyMocap, as OpenCV's FileStorage writes it in
// YAML (read with yaml-cpp: OpenCV's own parser can hang on a damaged file): the `names` list
// (in intri.yml), K_<cam>, dist_<cam> (1xN or Nx1: 1 to 5, 8, 12 or 14 coefficients as above,
// missing ones zero),
// R_<cam> (a Rodrigues rotation vector) or Rot_<cam> (a 3x3 matrix, preferred when both are
// present), T_<cam> (metres). The image size comes from H_<cam> / W_<cam> in intri.yml when
// present; otherwise width and height are 0, meaning "take it from the camera's first image":
// everything but the size is validated here, and the capture loader validates the camera again
// once it has filled the size in.
std::vector<Camera> ReadIntriExtri(const std::string& intri_path, const std::string& extri_path);

// The Calib.toml of Pose2Sim and anipose (aniposelib's CameraGroup.dump), read by a strict
// reader of the TOML they use (tables, key = value, strings, numbers, booleans, nested arrays;
// errors name the file, the line, the table and the key). Every table but [metadata] is a camera:
//
//   [cam_1]
//   name = "cam_1"              # optional, default the table's name; names the image folder
//   size = [ 1920, 1080]        # width, height in pixels (Pose2Sim writes 1920.0: whole floats)
//   matrix = [ [ fx, 0.0, cx], [ 0.0, fy, cy], [ 0.0, 0.0, 1.0]]   # pixels, OpenCV's K
//   distortions = [ k1, k2, p1, p2]   # optional; 4, 5, 8, 12 or 14 as in cameras.yaml
//   rotation = [ rx, ry, rz]    # Rodrigues vector of the world-to-camera rotation (OpenCV's rvec)
//   translation = [ tx, ty, tz] # world-to-camera, x_cam = R X + t
//   fisheye = false             # optional; true (OpenCV's fisheye model) is refused
//
// Both tools use OpenCV's conventions, which are finecap's (pixel centres at integers, OpenCV
// axes and distortion). Translations are in metres, as Pose2Sim writes them; anipose writes the
// unit of its calibration board (often mm), which [metadata] can state as `units = "mm"` (or
// "cm", "m"); other [metadata] keys (Pose2Sim's adjusted, error) are ignored. A rig more than
// 100 units across with no stated unit is refused as probably not metres. Unknown keys (the
// error lists the allowed ones), keys outside a table, wrong types or lengths, duplicate names,
// and cameras that fail Camera::Validate are refused.
std::vector<Camera> ReadCalibToml(const std::string& path);

// A capture's camera rig and what it was read from.
struct Rig {
  std::vector<Camera> cameras;
  // E.g. "cameras.yaml", "intri.yml + extri.yml", "Calib.toml (Pose2Sim/anipose)" or "COLMAP
  // binary model in sparse/0".
  std::string source;
  // For a COLMAP model, per camera, the image that posed it: the capture folder's images/NAME.
  // Empty for the other formats.
  std::vector<std::string> colmap_images;
};

// The rig of a capture folder, in this order: cameras.yaml; intri.yml + extri.yml; a Calib.toml
// (a file whose name, in any case, ends in ".toml" and contains "calib": Calib.toml,
// Calib_board.toml, calibration.toml, take1_camera_calibration.toml; more than one such file is
// refused as ambiguous); a COLMAP model in `capture_dir`/sparse, `capture_dir`/sparse/0 or
// `capture_dir` itself (the first holding a cameras.bin or cameras.txt; binary when both are
// there, as COLMAP reads them). Throws Error naming the folder if none is found.
Rig ReadRig(const std::string& capture_dir);

}  // namespace finecap

#endif  // FINECAP_CAMERA_IO_H_
