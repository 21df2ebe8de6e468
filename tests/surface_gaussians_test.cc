#include "finecap/surface_gaussians.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "finecap/error.h"

namespace finecap {
namespace {

ReferenceColors SomeColors() {
  ReferenceColors colors;
  colors.color_space = ColorSpace::kChromaticity;
  colors.sigma_hat = 0.0055;
  colors.method = ReferenceColorSource::kImageModel;
  colors.colors = {Eigen::Vector3f(0.1f, 0.25f, 0.6f), Eigen::Vector3f(0.3f, 0.3f, 0.3f),
                   Eigen::Vector3f(0.0f, 0.0f, 0.0f)};
  colors.valid = {1, 1, 0};
  return colors;
}

std::string TempPath(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / name).string();
}

TEST(ReferenceColorsTest, RoundTripKeepsEveryField) {
  const std::string path = TempPath("colors_round_trip.txt");
  const ReferenceColors written = SomeColors();
  WriteReferenceColors(path, written);
  const ReferenceColors read = ReadReferenceColors(path, 3);
  EXPECT_EQ(read.color_space, written.color_space);
  EXPECT_DOUBLE_EQ(read.sigma_hat, written.sigma_hat);
  EXPECT_EQ(read.method, ReferenceColorSource::kImageModel);
  EXPECT_EQ(read.valid, written.valid);
  for (int v = 0; v < 3; ++v) EXPECT_LT((read.colors[v] - written.colors[v]).norm(), 1e-7f);
}

TEST(ReferenceColorsTest, WrongVertexCountAndTruncationAreNamed) {
  const std::string path = TempPath("colors_count.txt");
  WriteReferenceColors(path, SomeColors());
  try {
    ReadReferenceColors(path, 4);
    FAIL() << "expected an Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("colors_count.txt"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("made for 3 vertices"), std::string::npos);
  }
  std::string text;
  {
    std::ifstream stream(path);
    text.assign(std::istreambuf_iterator<char>(stream), {});
  }
  std::ofstream(path) << text.substr(0, text.size() - 12);  // Cut the last vertex line.
  EXPECT_THROW(ReadReferenceColors(path, 3), Error);
}

}  // namespace
}  // namespace finecap
