// The temporal term (temporal_term.h): its pull on one frame's energy, and on a sequence, whose
// frames read the frame before from its saved files.
#include "energy/terms/temporal/temporal_term.h"

#include <cmath>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "energy/terms/prior/input_prior.h"
#include "energy_fixture.h"
#include "finecap/config/config.h"
#include "finecap/io/mesh_io.h"
#include "finecap/refine/run_folder.h"
#include "finecap/refine/sequence.h"
#include "finecap/solvers/solver.h"
#include "finecap/util/error.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::OneWorkerThread;

// A confidence pull too, which the temporal one must join rather than replace.
EnergyOptions PulledOptions() {
  EnergyOptions options;
  options.k_max = 0.01;
  options.confidence_prior = 50;
  return options;
}

// The term's options are the config section energy.temporal: a Check() failure names the key.
TEST(TemporalTermTest, ItsOptionsAreKeysOfTheirOwnSection) {
  EXPECT_EQ(ConfigKeyOfField("TemporalOptions::weight"), "energy.temporal.weight");
  EnergyOptions options;
  options.terms.temporal.weight = -0.1;
  EXPECT_THROW(options.Check(), Error);
  options.terms.temporal.weight = 0.3;
  EXPECT_NO_THROW(options.Check());
}

// The temporal pull (energy.temporal.weight) does nothing until the frame before is known, then
// joins the prior as one quadratic per k_s: the energy drops by exactly 1/2 w H (k_s - before_s)^2
// over the finite targets, H the median data curvature, for every k; the least-squares form
// follows it.
TEST(TemporalTermTest, TheFrameBeforeJoinsThePriorAsOneQuadratic) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6}, 2, 9);
  const Eigen::VectorXd offsets = RandomK(scene.surface.size(), 0.002, 11);
  scene.surface.input_offset.assign(offsets.data(), offsets.data() + offsets.size());
  const FrameEnergy plain(scene.surface, scene.cameras, scene.neighbourhoods, PulledOptions());
  EnergyOptions options = PulledOptions();
  const double weight = 2.0;
  options.terms.temporal.weight = weight;
  FrameEnergy pulled(scene.surface, scene.cameras, scene.neighbourhoods, options);
  const int n = pulled.num_parameters();
  EXPECT_EQ(pulled.pull_curvature(), plain.pull_curvature());
  EXPECT_EQ(pulled.pull_target(), plain.pull_target());

  Eigen::VectorXd before = RandomK(n, 0.003, 12);
  before[1] = std::nan("");  // A vertex the frame before did not refine: not pulled.
  pulled.TakeFrameBefore(before);
  const double h = MedianOfPositive(DataCurvature(&pulled.data_term(0), Eigen::VectorXd::Zero(n)));
  ASSERT_GT(h, 0.0);
  EXPECT_EQ(pulled.pull_curvature()[1], plain.pull_curvature()[1]);
  EXPECT_EQ(pulled.pull_target()[1], plain.pull_target()[1]);
  EXPECT_NEAR(pulled.pull_curvature()[0], plain.pull_curvature()[0] + weight * h,
              1e-12 * pulled.pull_curvature()[0]);

  double constant = std::nan("");
  for (unsigned seed : {20u, 21u, 22u}) {
    const Eigen::VectorXd k = RandomK(n, 0.004, seed);
    double pull = 0.0;
    for (int s = 0; s < n; ++s) {
      if (std::isfinite(before[s])) pull += 0.5 * weight * h * std::pow(k[s] - before[s], 2);
    }
    const double plain_energy = plain.Evaluate(k, nullptr), energy = pulled.Evaluate(k, nullptr);
    // The blend of two quadratics is one quadratic plus a constant: the same at every k.
    const double difference = plain_energy - energy - pull;
    if (std::isnan(constant)) constant = difference;
    EXPECT_NEAR(difference, constant, 1e-9 * std::abs(energy));
    EXPECT_NEAR(LeastSquaresCost(&pulled, k), -energy, 1e-9 * std::abs(energy));
  }
  // Taken again, the frame before replaces itself rather than pulling twice.
  const Eigen::VectorXd curvature = pulled.pull_curvature();
  pulled.TakeFrameBefore(before);
  EXPECT_EQ(pulled.pull_curvature(), curvature);
  EXPECT_THROW(pulled.TakeFrameBefore(Eigen::VectorXd::Zero(n + 1)), Error);
}

// The RMS over the vertices refined in both of the change of k from frame `before` to `after`
// in the run folder `out`, metres.
double ChangeOfK(const std::string& out, const std::string& before, const std::string& after,
                 int num_vertices) {
  const Eigen::VectorXd a =
      ReadDisplacement(FrameFilesIn(out, before, MeshFormat::kPly).displacement, num_vertices);
  const Eigen::VectorXd b =
      ReadDisplacement(FrameFilesIn(out, after, MeshFormat::kPly).displacement, num_vertices);
  double sum2 = 0.0;
  int count = 0;
  for (int v = 0; v < num_vertices; ++v) {
    if (!std::isfinite(a[v]) || !std::isfinite(b[v])) continue;
    sum2 += (b[v] - a[v]) * (b[v] - a[v]);
    ++count;
  }
  return count > 0 ? std::sqrt(sum2 / count) : std::nan("");
}

// energy.temporal.weight pulls each frame's k towards the frame before's: k changes less from
// frame to frame. The pull reads the frame before from its saved files, so frame 1 resumed and
// frame 2 refined by a run of its own give what one run gives.
TEST(TemporalTermTest, HoldsEachFrameOfASequenceNearerTheFrameBefore) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_temporal");
  Capture capture = testing_util::OpenTinyCapture(root, 3);
  const int num_vertices = SequenceModel(capture.ReadCoarseMesh(0), {},
                                         testing_util::QuickSequenceOptions().refine, "test")
                               .num_fine_vertices();
  SequenceOptions free_options = testing_util::QuickSequenceOptions(),
                  pulled_options = testing_util::QuickSequenceOptions();
  free_options.refine.energy.terms.temporal.weight = 0.0;
  pulled_options.refine.energy.terms.temporal.weight = 20.0;
  const std::string free = root + "/free", pulled = root + "/pulled", parts = root + "/parts";
  RefineSequence(&capture, {0, 3}, free_options, free);
  RefineSequence(&capture, {0, 3}, pulled_options, pulled);
  for (const auto& [before, after] :
       {std::pair<std::string, std::string>{"000000", "000001"}, {"000001", "000002"}}) {
    const double free_change = ChangeOfK(free, before, after, num_vertices);
    const double pulled_change = ChangeOfK(pulled, before, after, num_vertices);
    EXPECT_GT(free_change, 0.0) << after;
    EXPECT_LT(pulled_change, 0.5 * free_change) << after;
  }
  // Frame 0 has no frame before: the pull leaves it as it was.
  EXPECT_EQ(FileBytes(FrameFilesIn(pulled, "000000", MeshFormat::kPly).displacement),
            FileBytes(FrameFilesIn(free, "000000", MeshFormat::kPly).displacement));

  testing_util::RefineInParts(&capture, pulled_options, parts);
  for (const std::string frame : {"000001", "000002"}) {
    EXPECT_LT(testing_util::LargestDisplacementDifference(pulled, parts, frame, num_vertices), 1e-9)
        << frame;
  }
}

}  // namespace
}  // namespace finecap
