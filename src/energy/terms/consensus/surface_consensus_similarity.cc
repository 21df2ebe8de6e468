#include "energy/terms/consensus/surface_consensus_similarity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>

#include "energy/terms/consensus/patch_agreement.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

using SampleWeights = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// A sample lies on a triangle: its blend has at most three corners.
constexpr int kMaxCorners = 3;

// The reduced rows of a block (surface_consensus_similarity.h): `rows` (p + 1) and their
// Jacobian `jacobian` ((p + 1) x p, row-major) from its cost s, gradient g and Gauss-Newton
// matrix h = L L^T: the rows L^T with residuals L^-1 g. h is only semi-definite where a corner's
// weights are all but zero, so the factor is of h with its diagonal raised by a share of its
// largest entry too small to change a step (kRelativeRidge), and g lies in h's range (g = J^T r).
void ReducedRows(double s, const Eigen::VectorXd& g, Eigen::MatrixXd* h, double* rows,
                 double* jacobian) {
  constexpr double kRelativeRidge = 1e-12;
  const int p = static_cast<int>(g.size());
  const double largest = h->diagonal().maxCoeff();
  if (!(largest > 0.0)) {  // No derivative at all: the cost alone.
    std::fill_n(rows, p, 0.0);
    rows[p] = std::sqrt(s);
    std::fill_n(jacobian, (p + 1) * p, 0.0);
    return;
  }
  h->diagonal().array() += kRelativeRidge * largest;
  // Factored in place: no allocation per block.
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> factor(*h);
  Eigen::Map<Eigen::VectorXd> reducible(rows, p);
  reducible = factor.matrixL().solve(g);
  for (int i = 0; i < p; ++i) {
    for (int q = 0; q < p; ++q) jacobian[i * p + q] = q >= i ? factor.matrixLLT()(q, i) : 0.0;
  }
  // What of r no step can reduce; rounding may make the difference a hair negative.
  rows[p] = std::sqrt(std::max(0.0, s - reducible.squaredNorm()));
  std::fill_n(jacobian + p * p, p, 0.0);
}

// The corners every sample of patch `b` is blended from, ascending: the unknowns of its block.
std::vector<int> CornersOfPatch(const PixelConsensusSimilarity& patches,
                                const SurfaceSamples& samples, int b) {
  std::vector<int> corners;
  const int* members = patches.Members(b);
  for (int j = 0; j < patches.PatchSize(b); ++j) {
    Require(samples.weights.row(members[j]).nonZeros() <= kMaxCorners,
            "surface consensus similarity", "a sample is blended from at most 3 corners");
    for (SampleWeights::InnerIterator it(samples.weights, members[j]); it; ++it) {
      corners.push_back(static_cast<int>(it.col()));
    }
  }
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  return corners;
}

// The most corners a member of a patch is blended from: 3 where the samples lie inside the faces,
// 2 where the faces are split once (their edges' midpoints are the only samples between
// vertices).
int MostCorners(const PixelConsensusSimilarity& patches, const SurfaceSamples& samples) {
  int most = 0;
  for (int b = 0; b < static_cast<int>(patches.residual_blocks().size()); ++b) {
    const int* members = patches.Members(b);
    for (int j = 0; j < patches.PatchSize(b); ++j) {
      most = std::max(most, static_cast<int>(samples.weights.row(members[j]).nonZeros()));
    }
  }
  return most;
}

// The faces of the mesh the patches' samples lie on, as their corners (ascending), each once:
// those of the samples blended from three corners or, where the faces are split only once, the
// triangles of the edges whose midpoints are samples. Gathered patch by patch, each patch's
// distinct corner sets only, so that the lists grow with the mesh's faces, not with the samples.
std::vector<std::array<int, 3>> FacesOfPatches(const PixelConsensusSimilarity& patches,
                                               const SurfaceSamples& samples) {
  std::vector<std::array<int, 3>> faces, patch_faces;
  std::vector<std::pair<int, int>> edges, patch_edges;
  const auto append_distinct = [](auto* from, auto* to) {
    std::sort(from->begin(), from->end());
    from->erase(std::unique(from->begin(), from->end()), from->end());
    to->insert(to->end(), from->begin(), from->end());
    from->clear();
  };
  for (int b = 0; b < static_cast<int>(patches.residual_blocks().size()); ++b) {
    const int* members = patches.Members(b);
    for (int j = 0; j < patches.PatchSize(b); ++j) {
      std::array<int, 3> corners;
      int count = 0;
      for (SampleWeights::InnerIterator it(samples.weights, members[j]); it; ++it) {
        corners[count++] = static_cast<int>(it.col());
      }
      std::sort(corners.begin(), corners.begin() + count);
      if (count == 3) patch_faces.push_back(corners);
      if (count == 2) patch_edges.push_back({corners[0], corners[1]});
    }
    append_distinct(&patch_faces, &faces);
    append_distinct(&patch_edges, &edges);
  }
  std::vector<std::array<int, 3>> distinct_faces;
  append_distinct(&faces, &distinct_faces);
  if (!distinct_faces.empty()) return distinct_faces;
  std::vector<std::pair<int, int>> distinct_edges;
  append_distinct(&edges, &distinct_edges);
  std::vector<std::vector<int>> adjacent(samples.weights.cols());
  for (const auto& [a, c] : distinct_edges) {
    adjacent[a].push_back(c);
    adjacent[c].push_back(a);
  }
  for (std::vector<int>& list : adjacent) std::sort(list.begin(), list.end());
  for (int v = 0; v < static_cast<int>(adjacent.size()); ++v) {
    for (int a : adjacent[v]) {
      if (a < v) continue;
      for (int c : adjacent[v]) {
        if (c > a && std::binary_search(adjacent[a].begin(), adjacent[a].end(), c)) {
          faces.push_back({v, a, c});
        }
      }
    }
  }
  return faces;
}

// Three colours for the vertices of `faces` such that the corners of a face differ wherever the
// mesh allows it: from a face coloured 0, 1, 2, breadth-first over faces that share an edge, the
// corner opposite a coloured edge takes the colour its two ends leave. That is a proper colouring
// of a mesh whose vertices all have an even number of faces (a regular one, and Loop's
// subdivisions away from the input's own vertices); around the others some faces get two corners
// of one colour. -1 for vertices on no face.
std::vector<int> ColourVertices(const std::vector<std::array<int, 3>>& faces, int num_vertices) {
  // Each face's edges, sorted by their ends, so that the faces around an edge are adjacent.
  std::vector<std::pair<std::pair<int, int>, int>> edges;
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const std::array<int, 3>& v = faces[f];
    edges.push_back({{v[0], v[1]}, f});
    edges.push_back({{v[0], v[2]}, f});
    edges.push_back({{v[1], v[2]}, f});
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<int>> neighbours(faces.size());
  for (size_t begin = 0, end = 0; begin < edges.size(); begin = end) {
    while (end < edges.size() && edges[end].first == edges[begin].first) ++end;
    for (size_t a = begin; a < end; ++a) {
      for (size_t b = begin; b < end; ++b) {
        if (a != b) neighbours[edges[a].second].push_back(edges[b].second);
      }
    }
  }
  std::vector<int> colour(num_vertices, -1);
  std::vector<char> queued(faces.size(), 0);
  std::vector<int> queue;
  for (int seed = 0; seed < static_cast<int>(faces.size()); ++seed) {
    if (queued[seed] != 0) continue;
    queued[seed] = 1;
    queue.assign(1, seed);
    for (size_t head = 0; head < queue.size(); ++head) {
      const std::array<int, 3>& v = faces[queue[head]];
      bool used[3] = {false, false, false};
      for (int corner : v) {
        if (colour[corner] >= 0) used[colour[corner]] = true;
      }
      for (int corner : v) {
        if (colour[corner] >= 0) continue;
        const int left = static_cast<int>(std::find(used, used + 3, false) - used);
        colour[corner] = left < 3 ? left : 0;
        if (left < 3) used[left] = true;
      }
      for (int next : neighbours[queue[head]]) {
        if (queued[next] == 0) {
          queued[next] = 1;
          queue.push_back(next);
        }
      }
    }
  }
  return colour;
}

// The patches through which the term compares every sample between the vertices once, ascending.
// Every patch holds all the faces of its vertex, so that each face is compared in the patches of
// its three corners; comparing it in one compares the same pixels, and costs a third (a third
// of the patches keep half to all of what the term gains on the captures measured,
// docs/measurements.md, 2026-12-06). With samples inside the faces: the patches of one colour of
// ColourVertices, which has a corner on every face of a regular mesh; with the faces split once,
// whose only samples between vertices are the edges' midpoints: two colours, an end of every edge.
// Then the patches that hold a sample between vertices that none of them holds (irregular vertices,
// a mask's cut), in order; of the three choices of colours, the one with the fewest patches.
std::vector<int> FaceCoveringPatches(const PixelConsensusSimilarity& patches,
                                     const SurfaceSamples& samples) {
  const int num_patches = static_cast<int>(patches.residual_blocks().size());
  const std::vector<int> vertex_colour =
      ColourVertices(FacesOfPatches(patches, samples), samples.weights.cols());
  const int between = MostCorners(patches, samples);
  std::vector<char> covered;
  const auto cover = [&](int b) {
    const int* members = patches.Members(b);
    for (int j = 0; j < patches.PatchSize(b); ++j) covered[members[j]] = 1;
  };
  const auto leaves_one_out = [&](int b) {
    const int* members = patches.Members(b);
    for (int j = 0; j < patches.PatchSize(b); ++j) {
      if (covered[members[j]] == 0 && samples.weights.row(members[j]).nonZeros() == between) {
        return true;
      }
    }
    return false;
  };
  // The patches of the colours in `colours` (a bit each), and those that hold a sample between
  // vertices that none of them holds.
  const auto cover_from = [&](int colours) {
    covered.assign(samples.size(), 0);
    std::vector<char> taken(num_patches, 0);
    for (int b = 0; b < num_patches; ++b) {
      const int colour = vertex_colour[patches.residual_blocks()[b].parameters[0]];
      if (colour >= 0 && (colours >> colour & 1) != 0) {
        taken[b] = 1;
        cover(b);
      }
    }
    std::vector<int> chosen;
    for (int b = 0; b < num_patches; ++b) {
      if (taken[b] == 0 && leaves_one_out(b)) {
        taken[b] = 1;
        cover(b);
      }
      if (taken[b] != 0) chosen.push_back(b);
    }
    return chosen;
  };
  // With samples inside the faces one colour has a corner on each; with samples on the edges
  // only, two colours have an end on each edge.
  const std::vector<int> candidates =
      between == kMaxCorners ? std::vector<int>{1, 2, 4} : std::vector<int>{3, 5, 6};
  std::vector<int> best;
  for (size_t c = 0; c < candidates.size(); ++c) {
    std::vector<int> chosen = cover_from(candidates[c]);
    if (c == 0 || chosen.size() < best.size()) best = std::move(chosen);
  }
  return best;
}

// A block's sums over its members in PlainModelOfBlock (whose notation this follows), member
// after member: the inputs, each member's rows of K = 3 C entries, and the sums they add to.
struct MemberSums {
  int n, p;
  bool with_curvature;
  double squared_norm = 0.0;
  const double *s, *w2, *z, *d;
  // Each member's kMaxCorners corners (indices into the block's unknowns) and weights.
  const uint16_t* local;
  const double* corner_weights;
  // zy (K), the Gram matrices (C x C x 3, upper half), the rows per unknown (rho, mu, sigma; rho
  // alone without the curvature), g (p), own and across (p x p).
  double *zy, *gram, *per_unknown, *gradient, *own, *across;
};

// The sums of a block seen by kCameras cameras (0: num_cameras, not known when compiled): with
// the count a constant, the loops over a member's entries are unrolled and vectorised, and the
// channel of an entry is known without a division.
template <int kCameras>
void SumMembers(int num_cameras, MemberSums* sums) {
  const int cameras = kCameras > 0 ? kCameras : num_cameras;
  const int K = 3 * cameras, stride = (sums->with_curvature ? 3 : 1) * K, p = sums->p;
  const double* s = sums->s;
  const double* w2 = sums->w2;
  double row[3 * 3 * (kCameras > 0 ? kCameras : 1)];
  thread_local std::vector<double> dynamic_row;
  if (kCameras == 0) dynamic_row.resize(3 * K);
  double* member_row = kCameras > 0 ? row : dynamic_row.data();
  double squared_norm = 0.0;
  for (int j = 0; j < sums->n; ++j) {
    const double* zj = sums->z + j * K;
    const double* dj = sums->d + j * K;
    double mean[3] = {0.0, 0.0, 0.0}, e[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < cameras; ++a) {
      for (int c = 0; c < 3; ++c) {
        mean[c] += zj[3 * a + c];
        e[c] += s[3 * a + c] * dj[3 * a + c];
      }
    }
    double own_scale = 0.0, gradient_scale = 0.0;
    for (int a = 0; a < cameras; ++a) {
      for (int c = 0; c < 3; ++c) {
        const int t = 3 * a + c;
        const double y = zj[t] - mean[c] / cameras, sd = s[t] * dj[t];
        squared_norm += w2[t] * y * y;
        sums->zy[t] += zj[t] * y;
        own_scale += w2[t] * sd * sd;
        gradient_scale += w2[t] * sd * y;
        member_row[t] = zj[t] * dj[t];
        if (sums->with_curvature) {
          member_row[K + t] = dj[t];
          member_row[2 * K + t] = e[c] * zj[t];
        }
      }
    }
    if (sums->with_curvature) {
      for (int a = 0; a < cameras; ++a) {
        for (int b = a; b < cameras; ++b) {
          for (int c = 0; c < 3; ++c) {
            sums->gram[(a * cameras + b) * 3 + c] += zj[3 * a + c] * zj[3 * b + c];
          }
        }
      }
    }
    const uint16_t* local = sums->local + kMaxCorners * j;
    const double* weights = sums->corner_weights + kMaxCorners * j;
    for (int q = 0; q < kMaxCorners; ++q) {
      const double wi = weights[q];
      sums->gradient[local[q]] += wi * gradient_scale;
      double* unknown_rows = sums->per_unknown + static_cast<size_t>(local[q]) * stride;
      for (int t = 0; t < stride; ++t) unknown_rows[t] += wi * member_row[t];
    }
    if (!sums->with_curvature) continue;
    const double across_scale = w2[0] * e[0] * e[0] + w2[1] * e[1] * e[1] + w2[2] * e[2] * e[2];
    for (int q = 0; q < kMaxCorners; ++q) {
      for (int r = 0; r < kMaxCorners; ++r) {
        const double ww = weights[q] * weights[r];
        sums->own[local[q] * p + local[r]] += ww * own_scale;
        sums->across[local[q] * p + local[r]] += ww * across_scale;
      }
    }
  }
  sums->squared_norm = squared_norm;
}

}  // namespace

SurfaceConsensusSimilarity::SurfaceConsensusSimilarity(const PixelConsensusSimilarity& patches,
                                                       const SurfaceSamples& samples,
                                                       const ConsensusOptions& options)
    : patches_(patches), samples_(samples), options_(options) {
  options_.Check();
  if (options_.surface_patches == SurfacePatches::kFaceCover) {
    patch_of_ = FaceCoveringPatches(patches, samples);
  } else {
    patch_of_.resize(patches.residual_blocks().size());
    std::iota(patch_of_.begin(), patch_of_.end(), 0);
  }
  row_begin_.assign(1, 0);
  jacobian_begin_.assign(1, 0);
  for (int patch : patch_of_) {
    std::vector<int> unknowns = CornersOfPatch(patches, samples, patch);
    const int p = static_cast<int>(unknowns.size());
    blocks_.push_back({std::move(unknowns), p + 1});
    row_begin_.push_back(row_begin_.back() + p + 1);
    jacobian_begin_.push_back(jacobian_begin_.back() + static_cast<long>(p + 1) * p);
  }
  IndexContributions(samples.weights.cols());
  TabulateCorners();
}

void SurfaceConsensusSimilarity::IndexContributions(int num_unknowns) {
  parameter_begin_.assign(1, 0);
  std::vector<int> count(num_unknowns, 0);
  for (const ResidualBlock& block : blocks_) {
    parameter_begin_.push_back(parameter_begin_.back() +
                               static_cast<long>(block.parameters.size()));
    for (int s : block.parameters) ++count[s];
  }
  contribution_begin_.assign(1, 0);
  for (int s = 0; s < num_unknowns; ++s) {
    contribution_begin_.push_back(contribution_begin_.back() + count[s]);
  }
  contributions_.resize(contribution_begin_.back());
  std::vector<long> next(contribution_begin_.begin(), contribution_begin_.end() - 1);
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const std::vector<int>& unknowns = blocks_[b].parameters;
    for (size_t i = 0; i < unknowns.size(); ++i) {
      contributions_[next[unknowns[i]]++] = parameter_begin_[b] + static_cast<long>(i);
    }
  }
}

Eigen::VectorXd SurfaceConsensusSimilarity::Gather(const std::vector<double>& per_block_entry,
                                                   int num_unknowns) const {
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(num_unknowns);
#pragma omp parallel for schedule(static)
  for (int s = 0; s < num_unknowns; ++s) {
    for (long c = contribution_begin_[s]; c < contribution_begin_[s + 1]; ++c) {
      sums[s] += per_block_entry[contributions_[c]];
    }
  }
  return sums;
}

void SurfaceConsensusSimilarity::CornersOfMembers(int block, MemberCorners* corners) const {
  const int n = patches_.PatchSize(patch_of_[block]);
  const int* members = patches_.Members(patch_of_[block]);
  const uint16_t* local = &corner_local_[member_begin_[block] * kMaxCorners];
  corners->local.assign(local, local + n * kMaxCorners);
  corners->weights.assign(corners->local.size(), 0.0);
  for (int j = 0; j < n; ++j) {
    int corner = kMaxCorners * j;
    for (SampleWeights::InnerIterator it(samples_.weights, members[j]); it; ++it, ++corner) {
      corners->weights[corner] = it.value();
    }
  }
}

void SurfaceConsensusSimilarity::TabulateCorners() {
  member_begin_.assign(1, 0);
  for (int b = 0; b < static_cast<int>(blocks_.size()); ++b) {
    member_begin_.push_back(member_begin_.back() + patches_.PatchSize(patch_of_[b]));
  }
  corner_local_.assign(member_begin_.back() * kMaxCorners, 0);
  for (int b = 0; b < static_cast<int>(blocks_.size()); ++b) {
    const std::vector<int>& unknowns = blocks_[b].parameters;
    Require(unknowns.size() <= std::numeric_limits<uint16_t>::max(), "surface consensus similarity",
            "a vertex on more than 65535 faces");
    const int* members = patches_.Members(patch_of_[b]);
    for (int j = 0; j < patches_.PatchSize(patch_of_[b]); ++j) {
      long corner = (member_begin_[b] + j) * kMaxCorners;
      for (SampleWeights::InnerIterator it(samples_.weights, members[j]); it; ++it, ++corner) {
        corner_local_[corner] = static_cast<uint16_t>(
            std::lower_bound(unknowns.begin(), unknowns.end(), it.col()) - unknowns.begin());
      }
    }
  }
}

void SurfaceConsensusSimilarity::ReadNormalised(int block, const Eigen::VectorXd& k,
                                                const MemberCorners& corners,
                                                std::vector<double>* z,
                                                std::vector<double>* derivatives,
                                                std::vector<double>* inverse_deviations) const {
  const int n = patches_.PatchSize(patch_of_[block]),
            num_cameras = patches_.NumCameras(patch_of_[block]);
  const std::vector<int>& unknowns = blocks_[block].parameters;
  thread_local std::vector<double> member_k;
  member_k.assign(n, 0.0);
  for (int j = 0; j < n; ++j) {
    for (int corner = kMaxCorners * j; corner < kMaxCorners * (j + 1); ++corner) {
      member_k[j] += corners.weights[corner] * k[unknowns[corners.local[corner]]];
    }
  }
  const int stride = 3 * n;
  z->resize(static_cast<size_t>(stride) * num_cameras);
  if (derivatives != nullptr) derivatives->resize(z->size());
  patches_.ReadPatch(patch_of_[block], member_k.data(), z->data(),
                     derivatives != nullptr ? derivatives->data() : nullptr);
  inverse_deviations->resize(3 * num_cameras);
  for (int a = 0; a < num_cameras; ++a) {
    internal::NormaliseColors(n, options_.contrast_floor, !options_.gain_per_channel,
                              &(*z)[stride * a], &(*inverse_deviations)[3 * a]);
  }
}

void SurfaceConsensusSimilarity::PlainResidualsOfBlock(int block, const Eigen::VectorXd& k,
                                                       Eigen::VectorXd* residuals,
                                                       Eigen::MatrixXd* jacobian) const {
  const int n = patches_.PatchSize(patch_of_[block]),
            num_cameras = patches_.NumCameras(patch_of_[block]);
  const std::vector<int>& unknowns = blocks_[block].parameters;
  const int m = 3 * n * num_cameras, stride = 3 * n;
  thread_local std::vector<double> derivatives, z, inverse_deviations;
  thread_local MemberCorners corners;
  CornersOfMembers(block, &corners);
  ReadNormalised(block, k, corners, &z, jacobian != nullptr ? &derivatives : nullptr,
                 &inverse_deviations);
  const bool pooled = !options_.gain_per_channel;
  const Eigen::Vector3d weight = patches_.ResidualWeight(patch_of_[block]);
  *residuals = Eigen::Map<const Eigen::VectorXd>(z.data(), m);
  internal::AgainstCameraMean(n, num_cameras, weight, residuals->data());
  if (jacobian == nullptr) return;
  // A colour moves with its own sample's displacement, which corner v moves by the sample's
  // weight on v; each corner's column then goes through the normalisation as one direction of k.
  const int p = static_cast<int>(unknowns.size());
  jacobian->setZero(m, p);
  for (int j = 0; j < n; ++j) {
    for (int corner = kMaxCorners * j; corner < kMaxCorners * (j + 1); ++corner) {
      for (int a = 0; a < num_cameras; ++a) {
        for (int channel = 0; channel < 3; ++channel) {
          const int r = stride * a + 3 * j + channel;
          (*jacobian)(r, corners.local[corner]) += corners.weights[corner] * derivatives[r];
        }
      }
    }
  }
  for (int i = 0; i < p; ++i) {
    double* column = jacobian->col(i).data();
    for (int a = 0; a < num_cameras; ++a) {
      internal::NormaliseDerivative(n, pooled, &z[stride * a], &inverse_deviations[3 * a],
                                    column + stride * a);
    }
    internal::AgainstCameraMean(n, num_cameras, weight, column);
  }
}

void SurfaceConsensusSimilarity::ResidualsOfBlock(int block, const Eigen::VectorXd& k,
                                                  Eigen::VectorXd* residuals,
                                                  Eigen::MatrixXd* jacobian) const {
  PlainResidualsOfBlock(block, k, residuals, jacobian);
  const double c2 = patches_.LossScale(patch_of_[block]);
  const int m = static_cast<int>(residuals->size());
  const double root_weight = std::sqrt(options_.surface_weight);
  if (jacobian != nullptr) {
    for (int i = 0; i < jacobian->cols(); ++i) {
      Eigen::VectorXd plain = *residuals;  // Robustify scales the residuals it is given.
      internal::Robustify(c2, m, plain.data(), jacobian->col(i).data());
    }
    *jacobian *= root_weight;
  }
  internal::Robustify(c2, m, residuals->data(), nullptr);
  *residuals *= root_weight;
}

double SurfaceConsensusSimilarity::PlainModelOfBlock(int block, const Eigen::VectorXd& k,
                                                     Eigen::VectorXd* gradient,
                                                     Eigen::MatrixXd* curvature) const {
  // Notation of the derivation (docs/method.md, "The refined mesh itself"): camera a of the
  // block's C, member m of its n, channel c; z the normalised colours, s_ac their inverse
  // deviations, d the colours' derivatives in their own sample's displacement, W_mi the weight of
  // member m on unknown i, w_c the residuals' weight, y = z - (the cameras' mean of z). A
  // channel of a camera is one of K = 3 C "entries" (index 3 a + c); every per-member and
  // per-unknown quantity below is a row of K entries, so that the sums run over contiguous rows.
  const int n = patches_.PatchSize(patch_of_[block]),
            num_cameras = patches_.NumCameras(patch_of_[block]);
  const int p = static_cast<int>(blocks_[block].parameters.size()), K = 3 * num_cameras;
  const bool with_curvature = curvature != nullptr, pooled = !options_.gain_per_channel;
  thread_local std::vector<double> camera_z, camera_d, s;
  thread_local MemberCorners corners;
  CornersOfMembers(block, &corners);
  ReadNormalised(block, k, corners, &camera_z, &camera_d, &s);
  // z, d and y member after member (ReadPatch writes them camera after camera); w2 and the
  // cameras' Gram matrices of z per channel (gram[(a C + b) 3 + c] = sum_m z_amc z_bmc) per
  // entry.
  thread_local std::vector<double> z, d, w2, zy, gram;
  z.resize(static_cast<size_t>(n) * K);
  d.resize(z.size());
  for (int a = 0; a < num_cameras; ++a) {
    for (int j = 0; j < n; ++j) {
      for (int c = 0; c < 3; ++c) {
        z[j * K + 3 * a + c] = camera_z[3 * (a * n + j) + c];
        d[j * K + 3 * a + c] = camera_d[3 * (a * n + j) + c];
      }
    }
  }
  const Eigen::Vector3d weight = patches_.ResidualWeight(patch_of_[block]);
  w2.resize(K);
  for (int t = 0; t < K; ++t) w2[t] = weight[t % 3] * weight[t % 3];
  zy.assign(K, 0.0);
  gram.assign(with_curvature ? static_cast<size_t>(num_cameras) * num_cameras * 3 : 0, 0.0);

  // Per unknown i, over its members, one row each of mu_i = sum W d, rho_i = sum W z d and
  // sigma_i = sum W E_c z (E_mc = sum_a s_ac d_amc); with only the gradient asked, rho alone.
  const int rows_per_unknown = with_curvature ? 3 : 1;
  const int per_unknown_stride = rows_per_unknown * K;
  thread_local std::vector<double> per_unknown;
  per_unknown.assign(static_cast<size_t>(p) * per_unknown_stride, 0.0);
  gradient->setZero(p);
  // sum_m W_mi W_mj D_m and sum_m W_mi W_mj F_m (D_m = sum_ac w^2 s^2 d^2, F_m = sum_c w^2 E^2).
  thread_local std::vector<double> own, across;
  own.assign(with_curvature ? static_cast<size_t>(p) * p : 0, 0.0);
  across.assign(own.size(), 0.0);
  MemberSums sums;
  sums.n = n;
  sums.p = p;
  sums.with_curvature = with_curvature;
  sums.s = s.data();
  sums.w2 = w2.data();
  sums.z = z.data();
  sums.d = d.data();
  sums.local = corners.local.data();
  sums.corner_weights = corners.weights.data();
  sums.zy = zy.data();
  sums.gram = gram.data();
  sums.per_unknown = per_unknown.data();
  sums.gradient = gradient->data();
  sums.own = own.data();
  sums.across = across.data();
  // The common camera counts compiled for, the others with the count as a variable.
  switch (num_cameras) {
    // clang-format off
    case 2: SumMembers<2>(num_cameras, &sums); break;
    case 3: SumMembers<3>(num_cameras, &sums); break;
    case 4: SumMembers<4>(num_cameras, &sums); break;
    case 5: SumMembers<5>(num_cameras, &sums); break;
    case 6: SumMembers<6>(num_cameras, &sums); break;
    case 7: SumMembers<7>(num_cameras, &sums); break;
    case 8: SumMembers<8>(num_cameras, &sums); break;
    default: SumMembers<0>(num_cameras, &sums);
      // clang-format on
  }
  const double squared_norm = sums.squared_norm;

  // v_i = s beta_i, beta the normalisation's mean of z dq (per channel, or over the three when
  // the gain is pooled): g = sum_m W R_m - sum_ac w^2 v zy.
  thread_local std::vector<double> v;
  v.resize(static_cast<size_t>(p) * K);
  for (int i = 0; i < p; ++i) {
    const double* rho = &per_unknown[static_cast<size_t>(i) * per_unknown_stride];
    double* vi = &v[static_cast<size_t>(i) * K];
    for (int a = 0; a < num_cameras; ++a) {
      const double pooled_beta = (rho[3 * a] + rho[3 * a + 1] + rho[3 * a + 2]) / (3 * n);
      for (int c = 0; c < 3; ++c) {
        const int t = 3 * a + c;
        vi[t] = s[t] * (pooled ? pooled_beta : rho[t] / n);
        (*gradient)[i] -= vi[t] * w2[t] * zy[t];
      }
    }
  }
  if (!with_curvature) return squared_norm;

  // J^T J = A - B / C (the derivation's terms) gathered as
  // H_ij = own_ij - across_ij / C - n sum w^2 u_i u_j + (n / C) sum_c w^2 u_hat_ic u_hat_jc
  //        + sum (v_j x_i - v_i y_j - y_i v_j),
  // with u = s mu / n, u_hat the sum of u over the cameras, y = w^2 (s rho - sigma / C) and
  // x = w^2 (G_aa v - (G v) / C).
  thread_local std::vector<double> u, u_hat, x, y;
  u.resize(v.size());
  x.resize(v.size());
  y.resize(v.size());
  u_hat.assign(static_cast<size_t>(p) * 3, 0.0);
  for (int i = 0; i < p; ++i) {
    const double* rho = &per_unknown[static_cast<size_t>(i) * per_unknown_stride];
    const double* mu = rho + K;
    const double* sigma = rho + 2 * K;
    const double* vi = &v[static_cast<size_t>(i) * K];
    double* ui = &u[static_cast<size_t>(i) * K];
    double* xi = &x[static_cast<size_t>(i) * K];
    double* yi = &y[static_cast<size_t>(i) * K];
    for (int b = 0; b < num_cameras; ++b) {
      for (int c = 0; c < 3; ++c) {
        const int t = 3 * b + c;
        double gv = 0.0;
        for (int a = 0; a < num_cameras; ++a) {
          gv += gram[(std::min(a, b) * num_cameras + std::max(a, b)) * 3 + c] * vi[3 * a + c];
        }
        const double g_bb = gram[(b * num_cameras + b) * 3 + c];
        ui[t] = s[t] * mu[t] / n;
        u_hat[3 * i + c] += ui[t];
        xi[t] = w2[t] * (g_bb * vi[t] - gv / num_cameras);
        yi[t] = w2[t] * (s[t] * rho[t] - sigma[t] / num_cameras);
      }
    }
  }
  curvature->resize(p, p);
  for (int i = 0; i < p; ++i) {
    const double* ui = &u[static_cast<size_t>(i) * K];
    const double* vi = &v[static_cast<size_t>(i) * K];
    const double* xi = &x[static_cast<size_t>(i) * K];
    const double* yi = &y[static_cast<size_t>(i) * K];
    for (int l = i; l < p; ++l) {
      const double* ul = &u[static_cast<size_t>(l) * K];
      const double* vl = &v[static_cast<size_t>(l) * K];
      const double* yl = &y[static_cast<size_t>(l) * K];
      double uu = 0.0, rest = 0.0;
      for (int t = 0; t < K; ++t) {
        uu += w2[t] * ui[t] * ul[t];
        rest += vl[t] * (xi[t] - yi[t]) - vi[t] * yl[t];
      }
      double uu_hat = 0.0;
      for (int c = 0; c < 3; ++c) uu_hat += w2[c] * u_hat[3 * i + c] * u_hat[3 * l + c];
      const double h = own[i * p + l] - across[i * p + l] / num_cameras - n * uu +
                       n * uu_hat / num_cameras + rest;
      (*curvature)(i, l) = (*curvature)(l, i) = h;
    }
  }
  return squared_norm;
}

double SurfaceConsensusSimilarity::BlockModel(int block, const Eigen::VectorXd& k,
                                              Eigen::VectorXd* gradient,
                                              Eigen::MatrixXd* curvature) const {
  const double c2 = patches_.LossScale(patch_of_[block]), weight = options_.surface_weight;
  if (gradient == nullptr) {
    thread_local Eigen::VectorXd residuals;
    PlainResidualsOfBlock(block, k, &residuals, nullptr);
    BlockSummary plain;
    plain.squared_norm = residuals.squaredNorm();
    return weight * internal::Robustify(c2, plain, false).squared_norm;
  }
  double squared_norm = PlainModelOfBlock(block, k, gradient, curvature);
  internal::Robustify(c2, &squared_norm, gradient, curvature);
  *gradient *= weight;
  if (curvature != nullptr) *curvature *= weight;
  return weight * squared_norm;
}

double SurfaceConsensusSimilarity::Evaluate(const Eigen::VectorXd& k,
                                            Eigen::VectorXd* gradient) const {
  const int num_blocks = static_cast<int>(blocks_.size());
  std::vector<double> costs(num_blocks), entries(gradient != nullptr ? parameter_begin_.back() : 0);
#pragma omp parallel
  {
    Eigen::VectorXd block_gradient;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      // No J^T J: the gradient alone.
      costs[b] = BlockModel(b, k, gradient != nullptr ? &block_gradient : nullptr, nullptr);
      if (gradient == nullptr) continue;
      std::copy_n(block_gradient.data(), block_gradient.size(), &entries[parameter_begin_[b]]);
    }
  }
  if (gradient != nullptr) *gradient = -Gather(entries, static_cast<int>(k.size()));
  double sum_of_squares = 0.0;
  for (double cost : costs) sum_of_squares += cost;
  return -0.5 * sum_of_squares;
}

void SurfaceConsensusSimilarity::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  rows_.resize(row_begin_.back());
  row_jacobians_.resize(with_jacobians ? jacobian_begin_.back() : 0);
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel
  {
    Eigen::VectorXd gradient;
    Eigen::MatrixXd curvature;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      double* rows = &rows_[row_begin_[b]];
      if (!with_jacobians) {
        // A cost alone: any rows with its sum of squares.
        rows[0] = std::sqrt(BlockModel(b, k, nullptr, nullptr));
        std::fill_n(rows + 1, blocks_[b].num_residuals - 1, 0.0);
        continue;
      }
      const double squared_norm = BlockModel(b, k, &gradient, &curvature);
      ReducedRows(squared_norm, gradient, &curvature, rows, &row_jacobians_[jacobian_begin_[b]]);
    }
  }
}

void SurfaceConsensusSimilarity::BlockResiduals(int block, double* residuals,
                                                double* jacobian) const {
  const int num_rows = blocks_[block].num_residuals;
  std::copy_n(&rows_[row_begin_[block]], num_rows, residuals);
  if (jacobian != nullptr) {
    std::copy_n(&row_jacobians_[jacobian_begin_[block]],
                jacobian_begin_[block + 1] - jacobian_begin_[block], jacobian);
  }
}

void SurfaceConsensusSimilarity::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  const int num_blocks = static_cast<int>(blocks_.size());
  costs->resize(num_blocks);
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) (*costs)[b] = BlockModel(b, k, nullptr, nullptr);
}

Eigen::VectorXd SurfaceConsensusSimilarity::GaussNewtonDiagonal(const Eigen::VectorXd& k) {
  const int num_blocks = static_cast<int>(blocks_.size());
  std::vector<double> entries(parameter_begin_.back());
#pragma omp parallel
  {
    Eigen::VectorXd gradient;
    Eigen::MatrixXd curvature;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      BlockModel(b, k, &gradient, &curvature);
      for (Eigen::Index i = 0; i < curvature.rows(); ++i) {
        entries[parameter_begin_[b] + i] = curvature(i, i);
      }
    }
  }
  return Gather(entries, static_cast<int>(k.size()));
}

}  // namespace finecap
