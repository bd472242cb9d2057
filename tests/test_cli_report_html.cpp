// posebench report --html: one self-contained page (nothing fetched from a
// network or another file) with the tables, robustness as k/n with its
// interval, and a gallery of each method's worst failures and successes as
// inline overlays; rendered in headless Chromium (scripts/html_screenshot.sh),
// every gallery image loads and a screenshot is written.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

#include "cli_test_util.h"
#include "io/png.h"
#include "test_cli_run_scene.h"

namespace fs = std::filesystem;

TEST(CliReportHtml, SelfContainedPageWithGalleryRendersInChromium) {
  pbcli::TempDir tmp;
  auto r = pbcli::run_small_experiment(tmp.path, "htmltest", "[cvfh, esf]");
  ASSERT_EQ(r.code, 0) << r.err;
  r = pbcli::run("report res --format md --html", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string html = pbcli::slurp(tmp.path + "/res/report.html");

  // What the gallery must hold: per method min(3, failures) + min(2, successes).
  std::map<std::string, std::pair<int, int>> counts;  // method -> (correct, not)
  std::ifstream in(tmp.path + "/res/records.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    auto& c = counts[j["descriptor"].get<std::string>() + "+" + j["refinement"].get<std::string>()];
    (j.value("correct", false) ? c.first : c.second)++;
  }
  ASSERT_EQ(counts.size(), 2u);
  size_t expected = 0;
  for (const auto& [m, c] : counts) {
    expected += std::min(c.first, 2) + std::min(c.second, 3);
    EXPECT_NE(html.find("<h3>" + m + "</h3>"), std::string::npos) << m;
    // The robustness cell: k/n and an interval.
    EXPECT_NE(html.find(std::to_string(c.first) + "/" + std::to_string(c.first + c.second) + " <span class=ci>["),
              std::string::npos)
        << m;
  }
  // Inline PNGs (std::regex overflows the stack on 100 kB matches: by hand).
  const std::string tag = "src=\"data:image/png;base64,";
  size_t imgs = 0;
  for (size_t at = html.find(tag); at != std::string::npos; at = html.find(tag, at + 1)) {
    const size_t end = html.find('"', at + tag.size());
    ASSERT_NE(end, std::string::npos);
    const std::string b64 = html.substr(at + tag.size(), end - at - tag.size());
    EXPECT_EQ(b64.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/="), std::string::npos);
    EXPECT_EQ(b64.compare(0, 8, "iVBORw0K"), 0);  // the PNG signature
    ++imgs;
  }
  EXPECT_EQ(imgs, expected);
  // Self-contained: no resource from a network or another file.
  for (const char* ref : {"src=\"http", "href=\"http", "src=\"file", "href=\"file", "<link", "@import"})
    EXPECT_EQ(html.find(ref), std::string::npos) << ref;

  if (std::system("command -v chromium >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "chromium not installed (scripts/setup.sh installs Debian's chromium): the rendering is not checked";
  const std::string cmd = "cd '" + tmp.path + "' && '" + POSEBENCH_SOURCE_DIR +
                          "/scripts/html_screenshot.sh' res/report.html shot.png 1280,1600 > status.txt 2>&1";
  const int rc = std::system(cmd.c_str());
  const std::string status = pbcli::slurp(tmp.path + "/status.txt");
  EXPECT_EQ(rc, 0) << status;
  EXPECT_NE(status.find("images loaded: " + std::to_string(expected) + " of " + std::to_string(expected)),
            std::string::npos)
      << status;
  const pb::PngHeader h = pb::read_png_header(tmp.path + "/shot.png");
  EXPECT_EQ(h.width, 1280);
  EXPECT_EQ(h.height, 1600);
}
