// The energy's terms stay behind their registry (src/energy/term_registry.cc): outside the term
// folders, the registry and the option that names the choice, no source tests a similarity's
// kind or casts a term to find out what it is, so that a new term changes its folder and the
// registry, not the solvers, refine or eval.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace finecap {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = FINECAP_SOURCE_DIR;

// Whether `path` (relative to the source folder) may name a term's kind: the terms themselves,
// their registry, and the option whose values the kinds are.
bool MayNameKinds(const std::string& path) {
  return path.rfind("src/energy/terms/", 0) == 0 || path == "src/energy/term_registry.cc" ||
         path == "src/energy/energy_options.cc" ||
         path == "include/finecap/energy/energy_options.h";
}

// The library's sources and public headers, relative to the source folder.
std::vector<std::string> LibrarySources() {
  std::vector<std::string> paths;
  for (const char* root : {"src", "include", "tools"}) {
    for (const auto& entry : fs::recursive_directory_iterator(kSourceDir / root)) {
      const std::string extension = entry.path().extension().string();
      if (entry.is_regular_file() && (extension == ".cc" || extension == ".h")) {
        paths.push_back(fs::relative(entry.path(), kSourceDir).string());
      }
    }
  }
  return paths;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(EnergyRegistry, NoSourceOutsideItTestsATermsKind) {
  const std::vector<std::string> paths = LibrarySources();
  ASSERT_GT(paths.size(), 100u);  // The walk found the library.
  int registry_mentions = 0;
  for (const std::string& path : paths) {
    const std::string text = ReadText(kSourceDir / path);
    if (path == "src/energy/term_registry.cc") {
      registry_mentions += text.find("SimilarityType::") != std::string::npos;
    }
    EXPECT_EQ(text.find("dynamic_cast"), std::string::npos) << path << " casts to find a kind";
    if (MayNameKinds(path)) continue;
    EXPECT_EQ(text.find("SimilarityType::"), std::string::npos)
        << path << " names a similarity's kind: ask the registry (similarity_needs.h) instead";
  }
  EXPECT_EQ(registry_mentions, 1);  // The check above reads the files it means to.
}

}  // namespace
}  // namespace finecap
