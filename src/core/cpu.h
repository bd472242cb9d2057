// What the CPU running the program can do, asked once (the build targets
// plain x86-64; kernels compiled for more are chosen at run time).
#pragma once

namespace pb {

// True where the CPU has AVX2 (x86 only; false elsewhere).
inline bool cpu_has_avx2() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return yes;
#else
  return false;
#endif
}

// True where the CPU has AVX2 and fused multiply-add (x86 only).
inline bool cpu_has_fma() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0 && __builtin_cpu_supports("fma") != 0;
  }();
  return yes;
#else
  return false;
#endif
}

}  // namespace pb
