// finecap probe: the configured energy along k = alpha * k_true on a frame with ground truth
// (energy_probe.h), printed as a table and drawn as a plot.
#include <stdlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/eval/energy_probe.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// The folder of --out (output.dir); without one, a new folder under the system's temporary
// folder ($TMPDIR, else /tmp): the probe's plot and reference colours are a diagnostic, and the
// current directory is the user's, not the probe's. A new folder each run, so that reference
// colours cached for another capture are never reused.
std::string ProbeOutputFolder(const Config& config, const Capture& capture) {
  if (!config.output.dir.empty()) return internal::PrepareOutputFolder(config, capture);
  std::error_code error;
  const std::filesystem::path temp = std::filesystem::temp_directory_path(error);
  Require(!error, "TMPDIR",
          "no temporary folder for the probe's files (" + error.message() + "): pass --out DIR");
  std::string folder = (temp / "finecap-probe-XXXXXX").string();
  Require(mkdtemp(folder.data()) != nullptr, folder,
          std::string("cannot create the probe's folder: ") + std::strerror(errno) +
              " (pass --out DIR)");
  std::printf("probe: no --out given, writing into %s\n", folder.c_str());
  return folder;
}

}  // namespace

int RunProbe(const Config& configured, int frame_index) {
  Capture capture = internal::OpenConfiguredCapture(configured);
  const Config config = internal::WithSceneLengths(configured, capture, "probe");
  const int frame = frame_index >= 0 ? frame_index : capture.num_frames() - 1;
  Require(frame < capture.num_frames(), "--frame",
          "frame " + std::to_string(frame) + " does not exist in " + capture.directory());
  RequireProbeableFrame(capture, frame);
  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), config.refine,
                            capture.mesh_path(0));
  const std::string out = ProbeOutputFolder(config, capture);
  const ReferenceColors colors = internal::ConfiguredReferenceColors(config, model, &capture, out);
  const EnergyProbe probe = ProbeEnergyAlongTruth(&capture, frame, model, colors, config.refine,
                                                  config.validation.cameras);
  std::printf(
      "probe: frame %s, similarity %s (%s overlap), %d surface Gaussians, %ld pairs, "
      "RMS of k_true %.2f mm\n",
      probe.frame.c_str(), EnumToString(probe.similarity).c_str(),
      EnumToString(probe.overlap).c_str(), probe.num_surface_gaussians, probe.num_pairs,
      1000.0 * probe.rms_truth);
  std::printf("%8s %16s %16s %16s\n", "alpha", "E", "E_sim", "E_quad");
  for (const EnergyProbeSample& sample : probe.samples) {
    std::printf("%8.2f %16.8g %16.8g %16.8g\n", sample.alpha, sample.energy, sample.similarity,
                sample.quadratic);
  }
  const std::string plot_path = out + "/probe_" + probe.frame + ".png";
  WriteEnergyProbePlot(probe, plot_path);
  std::printf("plot: %s\n", plot_path.c_str());
  std::printf("similarity_alpha_optimum: %.3f\n", probe.similarity_optimum);
  std::printf("alpha_optimum: %.3f\n", probe.energy_optimum);
  return 0;
}

}  // namespace finecap
