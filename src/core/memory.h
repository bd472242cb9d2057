// The process's allocator policy (glibc's malloc), for the programs that
// time recognition: the runner's workers and the benchmarks.
#pragma once

namespace pb {

// Called once by each runner worker (runner/pool.h) and by each benchmark
// binary (bench/keep_freed_memory.cpp, so that bench/ times what a worker
// runs): a trial's freed buffers stay with the process for the next trial.
// A worker runs one trial after another, and a trial's
// large buffers (the 640x480 cloud, the voxel grid's keys, the normals) are
// freed at its end; glibc gives them back to the kernel (blocks from 128 KiB
// to a few MiB come from mmap, and the heap's free top beyond about twice
// the largest such block is trimmed), so the next trial would fault every
// page in again, and what ran before would decide a method's time: without
// this policy, PPF alone on the table frames spent 13.9 ms in
// preprocessing, 9.0 ms after CVFH had grown the heap
// (results/bench/README.md). Kept as
// latency-sensitive programs do: blocks under 64 MiB from the heap, and up to
// 1 GiB of freed heap not returned. It changes when memory goes back, never a
// result; a worker's resident size stays near its peak. glibc only (a no-op
// elsewhere and under AddressSanitizer, which has its own allocator).
void keep_freed_memory();

}  // namespace pb
