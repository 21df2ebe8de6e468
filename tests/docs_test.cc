// The documentation stays true to the code: the configuration reference is the table the schema
// generates, the README stays short, and every relative link of README.md and docs/*.md points
// to a file (and, into a Markdown page, to a heading) that exists.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/config/config.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = FINECAP_SOURCE_DIR;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// README.md and every page of docs/.
std::vector<fs::path> MarkdownPages() {
  std::vector<fs::path> pages = {kSourceDir / "README.md"};
  for (const fs::directory_entry& entry : fs::directory_iterator(kSourceDir / "docs")) {
    if (entry.path().extension() == ".md") pages.push_back(entry.path());
  }
  std::sort(pages.begin() + 1, pages.end());
  return pages;
}

// The anchor GitHub gives a heading: lower case, punctuation (and any non-ASCII character)
// dropped, spaces turned into hyphens; a repeated heading gets -1, -2, ...
std::string Anchor(const std::string& heading) {
  std::string anchor;
  for (const char c : heading) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u >= 0x80) continue;
    if (std::isalnum(u) || c == '-' || c == '_') {
      anchor += static_cast<char>(std::tolower(u));
    } else if (c == ' ') {
      anchor += '-';
    }
  }
  return anchor;
}

std::set<std::string> Anchors(const fs::path& page) {
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  bool fenced = false;
  for (const std::string& line : Lines(ReadText(page))) {
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    if (fenced || line.empty() || line[0] != '#') continue;
    const size_t text = line.find_first_not_of('#');
    if (text == std::string::npos || line[text] != ' ') continue;
    std::string anchor = Anchor(line.substr(text + 1));
    const int count = seen[anchor]++;
    if (count > 0) anchor += "-" + std::to_string(count);
    anchors.insert(anchor);
  }
  return anchors;
}

TEST(Docs, ConfigurationIsTheGeneratedTable) {
  Config defaults;
  const std::string table = MakeConfigSchema(&defaults).MarkdownTable();
  ASSERT_FALSE(table.empty());
  const std::string page = ReadText(kSourceDir / "docs" / "configuration.md");
  const size_t start = page.find("\n| key |");
  ASSERT_NE(start, std::string::npos) << "docs/configuration.md holds no table of config keys";
  EXPECT_EQ(page.substr(start + 1), table)
      << "docs/configuration.md is not the table `finecap --config_keys_markdown` prints; "
         "regenerate its table with that command";
  EXPECT_EQ(page.substr(0, start).find('|'), std::string::npos)
      << "docs/configuration.md has table rows before the generated table";
}

TEST(Docs, ReadmeIsShort) {
  const size_t lines = Lines(ReadText(kSourceDir / "README.md")).size();
  EXPECT_LE(lines, 300u) << "README.md has " << lines << " lines; move details into docs/";
}

TEST(Docs, RelativeLinksResolve) {
  const std::regex link(R"(\]\(([^()\s]+)\))");
  int checked = 0;
  for (const fs::path& page : MarkdownPages()) {
    const std::string name = fs::relative(page, kSourceDir).string();
    bool fenced = false;
    int number = 0;
    for (const std::string& line : Lines(ReadText(page))) {
      ++number;
      if (line.rfind("```", 0) == 0) fenced = !fenced;
      if (fenced) continue;
      for (std::sregex_iterator it(line.begin(), line.end(), link), end; it != end; ++it) {
        const std::string target = (*it)[1].str();
        if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0) continue;
        const size_t hash = target.find('#');
        const std::string file = target.substr(0, hash);
        const std::string anchor = hash == std::string::npos ? "" : target.substr(hash + 1);
        const fs::path resolved = file.empty() ? page : page.parent_path() / file;
        ++checked;
        if (!fs::exists(resolved)) {
          ADD_FAILURE() << name << ":" << number << ": the link " << target << " points to no file";
          continue;
        }
        if (!anchor.empty() && resolved.extension() == ".md") {
          EXPECT_EQ(Anchors(resolved).count(anchor), 1u)
              << name << ":" << number << ": the link " << target << " points to no heading of "
              << fs::relative(resolved, kSourceDir).string();
        }
      }
    }
  }
  EXPECT_GT(checked, 10) << "the pages link to each other less than expected";
}

}  // namespace
}  // namespace finecap
