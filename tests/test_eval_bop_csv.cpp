// BOP results CSV: exact round trip, the toolkit's layout, bad input named by
// file, line and field, and the results file name.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "core/error.h"
#include "core/random.h"
#include "core/rotation.h"
#include "eval/bop_csv.h"

using namespace pb;
namespace fs = std::filesystem;

namespace {

// A private temporary folder, removed when the test program exits.
struct TempDir {
  fs::path dir = fs::temp_directory_path() / ("posebench_test_eval_bop_csv_" + std::to_string(::getpid()));
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};
TempDir g_temp;

std::string temp_path(const std::string& name) {
  fs::create_directories(g_temp.dir);
  return (g_temp.dir / name).string();
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
}

std::string field_of(const std::string& path) {
  try {
    read_bop_results_csv(path);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    return e.field();
  }
  return "<no error>";
}

}  // namespace

TEST(EvalBopCsv, RoundTripIsExact) {
  Rng rng(5);
  std::vector<BopResultRow> rows;
  for (int i = 0; i < 20; ++i) {
    BopResultRow r;
    r.scene_id = i / 7;
    r.im_id = i / 3;
    r.obj_id = 1 + i % 4;
    r.score = rng.uniform();
    r.T_cam_model.R = random_rotation(rng);
    r.T_cam_model.t = Vec3(rng.normal(0, 300), rng.normal(0, 300), rng.uniform(300, 3000));
    r.time_s = r.im_id < 3 ? 0.1 * r.im_id + 1.0 / 3.0 : -1.0;
    rows.push_back(r);
  }
  const std::string path = temp_path("method_tless-test.csv");
  write_bop_results_csv(path, rows);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const std::vector<BopResultRow> back = read_bop_results_csv(path);
  ASSERT_EQ(back.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back[i].scene_id, rows[i].scene_id);
    EXPECT_EQ(back[i].im_id, rows[i].im_id);
    EXPECT_EQ(back[i].obj_id, rows[i].obj_id);
    EXPECT_EQ(back[i].score, rows[i].score);
    EXPECT_EQ(back[i].T_cam_model.R, rows[i].T_cam_model.R);  // bit-exact
    EXPECT_EQ(back[i].T_cam_model.t, rows[i].T_cam_model.t);
    EXPECT_EQ(back[i].time_s, rows[i].time_s);
  }
}

TEST(EvalBopCsv, LayoutIsTheToolkits) {
  BopResultRow r;
  r.scene_id = 3;
  r.im_id = 17;
  r.obj_id = 5;
  r.score = 0.5;
  r.T_cam_model.R << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // 90 degrees about z
  r.T_cam_model.t = Vec3(1.5, -2, 1000);
  r.time_s = 0.25;
  const std::string path = temp_path("layout.csv");
  write_bop_results_csv(path, {r});
  EXPECT_EQ(slurp(path),
            "scene_id,im_id,obj_id,score,R,t,time\n"
            "3,17,5,0.5,0 -1 0 1 0 0 0 0 1,1.5 -2 1000,0.25\n");
}

TEST(EvalBopCsv, ReadsHeaderlessAndCrlf) {
  const std::string path = temp_path("noheader.csv");
  write_text(path, "1,2,3,0.9,1 0 0 0 1 0 0 0 1,10 20 30,-1\r\n1,2,4,0.8,1 0 0 0 1 0 0 0 1,0 0 500,-1\r\n");
  const std::vector<BopResultRow> rows = read_bop_results_csv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].T_cam_model.t, Vec3(10, 20, 30));
  EXPECT_EQ(rows[1].obj_id, 4);
  EXPECT_EQ(rows[1].time_s, -1.0);
}

TEST(EvalBopCsv, BadInputNamesLineAndField) {
  const std::string h = "scene_id,im_id,obj_id,score,R,t,time\n";
  const std::string ok = "1,2,3,0.9,1 0 0 0 1 0 0 0 1,10 20 30,0.5\n";
  const std::string path = temp_path("bad.csv");

  write_text(path, h + ok + "1,2,3,0.9,1 0 0 0 1 0 0 0 1,10 20 30\n");
  EXPECT_EQ(field_of(path), "line 3");
  write_text(path, h + "1,2,3,0.9,1 0 0 0 1 0 0 0,10 20 30,0.5\n");
  EXPECT_EQ(field_of(path), "line 2 R");
  write_text(path, h + "1,2,3,0.9,1 0 0 0 1 0 0 0 1,10 x 30,0.5\n");
  EXPECT_EQ(field_of(path), "line 2 t");
  write_text(path, h + "1,two,3,0.9,1 0 0 0 1 0 0 0 1,10 20 30,0.5\n");
  EXPECT_EQ(field_of(path), "line 2 im_id");
  write_text(path, h + "1,2,3,nan,1 0 0 0 1 0 0 0 1,10 20 30,0.5\n");
  EXPECT_EQ(field_of(path), "line 2 score");
  // Two times for one image.
  write_text(path, h + ok + "1,2,4,0.9,1 0 0 0 1 0 0 0 1,10 20 30,0.7\n");
  EXPECT_EQ(field_of(path), "line 3 time");
  EXPECT_THROW(read_bop_results_csv(temp_path("missing.csv")), InputError);
  // R that is not a rotation: a reflection, a scaled rotation, a shear.
  for (const char* R : {"-1 0 0 0 1 0 0 0 1", "2 0 0 0 2 0 0 0 2", "1 0.1 0 0 1 0 0 0 1"}) {
    write_text(path, h + ok + "1,3,3,0.9," + R + ",10 20 30,0.5\n");
    EXPECT_EQ(field_of(path), "line 3 R") << R;
  }
  write_text(path, h + "1,2,-3,0.9,1 0 0 0 1 0 0 0 1,10 20 30,0.5\n");
  EXPECT_EQ(field_of(path), "line 2 obj_id");

  // The writer refuses two times for one image and leaves no file behind.
  BopResultRow a, b;
  a.time_s = 1.0;
  b.time_s = 2.0;
  const std::string out = temp_path("refused.csv");
  EXPECT_THROW(write_bop_results_csv(out, {a, b}), InputError);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out + ".tmp"));
}

// What the toolkit's check accepts: times of one image within 1 ms, and
// unknown times (negative) beside known ones; R rounded to 6 decimals.
TEST(EvalBopCsv, AcceptsWhatTheToolkitAccepts) {
  const std::string path = temp_path("lenient.csv");
  write_text(path,
             "1,2,3,0.9,0.707107 -0.707107 0 0.707107 0.707107 0 0 0 1,10 20 30,0.5\n"
             "1,2,4,0.9,1 0 0 0 1 0 0 0 1,10 20 30,0.5004\n"
             "1,2,5,0.9,1 0 0 0 1 0 0 0 1,10 20 30,-1\n");
  const std::vector<BopResultRow> rows = read_bop_results_csv(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].line, 1);
  EXPECT_EQ(rows[2].line, 3);
}

TEST(EvalBopCsv, ParsesTheToolkitsFileName) {
  auto n = parse_bop_results_filename("/some/where/cosypose-pbr_lmo-test.csv");
  ASSERT_TRUE(n.has_value());
  EXPECT_EQ(n->method, "cosypose-pbr");
  EXPECT_EQ(n->dataset, "lmo");
  EXPECT_EQ(n->split, "test");
  EXPECT_EQ(n->split_type, "");
  n = parse_bop_results_filename("m_tless-test-primesense.csv");
  ASSERT_TRUE(n.has_value());
  EXPECT_EQ(n->split, "test");
  EXPECT_EQ(n->split_type, "primesense");
  for (const char* bad : {"results.csv", "m_lmo.csv", "m_lmo-test.txt", "_lmo-test.csv", "a_b_c-test.csv", "m_-test.csv"})
    EXPECT_FALSE(parse_bop_results_filename(bad).has_value()) << bad;
}

TEST(EvalBopCsv, ResultsFileName) {
  EXPECT_EQ(bop_results_filename("fpfh_icp", "lmo", "test"), "fpfh-icp_lmo-test.csv");
  EXPECT_EQ(bop_results_filename("cvfh", "posebenchtable", "test"), "cvfh_posebenchtable-test.csv");
  EXPECT_THROW(bop_results_filename("x", "my-set", "test"), InputError);
  EXPECT_THROW(bop_results_filename("x", "lmo", ""), InputError);
}
