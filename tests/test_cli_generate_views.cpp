// posebench render-views and export-pcd.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace fs = std::filesystem;

namespace {

// The PCD header's value of KEY (e.g. "WIDTH").
std::string pcd_field(const std::string& text, const std::string& key) {
  const size_t p = text.find("\n" + key + " ");
  if (p == std::string::npos) return "";
  const size_t s = p + key.size() + 2;
  return text.substr(s, text.find('\n', s) - s);
}

}  // namespace

TEST(CliRenderViews, TwelveViewsWithPoses) {
  pbcli::TempDir tmp;
  const auto r = pbcli::run("render-views ls5 --views 12 --resolution 64 --out views", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto index = nlohmann::json::parse(pbcli::slurp(tmp.path + "/views/views.json"));
  ASSERT_EQ(index["list"].size(), 12u);
  int below = 0;
  for (int i = 0; i < 12; ++i) {
    char stem[32];
    std::snprintf(stem, sizeof stem, "view_%04d", i);
    const std::string base = tmp.path + "/views/" + stem;
    ASSERT_TRUE(fs::exists(base + ".png"));
    const std::string pcd = pbcli::slurp(base + ".pcd");
    EXPECT_EQ(pcd_field(pcd, "WIDTH"), "64");
    EXPECT_EQ(pcd_field(pcd, "HEIGHT"), "64");
    const auto j = nlohmann::json::parse(pbcli::slurp(base + ".json"));
    const auto T = j["T_cam_model"].get<std::vector<double>>();
    ASSERT_EQ(T.size(), 16u);
    Eigen::Matrix3d R;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) R(a, b) = T[4 * a + b];
    EXPECT_TRUE((R * R.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-9));
    EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
    // The model origin is straight ahead of the camera.
    EXPECT_NEAR(T[3], 0.0, 1e-6);
    EXPECT_NEAR(T[7], 0.0, 1e-6);
    EXPECT_GT(T[11], 0.0);
    // Camera centre in the model frame: -R^T t; its z is below 0 for views from below.
    const Eigen::Vector3d c = -R.transpose() * Eigen::Vector3d(T[3], T[7], T[11]);
    below += c.z() < 0;
    EXPECT_GT(j["points"].get<int>(), 100);
    EXPECT_EQ(j["cam_K"].size(), 9u);
  }
  EXPECT_EQ(below, 4);
}

TEST(CliRenderViews, BadInput) {
  pbcli::TempDir tmp;
  auto r = pbcli::run("render-views unicorn --views 8 --out v", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unicorn"), std::string::npos) << r.err;
  r = pbcli::run("render-views ls5 --views 0 --out v", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--views"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/v"));
}

TEST(CliExportPcd, OrganizedCloudOfAGeneratedImage) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/t.yaml", "scenario: table\nseed: 2\nimages: 1\nnoise: none\n");
  auto r = pbcli::run("generate t.yaml --out set --quiet", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  r = pbcli::run("export-pcd --dataset set --scene 1 --image 0 --out img.pcd", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string pcd = pbcli::slurp(tmp.path + "/img.pcd");
  EXPECT_EQ(pcd_field(pcd, "WIDTH"), "512");
  EXPECT_EQ(pcd_field(pcd, "HEIGHT"), "512");
  EXPECT_EQ(pcd_field(pcd, "POINTS"), "262144");
  r = pbcli::run("export-pcd --dataset set --scene 1 --image 7 --out bad.pcd", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--image"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/bad.pcd"));
  r = pbcli::run("export-pcd --dataset nowhere --scene 1 --image 0 --out bad.pcd", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("nowhere"), std::string::npos) << r.err;
}
