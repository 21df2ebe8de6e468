// finecap compare: the compare section of a config (variants checked against the schema), the
// summary of a variant's records against hand computations, solver traces as CSV, and the whole
// command on a tiny synthetic capture, plus its bad input.
#include "finecap/eval/comparison.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/solvers/solver_trace.h"
#include "finecap/synth/synth.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::WriteText;

constexpr char kTwoVariants[] =
    "compare:\n"
    "  variants:\n"
    "    - name: ceres\n"
    "      set: {solver.max_iterations: 3}\n"
    "    - name: ascent\n"
    "      set:\n"
    "        solver: {type: gradient_ascent, max_iterations: 4}\n"
    "        energy.w_reg: 2.5e-7\n";

TEST(CompareConfigTest, VariantsApplyDottedAndNestedSettingsInOrder) {
  const std::string file = MakeTempDir("compare_config") + "/two.yaml";
  WriteText(file, kTwoVariants);
  const Config config = LoadConfig(file, {});
  ASSERT_EQ(config.compare.variants.size(), 2u);
  EXPECT_EQ(config.compare.variants[1].name, "ascent");
  EXPECT_EQ(config.refine.solver.type, SolverType::kCeres);  // The shared config is left as it is.

  const Config ceres = VariantConfig(config, config.compare.variants[0]);
  EXPECT_EQ(ceres.refine.solver.type, SolverType::kCeres);
  EXPECT_EQ(ceres.refine.solver.max_iterations, 3);
  const Config ascent = VariantConfig(config, config.compare.variants[1]);
  EXPECT_EQ(ascent.refine.solver.type, SolverType::kGradientAscent);
  EXPECT_EQ(ascent.refine.solver.max_iterations, 4);
  EXPECT_DOUBLE_EQ(ascent.refine.energy.w_reg, 2.5e-7);
  EXPECT_DOUBLE_EQ(ascent.refine.energy.color_cutoff, config.refine.energy.color_cutoff);
}

TEST(CompareConfigTest, BadVariantsNameTheFileAndTheVariant) {
  const std::string dir = MakeTempDir("compare_bad");
  const auto expect_refused = [&](const std::string& name, const std::string& variants,
                                  const std::vector<std::string>& parts) {
    const std::string file = dir + "/" + name + ".yaml";
    WriteText(file, "compare:\n  variants:\n" + variants);
    std::vector<std::string> expected = {name + ".yaml"};
    expected.insert(expected.end(), parts.begin(), parts.end());
    ExpectErrorMentions([&] { LoadConfig(file, {}); }, expected);
  };
  expect_refused("unknown_key", "    - {name: fast, set: {solver.tipe: lbfgs}}\n",
                 {"variant 'fast'", "solver.tipe", "unknown key"});
  expect_refused("bad_choice", "    - {name: odd, set: {solver.type: newton}}\n",
                 {"variant 'odd'", "solver.type", "newton"});
  expect_refused("out_of_range", "    - {name: neg, set: {energy.w_reg: -1}}\n",
                 {"variant 'neg'", "energy.w_reg", "outside"});
  expect_refused("shared_key", "    - {name: elsewhere, set: {output.dir: /tmp/x}}\n",
                 {"variant 'elsewhere'", "output.dir", "share"});
  expect_refused("bad_name", "    - {name: ../up}\n", {"variant '../up'", "name"});
  expect_refused("no_name", "    - {set: {solver.type: lbfgs}}\n", {"variant 1", "name"});
  expect_refused("twice", "    - {name: a}\n    - {name: a}\n", {"two variants", "'a'"});
  const std::string file = dir + "/reference.yaml";
  WriteText(file, "compare:\n  reference: c\n  variants:\n    - {name: a}\n    - {name: b}\n");
  ExpectErrorMentions([&] { LoadConfig(file, {}); },
                      {"reference.yaml", "compare.reference", "'c'", "[a, b]"});
}

FrameStats Record(double energy_end, double rms_coarse, double rms_refined, double seconds) {
  FrameStats stats;
  stats.solver = "ceres";
  stats.similarity = "surface_color";
  stats.energy_end = energy_end;
  stats.ls_cost_end = -energy_end;
  stats.iterations = 4;
  stats.evaluations = 6;
  stats.rms_coarse_mm = rms_coarse;
  stats.rms_refined_mm = rms_refined;
  stats.rms_textureless_refined_mm = std::nan("");
  stats.seconds = seconds;
  stats.seconds_solve = seconds / 2;
  return stats;
}

TEST(ComparisonTest, SummaryMatchesAHandComputation) {
  std::vector<FrameStats> frames = {Record(-3.0, 6.0, 3.0, 1.0), Record(-1.0, 8.0, 4.0, 5.0),
                                    Record(-2.0, 0.0, 0.0, 2.0)};
  // The first frame has no flicker: the others' are pooled.
  frames[1].flicker_refined_mm = 1.0;
  frames[2].flicker_refined_mm = 7.0;
  const VariantSummary row = SummarizeVariant("v", frames, {-10.0, -20.0, -30.0});
  EXPECT_DOUBLE_EQ(row.flicker_textured_mm, 5.0);
  EXPECT_EQ(row.frames, 3);
  EXPECT_DOUBLE_EQ(row.energy_end, -2.0);
  EXPECT_DOUBLE_EQ(row.ls_cost_end, 2.0);
  EXPECT_DOUBLE_EQ(row.paper_similarity, -20.0);
  EXPECT_DOUBLE_EQ(row.rms_input_mm, std::sqrt((36.0 + 64.0) / 3));
  EXPECT_DOUBLE_EQ(row.rms_textured_mm, std::sqrt((9.0 + 16.0) / 3));
  EXPECT_DOUBLE_EQ(row.detail_recovered, 0.5);
  EXPECT_TRUE(std::isnan(row.rms_textureless_mm));
  EXPECT_DOUBLE_EQ(row.seconds_per_frame, 2.0);  // The median, not the mean (8/3).
  EXPECT_DOUBLE_EQ(row.seconds_solve, 1.0);
  EXPECT_DOUBLE_EQ(row.iterations, 4.0);

  VariantSummary ascent = row;
  ascent.name = "ascent";
  ascent.solver = "gradient_ascent";
  ascent.seconds_per_frame = 4.0;
  std::vector<VariantSummary> rows = {row, ascent};
  EXPECT_EQ(ReferenceVariant(rows, ""), 1);  // The first gradient ascent by default.
  EXPECT_EQ(ReferenceVariant(rows, "v"), 0);
  ExpectErrorMentions([&] { ReferenceVariant(rows, "w"); }, {"reference variant", "'w'"});
  SetTimeRatios(1, &rows);
  EXPECT_DOUBLE_EQ(rows[0].time_ratio, 0.5);
  EXPECT_DOUBLE_EQ(rows[1].time_ratio, 1.0);

  std::istringstream csv(ComparisonCsv(rows));
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(header.rfind("variant,solver,similarity,frames,energy_end,", 0), 0u) << header;
  EXPECT_EQ(first.rfind("v,ceres,surface_color,3,-2,-20,2,", 0), 0u) << first;
  EXPECT_NE(first.find(",nan,"), std::string::npos) << first;
  EXPECT_EQ(std::count(first.begin(), first.end(), ','),
            std::count(header.begin(), header.end(), ','));
  const std::string markdown = ComparisonMarkdown(rows);
  EXPECT_EQ(std::count(markdown.begin(), markdown.end(), '\n'), 4);
  EXPECT_NE(markdown.find("| ascent | gradient_ascent |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| n/a |"), std::string::npos) << markdown;
}

TEST(ComparisonTest, FrameStatsReadBackWhatRefineWrites) {
  FrameStats written = Record(-2.5, 7.0, 3.5, 1.25);
  written.frame = "000004";
  written.kept_input = true;
  const std::string dir = MakeTempDir("stats");
  WriteText(dir + "/000004.json", ToJson(written) + "\n");
  const FrameStats read = ReadFrameStats(dir + "/000004.json");
  EXPECT_EQ(read.frame, "000004");
  EXPECT_EQ(read.solver, "ceres");
  EXPECT_DOUBLE_EQ(read.energy_end, -2.5);
  EXPECT_DOUBLE_EQ(read.seconds_solve, 0.625);
  EXPECT_EQ(read.evaluations, 6);
  EXPECT_TRUE(read.kept_input);
  EXPECT_TRUE(std::isnan(read.rms_textureless_refined_mm));  // Written as null.
  WriteText(dir + "/bad.json", "{\"frame\": \"1\", \"solver\": 3}\n");
  ExpectErrorMentions([&] { ReadFrameStats(dir + "/bad.json"); }, {"bad.json", "solver"});
  ExpectErrorMentions([&] { ReadFrameStats(dir + "/none.json"); }, {"none.json", "cannot open"});
}

TEST(ComparisonTest, SummaryRefusesMismatchedInputs) {
  ExpectErrorMentions([] { SummarizeVariant("v", {}, {}); }, {"v", "no refined frame"});
  ExpectErrorMentions([] { SummarizeVariant("v", {Record(-1, 1, 1, 1)}, {}); },
                      {"v", "paper E_sim"});
}

TEST(SolverTraceTest, CsvRoundTripsAndNamesTheBadLine) {
  const std::vector<SolverIteration> trace = {{0, -12.5, 0.0}, {1, -9.75, 0.25}, {2, -9.5, 0.5}};
  const std::string dir = MakeTempDir("trace");
  WriteText(dir + "/t.csv", SolverTraceCsv(trace));
  const std::vector<SolverIteration> read = ReadSolverTraceCsv(dir + "/t.csv");
  ASSERT_EQ(read.size(), 3u);
  EXPECT_EQ(read[2].iteration, 2);
  EXPECT_DOUBLE_EQ(read[1].energy, -9.75);
  EXPECT_DOUBLE_EQ(read[2].seconds, 0.5);
  WriteText(dir + "/bad.csv", "iteration,energy,seconds\n0,-1,0\n1,oops,0.1\n");
  ExpectErrorMentions([&] { ReadSolverTraceCsv(dir + "/bad.csv"); }, {"bad.csv", "line 3"});
  WriteText(dir + "/headless.csv", "0,-1,0\n");
  ExpectErrorMentions([&] { ReadSolverTraceCsv(dir + "/headless.csv"); },
                      {"headless.csv", "header"});
}

SynthOptions TinyCaptureWithPlainBand() {
  SynthOptions options = testing_util::TinySynthOptions();
  options.texture.textureless_begin = 0.4;
  options.texture.textureless_end = 0.7;
  return options;
}

std::vector<std::string> CsvLines(const std::string& path) {
  std::istringstream text(FileBytes(path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  return lines;
}

bool IsPng(const std::string& path) {
  return FileBytes(path).compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

TEST(CompareCommandTest, WritesTablesVariantFoldersPlotsAndReport) {
  const std::string root = MakeTempDir("compare_run");
  const std::string capture = root + "/capture";
  GenerateSyntheticCapture(TinyCaptureWithPlainBand(), capture);
  WriteText(root + "/compare.yaml", kTwoVariants);
  const Config config = LoadConfig(root + "/compare.yaml", {{"capture.dir", capture, "--capture"},
                                                            {"output.dir", root + "/out", "--out"},
                                                            {"runtime.threads", "1", "--threads"}});
  ASSERT_EQ(RunCompare(config), 0);

  const std::string out = root + "/out";
  const std::vector<std::string> lines = CsvLines(out + "/comparison.csv");
  ASSERT_EQ(lines.size(), 3u);  // Header and one row per variant.
  const auto header_fields = std::count(lines[0].begin(), lines[0].end(), ',');
  for (int row = 1; row <= 2; ++row) {
    std::istringstream fields(lines[row]);
    std::string field;
    for (int column = 0; std::getline(fields, field, ','); ++column) {
      if (column < 3) continue;  // Variant, solver, similarity.
      EXPECT_TRUE(std::isfinite(std::stod(field))) << "row " << row << " column " << column;
    }
    EXPECT_EQ(std::count(lines[row].begin(), lines[row].end(), ','), header_fields);
  }
  EXPECT_EQ(lines[1].rfind("ceres,ceres,", 0), 0u);
  EXPECT_EQ(lines[2].rfind("ascent,gradient_ascent,", 0), 0u);
  const std::string markdown = FileBytes(out + "/comparison.md");
  EXPECT_NE(markdown.find("| ceres |"), std::string::npos);
  EXPECT_NE(markdown.find("| ascent |"), std::string::npos);

  for (const std::string variant : {"ceres", "ascent"}) {
    for (const std::string frame : {"000000", "000001"}) {
      EXPECT_TRUE(fs::exists(out + "/" + variant + "/meshes/" + frame + ".ply"));
      EXPECT_TRUE(fs::exists(out + "/" + variant + "/k/" + frame + ".txt"));
      EXPECT_GE(ReadSolverTraceCsv(out + "/" + variant + "/traces/" + frame + ".csv").size(), 2u);
    }
  }
  // The two variants take the reference colours the same way: one computation, shared.
  EXPECT_EQ(FileBytes(out + "/ceres/reference_colors.txt"),
            FileBytes(out + "/ascent/reference_colors.txt"));
  EXPECT_TRUE(IsPng(out + "/convergence_iterations.png"));
  EXPECT_TRUE(IsPng(out + "/convergence_time.png"));
  const std::string report = FileBytes(out + "/report.html");
  EXPECT_NE(report.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(report.find("gradient_ascent"), std::string::npos);

  // A variant's folder is a refined run like any other.
  Config ascent = VariantConfig(config, config.compare.variants[1]);
  ascent.output.dir = out + "/ascent";
  EXPECT_EQ(RunEval(ascent), 0);
}

TEST(CompareCommandTest, ABadVariantFailsBeforeWritingAnything) {
  const std::string root = MakeTempDir("compare_refused");
  WriteText(
      root + "/bad.yaml",
      "compare:\n  variants:\n    - {name: ok}\n    - {name: typo, set: {solver.iters: 3}}\n");
  ExpectErrorMentions(
      [&] {
        RunCompare(LoadConfig(root + "/bad.yaml", {{"capture.dir", root + "/none", "--capture"},
                                                   {"output.dir", root + "/out", "--out"}}));
      },
      {"bad.yaml", "variant 'typo'", "solver.iters", "unknown key"});
  WriteText(root + "/empty.yaml", "compare:\n  variants: []\n");
  ExpectErrorMentions(
      [&] {
        RunCompare(LoadConfig(root + "/empty.yaml", {{"output.dir", root + "/out", "--out"}}));
      },
      {"compare.variants", "no variants"});
  EXPECT_EQ(testing_util::FilesIn(root), (std::vector<std::string>{"bad.yaml", "empty.yaml"}));
}

}  // namespace
}  // namespace finecap
