// finecap's cameras.yaml: reader and writer.
#include <algorithm>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "finecap/io/camera_io.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "io/camera_io_util.h"
#include "util/io_util.h"

namespace finecap {
namespace {

// Written at the top of every cameras.yaml so that the file explains itself.
constexpr char kSchemaComment[] =
    "# finecap camera rig.\n"
    "# Convention: world units are metres; a world point X maps to camera coordinates\n"
    "# x_cam = R * X + t; OpenCV axes (x right, y down, z forward); pixel = K * distort(x_cam / "
    "z)\n"
    "# with the centre of the top-left pixel at (0, 0); OpenCV distortion (k1, k2, p1, p2, k3,\n"
    "# then k4, k5, k6 of the rational model and s1, s2, s3, s4 of the thin prism model).\n"
    "# Schema:\n"
    "# cameras:\n"
    "#   - name: cam0\n"
    "#     width: 1004                         # pixels\n"
    "#     height: 1004\n"
    "#     K: [fx, s, cx, 0, fy, cy, 0, 0, 1]  # row-major 3x3, pixels\n"
    "#     R: [r00, r01, ..., r22]             # row-major world-to-camera rotation\n"
    "#     t: [tx, ty, tz]                     # metres\n"
    "#     distortion: [k1, k2, p1, p2, k3]    # optional, OpenCV order: 4, 5, 8 or 12 numbers\n";

// In the order of the schema, which is the order an error lists them in.
const std::vector<std::string> kCameraKeys = {"name", "width", "height",    "K",
                                              "R",    "t",     "distortion"};

// The text of a mapping's key; a list or mapping used as a key (YAML allows it) is refused.
std::string KeyText(const YAML::Node& key, const std::string& where) {
  Require(key.IsScalar(), where,
          "a key must be a name, not a list or mapping (line " +
              std::to_string(key.Mark().line + 1) + ")");
  return key.Scalar();
}

// Where a value sits, for error messages: "cameras.yaml (camera 'cam0', key 'K')".
std::string Location(const std::string& path, const std::string& camera, const std::string& key) {
  std::string location = path + " (camera '" + camera + "'";
  if (!key.empty()) location += ", key '" + key + "'";
  return location + ")";
}

template <typename T>
T ReadScalar(const YAML::Node& node, const std::string& where, const std::string& type_name) {
  Require(node.IsScalar(), where, "must be " + type_name);
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(where, "must be " + type_name + ", not '" + node.Scalar() + "'");
  }
}

std::vector<double> ReadNumbers(const YAML::Node& node, const std::string& where) {
  Require(node.IsSequence(), where, "must be a list of numbers");
  std::vector<double> values;
  for (const YAML::Node& element : node)
    values.push_back(ReadScalar<double>(element, where, "a number"));
  return values;
}

std::vector<double> ReadNumberList(const YAML::Node& node, size_t length,
                                   const std::string& where) {
  Require(node.IsSequence() && node.size() == length, where,
          "must be a list of " + std::to_string(length) + " numbers");
  return ReadNumbers(node, where);
}

Eigen::Matrix3d ReadRowMajor3x3(const YAML::Node& node, const std::string& where) {
  const std::vector<double> values = ReadNumberList(node, 9, where);
  Eigen::Matrix3d matrix;
  for (int i = 0; i < 9; ++i) matrix(i / 3, i % 3) = values[i];
  return matrix;
}

Camera ReadCamera(const YAML::Node& node, int index, const std::string& path) {
  const std::string entry = path + " (camera #" + std::to_string(index) + ")";
  Require(node.IsMap(), entry, "each camera must be a map of name, width, height, K, R, t");
  Require(static_cast<bool>(node["name"]), entry, "missing key 'name'");
  Camera camera;
  camera.name = ReadScalar<std::string>(node["name"], entry + " key 'name'", "a string");
  Require(!camera.name.empty(), entry, "empty camera name");
  for (const auto& item : node) {
    const std::string key = KeyText(item.first, entry);
    Require(std::find(kCameraKeys.begin(), kCameraKeys.end(), key) != kCameraKeys.end(),
            Location(path, camera.name, key),
            "unknown key; allowed: " + internal::JoinWithCommas(kCameraKeys));
  }
  for (const char* key : {"width", "height", "K", "R", "t"}) {
    Require(static_cast<bool>(node[key]), Location(path, camera.name, key), "missing key");
  }
  camera.width = ReadScalar<int>(node["width"], Location(path, camera.name, "width"), "an integer");
  camera.height =
      ReadScalar<int>(node["height"], Location(path, camera.name, "height"), "an integer");
  camera.K = ReadRowMajor3x3(node["K"], Location(path, camera.name, "K"));
  camera.R = ReadRowMajor3x3(node["R"], Location(path, camera.name, "R"));
  const std::vector<double> t = ReadNumberList(node["t"], 3, Location(path, camera.name, "t"));
  camera.t = Eigen::Vector3d(t[0], t[1], t[2]);
  if (node["distortion"]) {
    const std::string where = Location(path, camera.name, "distortion");
    camera.distortion = internal::OpenCvDistortion(ReadNumbers(node["distortion"], where), where);
  }
  return camera;
}

YAML::Node LoadYaml(const std::string& path) {
  internal::RequireFile(path);
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::ParserException& error) {
    throw Error(path,
                "malformed YAML at line " + std::to_string(error.mark.line + 1) + ": " + error.msg);
  } catch (const YAML::Exception& error) {
    throw Error(path, std::string("cannot read the YAML file: ") + error.what());
  }
}

void EmitRowMajor(YAML::Emitter* out, const Eigen::Matrix3d& matrix) {
  *out << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 9; ++i) *out << matrix(i / 3, i % 3);
  *out << YAML::EndSeq;
}

std::vector<Camera> CamerasFromYaml(const YAML::Node& root, const std::string& path) {
  Require(root.IsMap() && root["cameras"], path, "missing key 'cameras' at the top level");
  for (const auto& item : root) {
    const std::string key = KeyText(item.first, path);
    Require(key == "cameras", path, "unknown top-level key '" + key + "'");
  }
  const YAML::Node list = root["cameras"];
  Require(list.IsSequence() && list.size() > 0, path, "'cameras' must be a non-empty list");
  std::vector<Camera> cameras;
  for (size_t i = 0; i < list.size(); ++i) {
    cameras.push_back(ReadCamera(list[i], static_cast<int>(i), path));
  }
  internal::MakeRotationsExact(&cameras, path);
  for (const Camera& camera : cameras) camera.Validate(path);
  internal::RequireUniqueCameraNames(cameras, path);
  return cameras;
}

}  // namespace

std::vector<Camera> ReadCamerasYaml(const std::string& path) {
  const YAML::Node root = LoadYaml(path);
  try {
    return CamerasFromYaml(root, path);
  } catch (const YAML::Exception& error) {
    // A conversion that the checks above did not foresee still ends in one Error naming the file.
    throw Error(path, std::string("cannot read the cameras: ") + error.what());
  }
}

void WriteCamerasYaml(const std::vector<Camera>& cameras, const std::string& path) {
  Require(!cameras.empty(), path, "no cameras to write");
  for (const Camera& camera : cameras) camera.Validate(path);
  internal::RequireUniqueCameraNames(cameras, path);

  YAML::Emitter out;
  out.SetDoublePrecision(17);  // 17 significant digits: reading back gives the same double.
  out << YAML::BeginMap << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const Camera& camera : cameras) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << camera.name;
    out << YAML::Key << "width" << YAML::Value << camera.width;
    out << YAML::Key << "height" << YAML::Value << camera.height;
    out << YAML::Key << "K" << YAML::Value;
    EmitRowMajor(&out, camera.K);
    out << YAML::Key << "R" << YAML::Value;
    EmitRowMajor(&out, camera.R);
    out << YAML::Key << "t" << YAML::Value << YAML::Flow
        << std::vector<double>{camera.t.x(), camera.t.y(), camera.t.z()};
    out << YAML::Key << "distortion" << YAML::Value << YAML::Flow
        << internal::ShortestOpenCvDistortion(camera.distortion);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  Require(out.good(), path, "cannot format the cameras as YAML: " + out.GetLastError());
  WriteTextFileAtomically(path, std::string(kSchemaComment) + out.c_str() + "\n");
}

}  // namespace finecap
