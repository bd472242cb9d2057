// The worker pool's share of the cores: N workers x OpenMP threads never
// exceeds the cores unless the user asks for it with OMP_NUM_THREADS. A
// worker keeps a trial's freed buffers for the next trial.
#include <gtest/gtest.h>

#include <malloc.h>

#include <cstdlib>
#include <cstring>

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

// A frame-sized buffer (8 MiB: a 640x480 cloud of 16-byte points is 4.9)
// comes from the heap, not from a mapping of its own, and stays with the
// process once freed. Without keep_freed_memory() glibc maps it (anything
// over 128 KiB before the first free) and unmaps it on free.
TEST(KeepFreedMemory, AFramesBufferStaysWithTheWorker) {
#ifndef __GLIBC__
  GTEST_SKIP() << "glibc's allocator only";
#endif
  if (!pb::kMemoryLimitApplies) GTEST_SKIP() << "AddressSanitizer has its own allocator";
  pb::keep_freed_memory();
  constexpr size_t kBytes = 8u << 20;
  const size_t mapped_before = mallinfo2().hblkhd;
  auto* p = static_cast<char*>(std::malloc(kBytes));
  ASSERT_NE(p, nullptr);
  std::memset(p, 1, kBytes);
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before) << "the buffer got a mapping of its own";
  std::free(p);
  EXPECT_GE(mallinfo2().fordblks, kBytes) << "the freed buffer went back to the kernel";
}

}  // namespace
