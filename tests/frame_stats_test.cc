#include "finecap/refine/frame_stats.h"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;

// Every field set to a value that ToJson's 10 significant digits keep exactly.
FrameStats SampleStats() {
  FrameStats stats;
  stats.frame = "000012";
  stats.solver = "ceres";
  stats.similarity = "surface_color";
  stats.energy_start = -1234.5;
  stats.energy_end = -0.0012345;
  stats.ls_cost_start = 2.5e-12;
  stats.ls_cost_end = 7.25e+30;
  stats.iterations = 17;
  stats.evaluations = 23;
  stats.termination = "CONVERGENCE: \"function\" tolerance\\reached";
  stats.seconds = 1.75;
  stats.seconds_preparation = 0.5;
  stats.seconds_solve = 1.0;
  stats.seconds_evaluation = 0.125;
  stats.seconds_linear_solver = 0.0625;
  stats.seconds_similarity = 0.03125;
  stats.cpu_seconds = 3.375;
  stats.surface_gaussians = 10112;
  stats.image_gaussians = 123456789012L;
  stats.pairs = 821000;
  stats.worse = true;
  stats.kept_input = false;
  stats.prepared_ahead = true;
  stats.rms_coarse_mm = 8.37;
  stats.rms_subdivided_mm = 8.5;
  stats.rms_refined_mm = std::nan("");
  stats.rms_textureless_coarse_mm = 0.0;
  stats.rms_textureless_subdivided_mm = 1.5;
  stats.rms_textureless_refined_mm = -3.25;
  stats.flicker_coarse_mm = 0.875;
  stats.flicker_subdivided_mm = 0.75;
  stats.flicker_refined_mm = std::nan("");
  stats.heldout_ncc_input = 0.5;
  stats.heldout_ncc_subdivided = 0.25;
  stats.heldout_ncc_refined = 0.75;
  stats.heldout_mad_input = 12.5;
  stats.heldout_mad_subdivided = 13.0;
  stats.heldout_mad_refined = 11.0;
  stats.peak_rss_mb = 35.25;
  stats.heap_in_use_mb = 6.5;
  stats.skipped_cameras = {"cam 1", "tab\there", "caf\xC3\xA9"};
  return stats;
}

void ExpectSameReal(double expected, double actual) {
  if (std::isnan(expected)) {
    EXPECT_TRUE(std::isnan(actual));
  } else {
    EXPECT_EQ(expected, actual);
  }
}

TEST(FrameStatsParse, RoundTripsEveryField) {
  const FrameStats stats = SampleStats();
  const FrameStats back = ParseFrameStats(ToJson(stats) + "\n", "stats.jsonl line 1");
  EXPECT_EQ(back.frame, stats.frame);
  EXPECT_EQ(back.solver, stats.solver);
  EXPECT_EQ(back.similarity, stats.similarity);
  EXPECT_EQ(back.termination, stats.termination);
  for (double FrameStats::*field : {&FrameStats::energy_start,
                                    &FrameStats::energy_end,
                                    &FrameStats::ls_cost_start,
                                    &FrameStats::ls_cost_end,
                                    &FrameStats::seconds,
                                    &FrameStats::seconds_preparation,
                                    &FrameStats::seconds_solve,
                                    &FrameStats::seconds_evaluation,
                                    &FrameStats::seconds_linear_solver,
                                    &FrameStats::seconds_similarity,
                                    &FrameStats::cpu_seconds,
                                    &FrameStats::rms_coarse_mm,
                                    &FrameStats::rms_subdivided_mm,
                                    &FrameStats::rms_refined_mm,
                                    &FrameStats::rms_textureless_coarse_mm,
                                    &FrameStats::rms_textureless_subdivided_mm,
                                    &FrameStats::rms_textureless_refined_mm,
                                    &FrameStats::flicker_coarse_mm,
                                    &FrameStats::flicker_subdivided_mm,
                                    &FrameStats::flicker_refined_mm,
                                    &FrameStats::heldout_ncc_input,
                                    &FrameStats::heldout_ncc_subdivided,
                                    &FrameStats::heldout_ncc_refined,
                                    &FrameStats::heldout_mad_input,
                                    &FrameStats::heldout_mad_subdivided,
                                    &FrameStats::heldout_mad_refined,
                                    &FrameStats::peak_rss_mb,
                                    &FrameStats::heap_in_use_mb}) {
    ExpectSameReal(stats.*field, back.*field);
  }
  EXPECT_EQ(back.iterations, 17);
  EXPECT_EQ(back.evaluations, 23);
  EXPECT_EQ(back.surface_gaussians, 10112);
  EXPECT_EQ(back.image_gaussians, 123456789012L);
  EXPECT_EQ(back.pairs, 821000);
  EXPECT_TRUE(back.worse);
  EXPECT_FALSE(back.kept_input);
  EXPECT_TRUE(back.prepared_ahead);
  EXPECT_EQ(back.skipped_cameras, stats.skipped_cameras);
  // Written again, the record is the same text.
  EXPECT_EQ(ToJson(back), ToJson(stats));
}

// A live block counts while it is held and no longer once it is freed.
TEST(HeapInUseMegabytesTest, CountsLiveBlocks) {
  const double before = HeapInUseMegabytes();
  auto block = std::make_unique<char[]>(8 << 20);
  block[0] = 1;
  const double holding = HeapInUseMegabytes();
  block.reset();
  const double after = HeapInUseMegabytes();
#if defined(__SANITIZE_ADDRESS__)
  // The sanitizer's allocator is not glibc's, whose statistics stay as they were.
  EXPECT_EQ(holding, before);
  EXPECT_EQ(after, before);
#else
  EXPECT_GE(holding - before, 8.0);
  EXPECT_LT(after, holding - 7.9);
#endif
}

TEST(FrameStatsParse, WritesTheSkippedCamerasAsAList) {
  FrameStats stats;
  stats.frame = "3";
  EXPECT_NE(ToJson(stats).find("\"skipped_cameras\": []"), std::string::npos);
  stats.skipped_cameras = {"cam0", "cam2"};
  EXPECT_NE(ToJson(stats).find("\"skipped_cameras\": [\"cam0\", \"cam2\"]"), std::string::npos);
}

TEST(FrameStatsParse, ReadsJsonEscapesAndOlderRecords) {
  // A record without the newer keys: they keep their defaults.
  const FrameStats stats =
      ParseFrameStats(R"( {"frame": "a\u00e9\n\/", "iterations": 4e0, "worse": false} )", "rec");
  EXPECT_EQ(stats.frame, "a\xC3\xA9\n/");
  EXPECT_EQ(stats.iterations, 4);
  EXPECT_TRUE(stats.skipped_cameras.empty());
  EXPECT_EQ(stats.solver, "");
  EXPECT_TRUE(std::isnan(stats.flicker_refined_mm));  // Not measured, rather than none.
}

TEST(FrameStatsParse, RefusesMalformedRecordsNamingTheProblem) {
  const std::string where = "out/stats.jsonl line 7";
  const auto parse = [&](const std::string& line) {
    return [line, where] { ParseFrameStats(line, where); };
  };
  ExpectErrorMentions(parse(R"({"frame": "1", "colour": 3})"), {where, "unknown key \"colour\""});
  ExpectErrorMentions(parse(R"({"iterations": 3})"), {where, "missing key \"frame\""});
  ExpectErrorMentions(parse(R"({"frame": 1})"), {where, "\"frame\" must be a string"});
  ExpectErrorMentions(parse(R"({"frame": "1", "iterations": 2.5})"),
                      {where, "\"iterations\" must be an integer"});
  ExpectErrorMentions(parse(R"({"frame": "1", "iterations": 1e300})"), {where, "iterations"});
  ExpectErrorMentions(parse(R"({"frame": "1", "worse": 1})"), {where, "true or false"});
  ExpectErrorMentions(parse(R"({"frame": "1", "seconds": "2"})"), {where, "number or null"});
  ExpectErrorMentions(parse(R"({"frame": "1", "skipped_cameras": [1]})"), {where, "expected '\"'"});
  ExpectErrorMentions(parse(R"({"frame": "1", "frame": "2"})"), {where, "appears twice"});
  ExpectErrorMentions(parse(R"({"frame": "1"} x)"), {where, "after the object", "character 16"});
  ExpectErrorMentions(parse(R"({"frame": "1)"), {where, "unterminated string"});
  ExpectErrorMentions(parse(R"({"frame": "\ud800"})"), {where, "surrogate"});
  ExpectErrorMentions(parse(R"({"frame": "\q"})"), {where, "unknown escape"});
  ExpectErrorMentions(parse(R"({"frame": "1", "seconds": 1e999})"), {where, "expected a value"});
  ExpectErrorMentions(parse(""), {where, "expected '{'"});
  ExpectErrorMentions(parse("{\"frame\": \"a\tb\"}"), {where, "control character"});
}

}  // namespace
}  // namespace finecap
