#include "finecap/io/mesh_io.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

// A 3x3 grid of vertices (two triangles per cell), jittered so no coordinate is round.
Mesh MakeGrid() {
  Mesh mesh;
  mesh.vertices.resize(3, 9);
  for (int v = 0; v < 9; ++v) {
    mesh.vertices.col(v) << (v % 3) / 3.0 + 1e-9 * v, (v / 3) / 7.0, std::sin(v) / 11.0;
  }
  mesh.faces.resize(3, 8);
  int f = 0;
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 2; ++col) {
      const int a = row * 3 + col;
      mesh.faces.col(f++) << a, a + 1, a + 4;
      mesh.faces.col(f++) << a, a + 4, a + 3;
    }
  }
  return mesh;
}

VertexAttributes MakeAttributes(const Mesh& mesh) {
  VertexAttributes attributes;
  attributes.normals = ComputeVertexNormals(mesh);
  attributes.colors = Eigen::Matrix3Xd::Zero(3, mesh.num_vertices());
  attributes.quality = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    attributes.colors.col(v) << v / 8.0, 1.0 - v / 8.0, 0.5;
    attributes.quality(v) = 0.001 * v - 0.003;
  }
  return attributes;
}

template <typename T>
T ReadLittleEndian(std::istream& stream) {
  unsigned char bytes[sizeof(T)];
  stream.read(reinterpret_cast<char*>(bytes), sizeof(T));
  uint64_t bits = 0;
  for (size_t i = 0; i < sizeof(T); ++i) bits |= static_cast<uint64_t>(bytes[i]) << (8 * i);
  T value;
  if constexpr (sizeof(T) == 8) {
    std::memcpy(&value, &bits, 8);
  } else if constexpr (sizeof(T) == 4) {
    const uint32_t narrow = static_cast<uint32_t>(bits);
    std::memcpy(&value, &narrow, 4);
  } else {
    value = static_cast<T>(bits);
  }
  return value;
}

TEST(MeshIoTest, PlyRoundTripKeepsVerticesFacesAndAttributes) {
  const std::string path = MakeTempDir("mesh") + "/frame.ply";
  const Mesh mesh = MakeGrid();
  const VertexAttributes attributes = MakeAttributes(mesh);
  WriteMesh(path, mesh, attributes);

  const Mesh read = ReadMesh(path);
  EXPECT_EQ(read.vertices, mesh.vertices);
  EXPECT_EQ(read.faces, mesh.faces);

  // Decode the body by hand against the layout the header announces.
  std::ifstream stream(path, std::ios::binary);
  std::string header, line;
  while (std::getline(stream, line) && line != "end_header") header += line + "\n";
  EXPECT_NE(header.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_NE(header.find("property float quality"), std::string::npos);
  EXPECT_NE(header.find("property uchar red"), std::string::npos);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int axis = 0; axis < 3; ++axis)
      EXPECT_EQ(ReadLittleEndian<double>(stream), mesh.vertices(axis, v));
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_FLOAT_EQ(ReadLittleEndian<float>(stream), attributes.normals(axis, v));
    }
    for (int channel = 0; channel < 3; ++channel) {
      EXPECT_EQ(ReadLittleEndian<uint8_t>(stream),
                std::lround(attributes.colors(channel, v) * 255));
    }
    EXPECT_FLOAT_EQ(ReadLittleEndian<float>(stream), attributes.quality(v));
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    EXPECT_EQ(ReadLittleEndian<uint8_t>(stream), 3);
    for (int corner = 0; corner < 3; ++corner)
      EXPECT_EQ(ReadLittleEndian<int32_t>(stream), mesh.faces(corner, f));
  }
  EXPECT_EQ(stream.peek(), std::char_traits<char>::eof());
}

TEST(MeshIoTest, ObjRoundTripKeepsVerticesFacesAndNormals) {
  const std::string path = MakeTempDir("mesh") + "/frame.obj";
  const Mesh mesh = MakeGrid();
  VertexAttributes attributes;
  attributes.normals = ComputeVertexNormals(mesh);
  WriteMesh(path, mesh, attributes, MeshFormat::kObj);

  const Mesh read = ReadMesh(path);
  EXPECT_EQ(read.vertices, mesh.vertices);
  EXPECT_EQ(read.faces, mesh.faces);
  std::ifstream stream(path);
  int normal = 0;
  for (std::string line; std::getline(stream, line);) {
    if (line.rfind("vn ", 0) != 0) continue;
    std::istringstream values(line.substr(3));
    Eigen::Vector3d n;
    values >> n.x() >> n.y() >> n.z();
    EXPECT_EQ(n, attributes.normals.col(normal)) << normal;
    ++normal;
  }
  EXPECT_EQ(normal, mesh.num_vertices());
}

TEST(MeshIoTest, PlyAsciiKeepsFileOrderDuplicatesAndUnusedVertices) {
  const std::string path = MakeTempDir("mesh") + "/frame.ply";
  WriteText(path,
            "ply\nformat ascii 1.0\ncomment made by hand\n"
            "element vertex 5\nproperty float y\nproperty double x\nproperty float z\n"
            "property uchar red\n"
            "element face 2\nproperty list uchar int vertex_index\n"
            "property list uchar float texcoord\n"
            "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
            "0 1 0 255\n0 0 0 1\n1 0 0 2\n1 1 0 3\n0 0 0 4\n"
            "3 1 0 2 6 0 0 1 0 0 1\n3 0 3 2 0\n"
            "0 1\n");
  const Mesh mesh = ReadMesh(path);
  ASSERT_EQ(mesh.num_vertices(), 5);  // The coincident vertices 1 and 4 stay apart.
  EXPECT_EQ(mesh.vertices.col(0), Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(mesh.vertices.col(2), Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(mesh.vertices.col(4), Eigen::Vector3d(0, 0, 0));
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(mesh.faces.col(0), Eigen::Vector3i(1, 0, 2));
  EXPECT_EQ(mesh.faces.col(1), Eigen::Vector3i(0, 3, 2));
}

// Appends `value` big-endian.
template <typename T>
void AppendBigEndian(T value, std::string* out) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const uint16_t one = 1;
  if (*reinterpret_cast<const uint8_t*>(&one) == 1) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

TEST(MeshIoTest, ReadsBigEndianPly) {
  const std::string path = MakeTempDir("mesh") + "/frame.ply";
  std::string contents =
      "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nproperty short flags\n"
      "element face 1\nproperty list uchar uint vertex_indices\nend_header\n";
  const float coordinates[3][3] = {{0.5f, -1.25f, 2.0f}, {3.0f, 0.0f, 1.0f}, {-0.75f, 4.0f, 8.0f}};
  for (const auto& vertex : coordinates) {
    for (float value : vertex) AppendBigEndian(value, &contents);
    AppendBigEndian(static_cast<int16_t>(-3), &contents);
  }
  AppendBigEndian(static_cast<uint8_t>(3), &contents);
  for (uint32_t index : {2u, 0u, 1u}) AppendBigEndian(index, &contents);
  WriteText(path, contents);

  const Mesh mesh = ReadMesh(path);
  ASSERT_EQ(mesh.num_vertices(), 3);
  EXPECT_EQ(mesh.vertices.col(0), Eigen::Vector3d(0.5, -1.25, 2.0));
  EXPECT_EQ(mesh.vertices.col(2), Eigen::Vector3d(-0.75, 4.0, 8.0));
  EXPECT_EQ(mesh.faces.col(0), Eigen::Vector3i(2, 0, 1));

  WriteText(path, contents.substr(0, contents.size() - 5));
  ExpectErrorMentions([&] { ReadMesh(path); }, {path, "face 0", "ends early"});
}

TEST(MeshIoTest, ObjCornerFormsAndNegativeIndices) {
  const std::string path = MakeTempDir("mesh") + "/frame.obj";
  WriteText(path,
            "# exported\nmtllib x.mtl\no body\n"
            "v 0 0 0\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nv 1 1 0\n"
            "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
            "usemtl skin\ns off\n"
            "f 1/1/1 2/2/1 3/3/1\n"
            "f 2//1 4//1 3//1  # trailing comment\n"
            "f -3/2 -1/1 -2/3\n");
  const Mesh mesh = ReadMesh(path);
  ASSERT_EQ(mesh.num_vertices(), 4);
  ASSERT_EQ(mesh.num_faces(), 3);
  EXPECT_EQ(mesh.faces.col(0), Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.faces.col(1), Eigen::Vector3i(1, 3, 2));
  EXPECT_EQ(mesh.faces.col(2), Eigen::Vector3i(1, 3, 2));
  EXPECT_EQ(mesh.vertices.col(1), Eigen::Vector3d(1, 0, 0));
}

TEST(MeshIoTest, ReadsOff) {
  const std::string path = MakeTempDir("mesh") + "/frame.off";
  WriteText(path,
            "COFF\n# a comment\n4 2 0\n"
            "0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n1 1 0.5 9 9 9 255\n"
            "3 0 1 2\n3 1 3 2 200 10 10\n");
  const Mesh mesh = ReadMesh(path);
  ASSERT_EQ(mesh.num_vertices(), 4);
  EXPECT_EQ(mesh.vertices.col(3), Eigen::Vector3d(1, 1, 0.5));
  ASSERT_EQ(mesh.num_faces(), 2);
  EXPECT_EQ(mesh.faces.col(1), Eigen::Vector3i(1, 3, 2));
}

TEST(MeshIoTest, OtherFormatsGoThroughAssimp) {
  const std::string path = MakeTempDir("mesh") + "/frame.stl";
  WriteText(path,
            "solid t\n"
            "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
            "endfacet\n"
            "facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
            "endfacet\nendsolid t\n");
  const Mesh mesh = ReadMesh(path);
  ASSERT_EQ(mesh.num_faces(), 2);
  ASSERT_EQ(mesh.num_vertices(), 6);  // STL shares no vertices.
  for (int f = 0; f < 2; ++f) {
    for (int corner = 0; corner < 3; ++corner) EXPECT_EQ(mesh.faces(corner, f), 3 * f + corner);
  }
  EXPECT_EQ(mesh.vertices.col(4), Eigen::Vector3d(1, 1, 0));
}

TEST(MeshIoTest, PolygonsAreRefused) {
  const std::string path = MakeTempDir("mesh") + "/frame.obj";
  WriteText(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  ExpectErrorMentions([&] { ReadMesh(path); }, {path, "line 5", "4 corners"});
}

TEST(MeshIoTest, FilesThatAreNotMeshesAreNamed) {
  const std::string dir = MakeTempDir("mesh");
  for (const std::string name : {"a.ply", "a.obj", "a.off", "a.stl", "a.txt"}) {
    WriteText(dir + "/" + name, "hello, this is a shopping list\n");
    try {
      ReadMesh(dir + "/" + name);
      ADD_FAILURE() << name;
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find(dir + "/" + name), std::string::npos)
          << error.what();
    }
  }
  ExpectErrorMentions([&] { ReadMesh(dir + "/a.ply"); }, {"is not a PLY file"});
  ExpectErrorMentions([&] { ReadMesh(dir + "/a.obj"); }, {"line 1", "not an OBJ statement"});
  ExpectErrorMentions([&] { ReadMesh(dir + "/a.off"); }, {"is not an OFF file"});
  WriteText(dir + "/empty.obj", "");
  ExpectErrorMentions([&] { ReadMesh(dir + "/empty.obj"); }, {"empty.obj", "no triangles"});
}

TEST(MeshIoTest, NonFiniteVerticesAreRefused) {
  const std::string dir = MakeTempDir("mesh");
  for (const std::string value : {"nan", "inf", "-inf"}) {
    WriteText(dir + "/a.obj", "v 0 0 0\nv 1 " + value + " 0\nv 0 1 0\nf 1 2 3\n");
    ExpectErrorMentions([&] { ReadMesh(dir + "/a.obj"); }, {"a.obj", "NaN or infinite"});
  }
  Mesh mesh = MakeGrid();
  mesh.vertices(1, 4) = std::numeric_limits<double>::quiet_NaN();
  // Written by hand: WriteMesh refuses it too.
  ExpectErrorMentions([&] { WriteMesh(dir + "/b.ply", mesh); }, {"b.ply", "NaN or infinite"});
  EXPECT_FALSE(std::filesystem::exists(dir + "/b.ply"));
}

TEST(MeshIoTest, MissingFileAndBadIndicesAreNamed) {
  const std::string dir = MakeTempDir("mesh");
  ExpectErrorMentions([&] { ReadMesh(dir + "/none.ply"); }, {"none.ply", "not found"});
  ExpectErrorMentions([&] { ReadMesh(dir + "/none.dae"); }, {"none.dae", "not found"});
  WriteText(dir + "/a.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  ExpectErrorMentions([&] { ReadMesh(dir + "/a.off"); }, {"a.off", "does not exist"});
}

TEST(MeshIoTest, WriterChecksAttributeSizes) {
  const std::string dir = MakeTempDir("mesh");
  const Mesh mesh = MakeGrid();
  VertexAttributes attributes;
  attributes.quality = Eigen::VectorXd::Zero(3);
  ExpectErrorMentions([&] { WriteMesh(dir + "/a.ply", mesh, attributes); },
                      {"a.ply", "quality", "3 entries for 9 vertices"});
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  ExpectErrorMentions([&] { WriteMesh(dir + "/no/such/folder/a.ply", mesh); }, {"a.ply"});
}

}  // namespace
}  // namespace finecap
