// OBJ and OFF readers (vertex order kept as in the file) and the OBJ writer.
#include <set>
#include <sstream>

#include "finecap/util/error.h"
#include "io/mesh_io_internal.h"
#include "util/io_util.h"

namespace finecap {
namespace internal {
namespace {

// OBJ statements that carry nothing a triangle mesh needs; any other unknown keyword means the
// file is not an OBJ mesh.
const std::set<std::string> kIgnoredObjStatements = {
    "vt",     "vn",         "vp",        "o",      "g",     "s",        "usemtl",
    "mtllib", "l",          "p",         "cstype", "deg",   "bmat",     "step",
    "curv",   "curv2",      "surf",      "parm",   "trim",  "hole",     "scrv",
    "sp",     "end",        "con",       "mg",     "bevel", "c_interp", "d_interp",
    "lod",    "shadow_obj", "trace_obj", "ctech",  "stech", "maplib",   "usemap"};

// Lines without their `#` comments; empty lines kept so that line numbers stay right.
std::vector<std::string> LinesWithoutComments(const std::string& contents) {
  std::vector<std::string> lines;
  std::istringstream stream(contents);
  for (std::string line; std::getline(stream, line);) {
    lines.push_back(line.substr(0, line.find('#')));
  }
  return lines;
}

std::vector<double> ParseCoordinates(const std::vector<std::string>& tokens, size_t first,
                                     const std::string& where) {
  Require(tokens.size() >= first + 3, where, "a vertex needs three coordinates");
  std::vector<double> xyz(3);
  for (size_t i = 0; i < 3; ++i) {
    Require(ParseDouble(tokens[first + i], &xyz[i]), where,
            "'" + tokens[first + i] + "' is not a number");
  }
  return xyz;
}

// An OBJ face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`: 1-based, or negative counting back from
// the last vertex read so far.
int ParseObjCorner(const std::string& token, int num_vertices, const std::string& where) {
  int index = 0;
  Require(ParseInt(token.substr(0, token.find('/')), &index) && index != 0, where,
          "'" + token + "' is not a vertex reference");
  return index > 0 ? index - 1 : num_vertices + index;
}

}  // namespace

Mesh ParseObj(const std::string& contents, const std::string& path) {
  MeshBuilder builder(path);
  const std::vector<std::string> lines = LinesWithoutComments(contents);
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::vector<std::string> tokens = SplitWhitespace(lines[i]);
    if (tokens.empty()) continue;
    const std::string where = path + " line " + std::to_string(i + 1);
    if (tokens[0] == "v") {
      const std::vector<double> xyz = ParseCoordinates(tokens, 1, where);
      builder.AddVertex(xyz[0], xyz[1], xyz[2]);
    } else if (tokens[0] == "f") {
      std::vector<int> corners;
      for (size_t c = 1; c < tokens.size(); ++c) {
        corners.push_back(ParseObjCorner(tokens[c], builder.num_vertices(), where));
      }
      builder.AddFace(corners, [&] { return where; });
    } else {
      Require(kIgnoredObjStatements.count(tokens[0]) > 0, where,
              "'" + tokens[0] + "' is not an OBJ statement: not an OBJ mesh");
    }
  }
  return builder.Build();
}

// OFF, line by line: a vertex line's numbers after x y z (colours, normals of COFF/NOFF) and a
// face line's after its corners (a colour) are ignored.
Mesh ParseOff(const std::string& contents, const std::string& path) {
  const std::vector<std::string> lines = LinesWithoutComments(contents);
  size_t next = 0;
  auto next_tokens = [&](const std::string& what) {
    while (next < lines.size()) {
      std::vector<std::string> tokens = SplitWhitespace(lines[next++]);
      if (!tokens.empty()) return tokens;
    }
    throw Error(path, "the file ends before " + what);
  };
  std::vector<std::string> tokens = next_tokens("the OFF header");
  const std::string keyword = tokens[0];
  Require(keyword == "OFF" || keyword == "COFF" || keyword == "NOFF" || keyword == "CNOFF", path,
          "is not an OFF file (it does not start with OFF, COFF, NOFF or CNOFF)");
  tokens.erase(tokens.begin());
  if (tokens.empty()) tokens = next_tokens("the OFF counts");
  int num_vertices = 0, num_faces = 0;
  Require(tokens.size() >= 2 && ParseInt(tokens[0], &num_vertices) &&
              ParseInt(tokens[1], &num_faces) && num_vertices >= 0 && num_faces >= 0,
          path, "expected the counts 'VERTICES FACES EDGES' after the OFF keyword");
  MeshBuilder builder(path);
  for (int v = 0; v < num_vertices; ++v) {
    const std::string what = "vertex " + std::to_string(v);
    const std::vector<double> xyz =
        ParseCoordinates(next_tokens(what), 0, path + " (" + what + ")");
    builder.AddVertex(xyz[0], xyz[1], xyz[2]);
  }
  for (int f = 0; f < num_faces; ++f) {
    const std::string where = path + " (face " + std::to_string(f) + ")";
    const std::vector<std::string> face = next_tokens("face " + std::to_string(f));
    int count = 0;
    Require(ParseInt(face[0], &count) && count >= 0 && face.size() >= 1 + size_t(count), where,
            "expected 'N i1 ... iN'");
    std::vector<int> corners(count);
    for (int c = 0; c < count; ++c) {
      Require(ParseInt(face[1 + c], &corners[c]), where, "'" + face[1 + c] + "' is not an index");
    }
    builder.AddFace(corners, [&] { return where; });
  }
  return builder.Build();
}

std::string FormatObj(const Mesh& mesh, const VertexAttributes& attributes) {
  std::ostringstream out;
  out.precision(17);  // Reading back gives the same doubles.
  out << "# finecap mesh: metres, one vertex list shared by every frame\n";
  const bool has_normals = attributes.normals.size() > 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    out << "v " << mesh.vertices(0, v) << " " << mesh.vertices(1, v) << " " << mesh.vertices(2, v);
    if (attributes.colors.size() > 0) {
      out << " " << attributes.colors(0, v) << " " << attributes.colors(1, v) << " "
          << attributes.colors(2, v);
    }
    out << "\n";
  }
  for (int v = 0; has_normals && v < mesh.num_vertices(); ++v) {
    out << "vn " << attributes.normals(0, v) << " " << attributes.normals(1, v) << " "
        << attributes.normals(2, v) << "\n";
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    out << "f";
    for (int corner = 0; corner < 3; ++corner) {
      const int index = mesh.faces(corner, f) + 1;
      out << " " << index;
      if (has_normals) out << "//" << index;
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace internal
}  // namespace finecap
