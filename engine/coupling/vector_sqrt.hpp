#pragma once
// x[k] = sqrt(x[k]) for k < n, several at a time where the instruction set
// has it: std::sqrt does not vectorise while it may set errno, and the
// couplings take square roots of every marker's and every covered cell's
// distances each step. Correctly rounded: the values of std::sqrt.
#include <cmath>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace flocsim::coupling {

inline void sqrt_in_place(double* x, int n) {
  int k = 0;
#if defined(__AVX512F__)
  for (; k + 8 <= n; k += 8)
    _mm512_storeu_pd(x + k, _mm512_maskz_sqrt_pd(0xFF, _mm512_loadu_pd(x + k)));
#endif
#if defined(__AVX__)
  for (; k + 4 <= n; k += 4) _mm256_storeu_pd(x + k, _mm256_sqrt_pd(_mm256_loadu_pd(x + k)));
#endif
#if defined(__SSE2__)
  for (; k + 2 <= n; k += 2) _mm_storeu_pd(x + k, _mm_sqrt_pd(_mm_loadu_pd(x + k)));
#endif
  for (; k < n; ++k) x[k] = std::sqrt(x[k]);
}

}  // namespace flocsim::coupling
