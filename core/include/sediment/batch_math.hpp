// SPDX-License-Identifier: GPL-2.0-or-later
// e^x and ln x of many values at once, for the per-atom loops that need one or more of each per atom
// and step (the drag step's exponentials, the Di Felice hindrance). On x86-64 with glibc they are the
// vector functions of glibc's libmvec (8 values per call where the processor has AVX-512, 4 with
// AVX2, else 2 with SSE2), within 4 ulp of std::exp and std::log; elsewhere std::exp and std::log
// one by one.
// Every value goes through the same function wherever it sits in the batch, so a sphere's result
// does not depend on which others share its batch (nor on how atoms are spread over MPI ranks).
#pragma once

// The attributes that compile a function for AVX2 or for AVX-512 F beside the default build, so that
// the per-atom loops inlined into it run in vectors of that width (no fused multiply-adds: the build
// keeps -ffp-contract=off, so every width rounds alike). Empty off x86-64 GCC/Clang, where
// batch_math_available() never picks those kinds.
#if defined(__x86_64__) && defined(__GNUC__)
#define SEDIMENT_TARGET_AVX2 __attribute__((target("avx2")))
#define SEDIMENT_TARGET_AVX512 __attribute__((target("avx512f")))
#else
#define SEDIMENT_TARGET_AVX2
#define SEDIMENT_TARGET_AVX512
#endif

namespace sediment {

enum class BatchMath { Scalar, SSE2, AVX2, AVX512 };
// Every kind, for the tests and benchmarks that compare them.
inline constexpr BatchMath batch_math_kinds[] = {BatchMath::Scalar, BatchMath::SSE2, BatchMath::AVX2,
                                                 BatchMath::AVX512};

// Whether this processor runs AVX2 instructions (checked once per process; false off x86-64 GCC/Clang):
// what every function with an AVX2 path asks.
bool processor_has_avx2();
bool processor_has_avx512();    // AVX-512 F, which the AVX512 kind needs

// The fastest kind this build has on this processor (decided once per process), and whether a
// kind runs here at all (Scalar always does).
BatchMath batch_math_kind();
bool batch_math_available(BatchMath kind);
const char *batch_math_name(BatchMath kind);

// out[k] = e^x[k] and ln x[k], k < n; out may be x. Special values as std::exp and std::log.
// With a kind that is not available here, the scalar functions run.
void exp_many(const double *x, double *out, int n, BatchMath kind = batch_math_kind());
void log_many(const double *x, double *out, int n, BatchMath kind = batch_math_kind());

}    // namespace sediment
