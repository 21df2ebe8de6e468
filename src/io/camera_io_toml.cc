// The Calib.toml of Pose2Sim and anipose (aniposelib's CameraGroup.dump), read with the strict
// TOML subset reader of toml_subset.h.
#include <algorithm>
#include <cmath>
#include <iostream>

#include "finecap/io/camera_io.h"
#include "finecap/util/error.h"
#include "io/camera_io_util.h"
#include "io/toml_subset.h"
#include "util/io_util.h"

namespace finecap {
namespace {

using internal::TomlEntries;
using internal::TomlTable;
using internal::TomlValue;

const std::vector<std::string> kCameraKeys = {"name",     "size",        "matrix", "distortions",
                                              "rotation", "translation", "fisheye"};

// A rig wider than this many metres is almost certainly written in millimetres (anipose writes
// the unit of board_square_side_length, which its documentation gives in mm).
constexpr double kLargestPlausibleRigMetres = 100.0;

// "Calib.toml line 7 (camera [cam_1], key 'matrix')".
std::string Location(const std::string& path, int line, const std::string& table,
                     const std::string& key) {
  std::string where = path + " line " + std::to_string(line) + " (";
  if (!table.empty()) where += "table [" + table + "]";
  if (!table.empty() && !key.empty()) where += ", ";
  if (!key.empty()) where += "key '" + key + "'";
  return where + ")";
}

const TomlValue* Find(const TomlEntries& entries, const std::string& key) {
  for (const auto& entry : entries) {
    if (entry.first == key) return &entry.second;
  }
  return nullptr;
}

class CameraTableReader {
 public:
  CameraTableReader(const TomlTable& table, const std::string& path) : table_(table), path_(path) {}

  Camera Read() const {
    for (const auto& [key, value] : table_.entries) {
      Require(std::find(kCameraKeys.begin(), kCameraKeys.end(), key) != kCameraKeys.end(),
              Where(value, key), "unknown key; allowed: " + internal::JoinWithCommas(kCameraKeys));
    }
    Camera camera;
    camera.name = ReadName();
    if (const TomlValue* fisheye = Find(table_.entries, "fisheye")) {
      Require(fisheye->type == TomlValue::Type::kBool, Where(*fisheye, "fisheye"),
              "must be true or false, not " + internal::TomlTypeName(*fisheye));
      Require(!fisheye->boolean, Where(*fisheye, "fisheye"),
              "the fisheye (Kannala-Brandt) lens model is not supported: finecap's cameras use "
              "OpenCV's pinhole model with its distortion (undistort the videos first)");
    }
    const std::vector<double> size = Numbers(Required("size"), "size", 2);
    camera.width = Dimension(size[0], Required("size"));
    camera.height = Dimension(size[1], Required("size"));
    camera.K = Matrix3x3(Required("matrix"));
    if (const TomlValue* distortions = Find(table_.entries, "distortions")) {
      const std::string where = Where(*distortions, "distortions");
      camera.distortion =
          internal::OpenCvDistortion(Numbers(*distortions, "distortions", -1), where);
    }
    const std::vector<double> rotation = Numbers(Required("rotation"), "rotation", 3);
    camera.R =
        internal::RotationOfRodrigues(Eigen::Vector3d(rotation[0], rotation[1], rotation[2]));
    const std::vector<double> translation = Numbers(Required("translation"), "translation", 3);
    camera.t = Eigen::Vector3d(translation[0], translation[1], translation[2]);
    return camera;
  }

 private:
  std::string Where(const TomlValue& value, const std::string& key) const {
    return Location(path_, value.line, table_.name, key);
  }

  const TomlValue& Required(const std::string& key) const {
    const TomlValue* value = Find(table_.entries, key);
    Require(value != nullptr, Location(path_, table_.line, table_.name, key), "missing key");
    return *value;
  }

  // The camera's name: `name` (a string, or an integer as some scripts write it), else the
  // table's name.
  std::string ReadName() const {
    const TomlValue* name = Find(table_.entries, "name");
    if (name == nullptr) return table_.name;
    Require(name->type == TomlValue::Type::kString || name->type == TomlValue::Type::kInteger,
            Where(*name, "name"), "must be a string, not " + internal::TomlTypeName(*name));
    return name->text;
  }

  // The numbers of a flat array; `count` < 0 takes any length.
  std::vector<double> Numbers(const TomlValue& value, const std::string& key, int count) const {
    const std::string what =
        count < 0 ? "an array of numbers" : "an array of " + std::to_string(count) + " numbers";
    Require(value.type == TomlValue::Type::kArray &&
                (count < 0 || value.items.size() == static_cast<size_t>(count)),
            Where(value, key), "must be " + what);
    std::vector<double> numbers;
    for (const TomlValue& item : value.items) {
      Require(item.IsNumber(), Where(item, key),
              "must be " + what + ", found " + internal::TomlTypeName(item));
      numbers.push_back(item.number);
    }
    return numbers;
  }

  // A size in pixels: Pose2Sim writes it as a float ("1920.0"), aniposelib as an integer.
  int Dimension(double value, const TomlValue& size) const {
    Require(value >= 1.0 && value <= 1e6 && value == std::floor(value), Where(size, "size"),
            "must be [width, height] in pixels: whole numbers between 1 and 1000000");
    return static_cast<int>(value);
  }

  Eigen::Matrix3d Matrix3x3(const TomlValue& value) const {
    Require(value.type == TomlValue::Type::kArray && value.items.size() == 3,
            Where(value, "matrix"),
            "must be a 3x3 matrix written as 3 rows of 3 numbers ([[fx, 0, cx], [0, fy, cy], "
            "[0, 0, 1]])");
    Eigen::Matrix3d matrix;
    for (int row = 0; row < 3; ++row) {
      const std::vector<double> numbers = Numbers(value.items[row], "matrix", 3);
      for (int col = 0; col < 3; ++col) matrix(row, col) = numbers[col];
    }
    return matrix;
  }

  const TomlTable& table_;
  const std::string& path_;
};

// The length unit of the translations: metres unless [metadata] says `units = "mm"` or "cm".
double MetresPerUnit(const TomlTable& metadata, const std::string& path) {
  const TomlValue* units = Find(metadata.entries, "units");
  if (units == nullptr) return 1.0;
  const std::string where = Location(path, units->line, metadata.name, "units");
  Require(units->type == TomlValue::Type::kString, where, "must be \"m\", \"cm\" or \"mm\"");
  if (units->text == "m") return 1.0;
  if (units->text == "cm") return 0.01;
  if (units->text == "mm") return 0.001;
  throw Error(where, "must be \"m\", \"cm\" or \"mm\", not \"" + units->text + "\"");
}

// Refuses a rig whose size says that its translations are not in metres.
void RequirePlausibleMetres(const std::vector<Camera>& cameras, const std::string& path) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Camera& camera : cameras) centroid += camera.Center();
  centroid /= static_cast<double>(cameras.size());
  double widest = 0.0;
  for (const Camera& camera : cameras)
    widest = std::max(widest, (camera.Center() - centroid).norm());
  Require(!(widest > kLargestPlausibleRigMetres), path,
          "the cameras lie up to " + std::to_string(widest) +
              " units from their centre: read as metres that is not a capture rig. anipose writes "
              "the unit of board_square_side_length (often mm); say so with `units = \"mm\"` (or "
              "\"cm\") in the file's [metadata] table");
}

}  // namespace

std::vector<Camera> ReadCalibToml(const std::string& path) {
  const internal::TomlDocument document =
      internal::ParseTomlSubset(internal::ReadWholeFile(path), path);
  if (!document.root.empty()) {
    const auto& [key, value] = document.root.front();
    throw Error(Location(path, value.line, "", key),
                "key outside any table: each camera is a table ([cam_1], [name], ...)");
  }
  std::vector<Camera> cameras;
  double metres_per_unit = 1.0;
  for (const TomlTable& table : document.tables) {
    if (table.name == "metadata") {  // Pose2Sim: adjusted, error; finecap: units.
      metres_per_unit = MetresPerUnit(table, path);
      continue;
    }
    cameras.push_back(CameraTableReader(table, path).Read());
  }
  Require(!cameras.empty(), path, "no camera table ([cam_1], ...) in the file");
  for (Camera& camera : cameras) camera.t *= metres_per_unit;
  internal::MakeRotationsExact(&cameras, path);
  for (const Camera& camera : cameras) camera.Validate(path);
  internal::RequireUniqueCameraNames(cameras, path);
  RequirePlausibleMetres(cameras, path);
  return cameras;
}

}  // namespace finecap
