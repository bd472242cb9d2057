// The worker pool's share of the cores: N workers x OpenMP threads never
// exceeds the cores unless the user asks for it with OMP_NUM_THREADS.
#include <gtest/gtest.h>

#include <cstdlib>

#include "runner/pool.h"

namespace {

struct UnsetOmp : ::testing::Test {
  void SetUp() override { unsetenv("OMP_NUM_THREADS"); }
  void TearDown() override { unsetenv("OMP_NUM_THREADS"); }
};

TEST_F(UnsetOmp, CoresAreSharedOutAmongTheWorkers) {
  EXPECT_EQ(pb::omp_threads_per_worker(1, 2), 2);
  EXPECT_EQ(pb::omp_threads_per_worker(2, 2), 1);
  EXPECT_EQ(pb::omp_threads_per_worker(3, 8), 2);
  EXPECT_EQ(pb::omp_threads_per_worker(4, 2), 1);  // never below one thread
}

TEST_F(UnsetOmp, TheUsersSettingWins) {
  setenv("OMP_NUM_THREADS", "3", 1);
  EXPECT_EQ(pb::omp_threads_per_worker(2, 2), 3);
}

TEST_F(UnsetOmp, AnUnusableSettingIsIgnored) {
  for (const char* v : {"0", "-2", "two", "3x"}) {
    setenv("OMP_NUM_THREADS", v, 1);
    EXPECT_EQ(pb::omp_threads_per_worker(2, 4), 2) << v;
  }
}

}  // namespace
