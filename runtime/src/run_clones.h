// Internal: KDM_RUN_CLONES compiles a loop for AVX-512 (x86-64-v4), AVX2 and the baseline, picked once by
// the loader (GCC on x86-64; elsewhere the baseline only). The runtime builds with -ffp-contract=off (no
// fused multiply-add), so every clone computes the same operations in the same order: the same bits.
#pragma once

// GCC gives a clone's ifunc and resolver default visibility whatever -fvisibility or a visibility attribute
// says: the loops live in namespace kdm_runs, outside the kdm::* that a shared library's version script
// exports.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define KDM_RUN_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define KDM_RUN_CLONES
#endif
