// Eight float lanes for the front end's vector kernels (GCC vector extension: AVX on x86-64,
// NEON on ARM), and how those kernels are built. On x86-64 they are also built for AVX2 and
// picked at load time (one register for eight lanes; the baseline splits them); other targets
// (the ARM boards puppets run on) get their own default vectorisation.
#pragma once

#include <cstddef>

namespace lipsyncd::dsp {

inline constexpr std::size_t kVectorLanes = 8;
using FloatLanes = float __attribute__((vector_size(kVectorLanes * sizeof(float))));
using IntLanes = int __attribute__((vector_size(kVectorLanes * sizeof(int))));

}  // namespace lipsyncd::dsp

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define LIPSYNCD_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define LIPSYNCD_VECTOR_CLONES
#endif
