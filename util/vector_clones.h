// MOTIONDB_VECTOR_CLONES marks a function whose time goes into short float loops: on x86-64 it
// is compiled twice, for AVX2 and for the baseline the distribution builds for, and the CPU
// picks at load time (the warps ran about 15% faster with AVX2 on the benchmark machine).
// GCC only: clang 14 (the fuzz build's) refuses target_clones on function templates such as
// band_warp.cc's StepRow<S>, and the fuzzers do not need the speed.
#ifndef MOTIONDB_UTIL_VECTOR_CLONES_H_
#define MOTIONDB_UTIL_VECTOR_CLONES_H_

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define MOTIONDB_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define MOTIONDB_VECTOR_CLONES
#endif

#endif  // MOTIONDB_UTIL_VECTOR_CLONES_H_
