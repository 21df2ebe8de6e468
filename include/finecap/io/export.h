// Writing a refined sequence where animation tools read it: a PC2 point cache of the vertex
// positions of every frame (Blender's Mesh Cache modifier, 3ds Max's Point Cache, Maya via
// cacheFile -pc2), and per-frame PLY meshes that carry the displacement as vertex quality.
#ifndef FINECAP_EXPORT_H_
#define FINECAP_EXPORT_H_

#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/mesh.h"

namespace finecap {

// The 32-byte header of a PC2 file, all fields little-endian:
//   bytes  0..11  "POINTCACHE2\0"   signature
//   bytes 12..15  int32   version, always 1
//   bytes 16..19  int32   num_points, vertices per sample
//   bytes 20..23  float32 start_frame, the frame of the first sample
//   bytes 24..27  float32 sample_rate, frames between samples (1: one sample per frame)
//   bytes 28..31  int32   num_samples
// followed by num_samples * num_points float32 x, y, z triples, sample after sample.
struct Pc2Header {
  int num_points = 0;
  float start_frame = 0.0f;
  float sample_rate = 1.0f;
  int num_samples = 0;
};

// Writes a PC2 file one sample (frame) at a time, so memory does not grow with the length of
// the sequence. The file is written under a temporary name next to `path` and renamed into
// place by Finish(); a writer destroyed before Finish() (an interrupted run, an exception)
// removes its temporary and leaves `path` untouched. Coordinates are stored as float32 in the
// unit of the mesh (metres).
class Pc2Writer {
 public:
  // Throws Error naming `path` unless num_points > 0, start_frame is finite, sample_rate is
  // positive and finite, and the temporary file can be created.
  Pc2Writer(const std::string& path, int num_points, float start_frame = 0.0f,
            float sample_rate = 1.0f);
  ~Pc2Writer();
  Pc2Writer(const Pc2Writer&) = delete;
  Pc2Writer& operator=(const Pc2Writer&) = delete;

  // Appends one sample: one column per point. Throws Error naming the file and the sample when
  // the point count differs from the header's, a coordinate is not finite, the write fails, or
  // the cache is already finished.
  void Append(const Eigen::Matrix3Xd& points);

  // Writes the sample count into the header and renames the file into place. Throws Error
  // naming the file on failure or when called twice.
  void Finish();

  int num_samples() const { return header_.num_samples; }

 private:
  void RequireOpen() const;

  std::string path_;
  std::string temporary_path_;
  std::ofstream stream_;
  Pc2Header header_;
  bool finished_ = false;
};

// A whole PC2 file in memory: its header and samples[s].col(p) the position of point p in
// sample s.
struct Pc2Cache {
  Pc2Header header;
  std::vector<Eigen::Matrix3Xf> samples;
};

// Reads a PC2 file. Throws Error naming the file when it is missing, lacks the signature, has a
// version other than 1, negative counts, or a size that disagrees with its header.
Pc2Cache ReadPc2(const std::string& path);

// Writes `mesh` as binary PLY with `displacement` (one value per vertex, metres, e.g. the
// refined k) as the vertex property "quality", which MeshLab and Blender can colour by. Written
// atomically; throws Error naming the file when `displacement` has the wrong size or the write
// fails.
void WriteDisplacementPly(const std::string& path, const Mesh& mesh,
                          const Eigen::VectorXd& displacement);

}  // namespace finecap

#endif  // FINECAP_EXPORT_H_
