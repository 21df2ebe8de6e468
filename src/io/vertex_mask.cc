#include "finecap/io/vertex_mask.h"

#include <algorithm>
#include <sstream>

#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {

std::vector<int> ReadVertexMask(const std::string& path, int num_vertices) {
  std::istringstream stream(internal::ReadWholeFile(path));
  std::vector<int> ids;
  int line_number = 0;
  for (std::string line; std::getline(stream, line);) {
    ++line_number;
    const std::string where = path + " line " + std::to_string(line_number);
    for (const std::string& token : internal::SplitWhitespace(line.substr(0, line.find('#')))) {
      int id = 0;
      Require(internal::ParseInt(token, &id), where, "'" + token + "' is not a vertex id");
      Require(id >= 0 && id < num_vertices, where,
              "vertex id " + token + " is out of range: the mesh has " +
                  std::to_string(num_vertices) + " vertices");
      ids.push_back(id);
    }
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

}  // namespace finecap
