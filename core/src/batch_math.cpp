// SPDX-License-Identifier: GPL-2.0-or-later
#include "sediment/batch_math.hpp"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__) && defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 22)
#define SEDIMENT_LIBMVEC 1
#include <immintrin.h>
// glibc's vector functions (names of the x86-64 vector ABI; libm.so pulls libmvec in as needed):
// b = SSE2, 2 doubles; d = AVX2, 4 doubles; e = AVX-512, 8 doubles.
extern "C" {
__m128d _ZGVbN2v_exp(__m128d);
__m128d _ZGVbN2v_log(__m128d);
__m256d _ZGVdN4v_exp(__m256d);
__m256d _ZGVdN4v_log(__m256d);
__m512d _ZGVeN8v_exp(__m512d);
__m512d _ZGVeN8v_log(__m512d);
}
#endif

namespace sediment {

namespace {

#ifdef SEDIMENT_LIBMVEC
// A short last group is padded with ones (finite for both functions) to a full vector, or masked:
// each value takes the same function wherever it sits.
SEDIMENT_TARGET_AVX512 void with_avx512(const double *x, double *out, int n, __m512d (*f)(__m512d))
{
  int k = 0;
  for (; k + 8 <= n; k += 8) _mm512_storeu_pd(out + k, f(_mm512_loadu_pd(x + k)));
  if (k == n) return;
  // The lanes past n are ones, loaded from and stored to nowhere.
  const __mmask8 tail = static_cast<__mmask8>((1u << (n - k)) - 1u);
  _mm512_mask_storeu_pd(out + k, tail, f(_mm512_mask_loadu_pd(_mm512_set1_pd(1.0), tail, x + k)));
}

SEDIMENT_TARGET_AVX2 void with_avx2(const double *x, double *out, int n, __m256d (*f)(__m256d))
{
  int k = 0;
  for (; k + 4 <= n; k += 4) _mm256_storeu_pd(out + k, f(_mm256_loadu_pd(x + k)));
  if (k == n) return;
  double padded[4] = {1.0, 1.0, 1.0, 1.0};
  std::copy(x + k, x + n, padded);
  _mm256_storeu_pd(padded, f(_mm256_loadu_pd(padded)));
  std::copy(padded, padded + (n - k), out + k);
}

void with_sse2(const double *x, double *out, int n, __m128d (*f)(__m128d))
{
  int k = 0;
  for (; k + 2 <= n; k += 2) _mm_storeu_pd(out + k, f(_mm_loadu_pd(x + k)));
  if (k == n) return;
  double padded[2] = {x[k], 1.0};
  _mm_storeu_pd(padded, f(_mm_loadu_pd(padded)));
  out[k] = padded[0];
}
#endif

template <class Scalar> void one_by_one(const double *x, double *out, int n, Scalar f)
{
  for (int k = 0; k < n; ++k) out[k] = f(x[k]);
}

}    // namespace

namespace {
// Set at load time, not on first use: read per block and per batch, a guarded static cost about one
// instruction per sphere-step (cost.py --counts). Not for other files' static initialisers.
#if defined(__x86_64__) && defined(__GNUC__)
const bool has_avx2 = (__builtin_cpu_init(), __builtin_cpu_supports("avx2"));
const bool has_avx512 = (__builtin_cpu_init(), __builtin_cpu_supports("avx512f"));
#else
const bool has_avx2 = false;
const bool has_avx512 = false;
#endif
}    // namespace

bool processor_has_avx2() { return has_avx2; }
bool processor_has_avx512() { return has_avx512; }

BatchMath batch_math_kind()
{
#ifdef SEDIMENT_LIBMVEC
  return processor_has_avx512() ? BatchMath::AVX512 : processor_has_avx2() ? BatchMath::AVX2 : BatchMath::SSE2;
#else
  return BatchMath::Scalar;
#endif
}

bool batch_math_available(BatchMath kind)
{
#ifdef SEDIMENT_LIBMVEC
  if (kind == BatchMath::AVX512) return processor_has_avx512();
  return kind != BatchMath::AVX2 || processor_has_avx2();
#else
  return kind == BatchMath::Scalar;
#endif
}

const char *batch_math_name(BatchMath kind)
{
  switch (kind) {
    case BatchMath::SSE2:
      return "sse2";
    case BatchMath::AVX2:
      return "avx2";
    case BatchMath::AVX512:
      return "avx512";
    case BatchMath::Scalar:
      break;
  }
  return "scalar";
}

void exp_many(const double *x, double *out, int n, BatchMath kind)
{
#ifdef SEDIMENT_LIBMVEC
  if (kind == BatchMath::AVX512 && processor_has_avx512()) return with_avx512(x, out, n, _ZGVeN8v_exp);
  if (kind == BatchMath::AVX2 && processor_has_avx2()) return with_avx2(x, out, n, _ZGVdN4v_exp);
  if (kind == BatchMath::SSE2) return with_sse2(x, out, n, _ZGVbN2v_exp);
#endif
  one_by_one(x, out, n, [](double v) { return std::exp(v); });
}

void log_many(const double *x, double *out, int n, BatchMath kind)
{
#ifdef SEDIMENT_LIBMVEC
  if (kind == BatchMath::AVX512 && processor_has_avx512()) return with_avx512(x, out, n, _ZGVeN8v_log);
  if (kind == BatchMath::AVX2 && processor_has_avx2()) return with_avx2(x, out, n, _ZGVdN4v_log);
  if (kind == BatchMath::SSE2) return with_sse2(x, out, n, _ZGVbN2v_log);
#endif
  one_by_one(x, out, n, [](double v) { return std::log(v); });
}

}    // namespace sediment
