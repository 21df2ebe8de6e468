// The optional list of vertices to refine (the paper refines cloth regions only).
#ifndef FINECAP_VERTEX_MASK_H_
#define FINECAP_VERTEX_MASK_H_

#include <string>
#include <vector>

namespace finecap {

// Reads 0-based vertex ids separated by whitespace or newlines; `#` starts a comment that runs to
// the end of the line. Returns the ids sorted and without repeats (a file may list an id twice).
// Throws Error naming the file and line for a token that is not an integer or an id outside
// [0, num_vertices), and naming the file when it is missing.
std::vector<int> ReadVertexMask(const std::string& path, int num_vertices);

}  // namespace finecap

#endif  // FINECAP_VERTEX_MASK_H_
