// PLY: a reader for ascii and binary (either endianness) files, and a binary little-endian writer.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>

#include "finecap/util/error.h"
#include "io/mesh_io_internal.h"
#include "util/io_util.h"

namespace finecap {
namespace internal {
namespace {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // For a list: the type of its elements.
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  size_t data_offset = 0;  // Where the body starts in the file.
};

bool HostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first_byte = 0;
  std::memcpy(&first_byte, &one, 1);
  return first_byte == 1;
}

size_t SizeOf(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool ParseType(const std::string& name, PlyType* type) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [candidate, value] : kNames) {
    if (name == candidate) {
      *type = value;
      return true;
    }
  }
  return false;
}

PlyProperty ParseProperty(const std::vector<std::string>& tokens, const std::string& where) {
  PlyProperty property;
  if (tokens.size() == 5 && tokens[1] == "list") {
    property.is_list = true;
    Require(ParseType(tokens[2], &property.count_type) && ParseType(tokens[3], &property.type),
            where, "unknown PLY type in '" + tokens[2] + " " + tokens[3] + "'");
    property.name = tokens[4];
    return property;
  }
  Require(tokens.size() == 3, where, "expected 'property TYPE NAME' or 'property list ...'");
  Require(ParseType(tokens[1], &property.type), where, "unknown PLY type '" + tokens[1] + "'");
  property.name = tokens[2];
  return property;
}

PlyFormat ParseFormat(const std::vector<std::string>& tokens, const std::string& where) {
  Require(tokens.size() == 3 && tokens[2] == "1.0", where, "expected 'format FORMAT 1.0'");
  if (tokens[1] == "ascii") return PlyFormat::kAscii;
  if (tokens[1] == "binary_little_endian") return PlyFormat::kBinaryLittleEndian;
  if (tokens[1] == "binary_big_endian") return PlyFormat::kBinaryBigEndian;
  throw Error(where, "unknown PLY format '" + tokens[1] + "'");
}

PlyHeader ParseHeader(const std::string& contents, const std::string& path) {
  Require(contents.compare(0, 4, "ply\n") == 0 || contents.compare(0, 5, "ply\r\n") == 0, path,
          "is not a PLY file (it does not start with the line 'ply')");
  PlyHeader header;
  bool has_format = false;
  size_t position = 0;
  for (int line_number = 1;; ++line_number) {
    const size_t end = contents.find('\n', position);
    Require(end != std::string::npos, path, "PLY header has no 'end_header' line");
    const std::vector<std::string> tokens =
        SplitWhitespace(contents.substr(position, end - position));
    position = end + 1;
    const std::string where = path + " line " + std::to_string(line_number);
    if (line_number == 1 || tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info") {
      continue;
    }
    if (tokens[0] == "end_header") break;
    if (tokens[0] == "format") {
      header.format = ParseFormat(tokens, where);
      has_format = true;
    } else if (tokens[0] == "element") {
      int count = 0;
      Require(tokens.size() == 3 && ParseInt(tokens[2], &count) && count >= 0, where,
              "expected 'element NAME COUNT'");
      header.elements.push_back({tokens[1], static_cast<size_t>(count), {}});
    } else if (tokens[0] == "property") {
      Require(!header.elements.empty(), where, "property before any element");
      header.elements.back().properties.push_back(ParseProperty(tokens, where));
    } else {
      throw Error(where, "unexpected PLY header line starting with '" + tokens[0] + "'");
    }
  }
  Require(has_format, path, "PLY header has no 'format' line");
  header.data_offset = position;
  return header;
}

// Reads the body's values one at a time, as doubles, whatever their stored type.
class PlyValueReader {
 public:
  PlyValueReader(const std::string& contents, size_t offset, PlyFormat format)
      : contents_(contents),
        position_(offset),
        format_(format),
        swap_bytes_((format == PlyFormat::kBinaryBigEndian) == HostIsLittleEndian()) {}

  // False when the body ends early or (ascii) the token is not a number.
  bool Read(PlyType type, double* value) {
    return format_ == PlyFormat::kAscii ? ReadAscii(value) : ReadBinary(type, value);
  }

  size_t remaining_bytes() const { return contents_.size() - position_; }

 private:
  bool ReadAscii(double* value) {
    const size_t start = contents_.find_first_not_of(" \t\r\n", position_);
    if (start == std::string::npos) return false;
    size_t end = contents_.find_first_of(" \t\r\n", start);
    if (end == std::string::npos) end = contents_.size();
    position_ = end;
    return ParseDouble(contents_.substr(start, end - start), value);
  }

  bool ReadBinary(PlyType type, double* value) {
    const size_t size = SizeOf(type);
    if (remaining_bytes() < size) return false;
    unsigned char bytes[8];
    std::memcpy(bytes, contents_.data() + position_, size);
    position_ += size;
    if (swap_bytes_) std::reverse(bytes, bytes + size);
    *value = Decode(type, bytes);
    return true;
  }

  template <typename T>
  static double As(const unsigned char* bytes) {
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return static_cast<double>(value);
  }

  static double Decode(PlyType type, const unsigned char* bytes) {
    switch (type) {
      case PlyType::kInt8:
        return As<int8_t>(bytes);
      case PlyType::kUint8:
        return As<uint8_t>(bytes);
      case PlyType::kInt16:
        return As<int16_t>(bytes);
      case PlyType::kUint16:
        return As<uint16_t>(bytes);
      case PlyType::kInt32:
        return As<int32_t>(bytes);
      case PlyType::kUint32:
        return As<uint32_t>(bytes);
      case PlyType::kFloat32:
        return As<float>(bytes);
      case PlyType::kFloat64:
        return As<double>(bytes);
    }
    return 0.0;
  }

  const std::string& contents_;
  size_t position_;
  PlyFormat format_;
  bool swap_bytes_;
};

int FindProperty(const PlyElement& element, const std::vector<std::string>& names) {
  for (size_t i = 0; i < element.properties.size(); ++i) {
    for (const std::string& name : names) {
      if (element.properties[i].name == name) return static_cast<int>(i);
    }
  }
  return -1;
}

// Where instance `index` of `element` lies in the file at `path`, for error messages: built only
// for an error, not for each of a mesh's many instances.
struct InstanceLocation {
  const std::string& path;
  const PlyElement& element;
  size_t index;
  std::string operator()() const {
    return path + " (" + element.name + " " + std::to_string(index) + ")";
  }
};

// Reads one instance of `element`: the scalar properties into `scalars`, the list named by
// `list_index` (if any) into `list`. Other lists are read and dropped.
void ReadInstance(const PlyElement& element, int list_index, PlyValueReader* reader,
                  const InstanceLocation& where, std::vector<double>* scalars,
                  std::vector<int>* list) {
  scalars->assign(element.properties.size(), 0.0);
  list->clear();
  const auto read = [&](PlyType type, double* value) {
    if (!reader->Read(type, value)) {
      throw Error(where(), "the data ends early or holds a value that is not a number");
    }
  };
  for (size_t p = 0; p < element.properties.size(); ++p) {
    const PlyProperty& property = element.properties[p];
    double value = 0.0;
    read(property.is_list ? property.count_type : property.type, &value);
    if (!property.is_list) {
      (*scalars)[p] = value;
      continue;
    }
    if (!(value >= 0 && value <= 1e6 && value == std::floor(value))) {
      throw Error(where(), "invalid list length");
    }
    for (int i = 0; i < static_cast<int>(value); ++i) {
      double item = 0.0;
      read(property.type, &item);
      if (static_cast<int>(p) != list_index) continue;
      if (!(item == std::floor(item) && std::abs(item) < 2e9)) {
        throw Error(where(), "vertex index is not an integer");
      }
      list->push_back(static_cast<int>(item));
    }
  }
}

void ReadElement(const PlyElement& element, PlyValueReader* reader, const std::string& path,
                 MeshBuilder* builder) {
  const bool is_vertex = element.name == "vertex";
  const bool is_face = element.name == "face";
  const int x = FindProperty(element, {"x"}), y = FindProperty(element, {"y"}),
            z = FindProperty(element, {"z"});
  const int indices = FindProperty(element, {"vertex_indices", "vertex_index"});
  Require(!is_vertex || (x >= 0 && y >= 0 && z >= 0), path, "PLY vertex element lacks x, y or z");
  Require(!is_face || (indices >= 0 && element.properties[indices].is_list), path,
          "PLY face element lacks the list 'vertex_indices'");
  // Every instance takes at least one byte: a larger count is a damaged header, not a big mesh.
  Require(element.count <= reader->remaining_bytes(), path,
          "the file is shorter than its header's " + std::to_string(element.count) + " " +
              element.name + " entries");
  std::vector<double> scalars;
  std::vector<int> list;
  for (size_t i = 0; i < element.count; ++i) {
    const InstanceLocation where{path, element, i};
    ReadInstance(element, is_face ? indices : -1, reader, where, &scalars, &list);
    if (is_vertex) builder->AddVertex(scalars[x], scalars[y], scalars[z]);
    if (is_face) builder->AddFace(list, where);
  }
}

template <typename T>
void AppendLittleEndian(T value, std::string* out) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (!HostIsLittleEndian()) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

uint8_t ColorByte(double channel) {
  return static_cast<uint8_t>(std::lround(std::clamp(channel, 0.0, 1.0) * 255.0));
}

std::string PlyHeaderText(const Mesh& mesh, const VertexAttributes& attributes) {
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\n"
         << "comment finecap mesh: metres, one vertex list shared by every frame\n"
         << "element vertex " << mesh.num_vertices() << "\n"
         << "property double x\nproperty double y\nproperty double z\n";
  if (attributes.normals.size() > 0) {
    header << "property float nx\nproperty float ny\nproperty float nz\n";
  }
  if (attributes.colors.size() > 0) {
    header << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (attributes.quality.size() > 0) header << "property float quality\n";
  header << "element face " << mesh.num_faces() << "\n"
         << "property list uchar int vertex_indices\nend_header\n";
  return header.str();
}

}  // namespace

Mesh ParsePly(const std::string& contents, const std::string& path) {
  const PlyHeader header = ParseHeader(contents, path);
  PlyValueReader reader(contents, header.data_offset, header.format);
  MeshBuilder builder(path);
  for (const PlyElement& element : header.elements) {
    ReadElement(element, &reader, path, &builder);
  }
  return builder.Build();
}

std::string FormatPly(const Mesh& mesh, const VertexAttributes& attributes) {
  std::string out = PlyHeaderText(mesh, attributes);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int axis = 0; axis < 3; ++axis) AppendLittleEndian(mesh.vertices(axis, v), &out);
    if (attributes.normals.size() > 0) {
      for (int axis = 0; axis < 3; ++axis) {
        AppendLittleEndian(static_cast<float>(attributes.normals(axis, v)), &out);
      }
    }
    if (attributes.colors.size() > 0) {
      for (int channel = 0; channel < 3; ++channel) {
        AppendLittleEndian(ColorByte(attributes.colors(channel, v)), &out);
      }
    }
    if (attributes.quality.size() > 0) {
      AppendLittleEndian(static_cast<float>(attributes.quality(v)), &out);
    }
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    AppendLittleEndian(static_cast<uint8_t>(3), &out);
    for (int corner = 0; corner < 3; ++corner) {
      AppendLittleEndian(static_cast<int32_t>(mesh.faces(corner, f)), &out);
    }
  }
  return out;
}

}  // namespace internal
}  // namespace finecap
