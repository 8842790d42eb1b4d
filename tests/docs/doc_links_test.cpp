// Links inside the documentation: the summaries at the top of docs/accuracy-cost.md and
// docs/immersed-boundary.md, and the summary docs/validation.md with its study pages under
// docs/validation/, point at their sections by anchor, so a renamed heading or a moved page must
// fail here rather than leave a dead link for the reader.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kSource = FLOCSIM_SOURCE_DIR;

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The anchor GitHub (and most Markdown renderers) give a heading: lower case, every character
// other than a letter, digit, space, hyphen or underscore dropped, spaces turned into hyphens.
std::string heading_anchor(const std::string& heading) {
  std::string anchor;
  for (const char c : heading) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80 || std::isalnum(u) || c == '-' || c == '_') {
      anchor += static_cast<char>(std::tolower(u));
    } else if (c == ' ') {
      anchor += '-';
    }
  }
  return anchor;
}

// Every anchor a Markdown file offers: one per heading outside code blocks; a repeated heading
// gets -1, -2, ... as GitHub numbers them.
std::set<std::string> anchors_of(const fs::path& file) {
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  std::istringstream lines(read_text(file));
  std::string line;
  bool in_code = false;
  static const std::regex heading(R"(^#{1,6}\s+(.*?)\s*#*\s*$)");
  while (std::getline(lines, line)) {
    if (line.rfind("```", 0) == 0) {
      in_code = !in_code;
      continue;
    }
    std::smatch m;
    if (in_code || !std::regex_match(line, m, heading)) continue;
    const std::string base = heading_anchor(m[1].str());
    const int n = seen[base]++;
    anchors.insert(n == 0 ? base : base + "-" + std::to_string(n));
  }
  return anchors;
}

std::vector<fs::path> documentation_files() {
  std::vector<fs::path> files{kSource / "README.md"};
  for (const auto& entry : fs::recursive_directory_iterator(kSource / "docs")) {
    if (entry.is_regular_file() && entry.path().extension() == ".md") files.push_back(entry.path());
  }
  return files;
}

}  // namespace

TEST(DocLinks, AnchorsFollowGitHubsRule) {
  // Worked by hand from GitHub's rendering of these headings.
  EXPECT_EQ(heading_anchor("The paper's case at a = 4, du = 0 (the non-aggregating baseline)"),
            "the-papers-case-at-a--4-du--0-the-non-aggregating-baseline");
  EXPECT_EQ(heading_anchor("Beyond Re ~ 10: Re_inf = 48 (the standard box at a = 6)"),
            "beyond-re--10-re_inf--48-the-standard-box-at-a--6");
  EXPECT_EQ(heading_anchor("Measured figures (tests)"), "measured-figures-tests");
}

TEST(DocLinks, EveryRelativeLinkNamesAnExistingFileAndSection) {
  static const std::regex link(R"(\]\(([^)\s]+)\))");
  int checked = 0;
  for (const fs::path& file : documentation_files()) {
    const std::string text = read_text(file);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), link);
         it != std::sregex_iterator(); ++it) {
      const std::string target = (*it)[1].str();
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0) continue;
      const auto hash = target.find('#');
      const std::string path_part = target.substr(0, hash);
      const fs::path linked = path_part.empty() ? file : file.parent_path() / path_part;
      ++checked;
      ASSERT_TRUE(fs::exists(linked)) << file << " links to " << target << ": no such file";
      if (hash == std::string::npos || linked.extension() != ".md") continue;
      const std::string anchor = target.substr(hash + 1);
      EXPECT_TRUE(anchors_of(linked).count(anchor))
          << file.lexically_relative(kSource) << " links to " << target << ": "
          << linked.lexically_relative(kSource) << " has no heading with that anchor";
    }
  }
  // The summaries link to their sections; finding none means the pattern above went wrong.
  EXPECT_GT(checked, 20);
}

TEST(DocLinks, TheValidationSummaryLinksEveryStudyPage) {
  // docs/validation.md is a one-screen summary; each study has its own page in docs/validation/,
  // which a reader finds only through the summary's links.
  const std::string summary = read_text(kSource / "docs" / "validation.md");
  int pages = 0;
  for (const auto& entry : fs::directory_iterator(kSource / "docs" / "validation")) {
    if (!entry.is_regular_file() || entry.path().extension() != ".md") continue;
    ++pages;
    const std::string name = entry.path().filename().string();
    EXPECT_NE(summary.find("](validation/" + name), std::string::npos)
        << "docs/validation.md does not link docs/validation/" << name;
  }
  EXPECT_GT(pages, 5);
}
