#include "bench/memory_bandwidth.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>

namespace flocsim::bench {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

namespace {

// Non-temporal store of 4 doubles where AVX is available, plain store otherwise.
inline void stream_store(double* dst, const double* v4) {
#if defined(__AVX__)
  _mm256_stream_pd(dst, _mm256_loadu_pd(v4));
#elif defined(__SSE2__)
  _mm_stream_pd(dst, _mm_loadu_pd(v4));
  _mm_stream_pd(dst + 2, _mm_loadu_pd(v4 + 2));
#else
  std::memcpy(dst, v4, 4 * sizeof(double));
#endif
}

inline void store_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

double* alloc(std::size_t n) {
  auto* p =
      static_cast<double*>(std::aligned_alloc(4096, (n * sizeof(double) + 4095) / 4096 * 4096));
  if (!p) throw std::bad_alloc();
  return p;
}

}  // namespace

std::vector<BandwidthFigure> measure_memory_bandwidth(int threads, std::size_t bytes_per_array,
                                                      int repetitions) {
  const std::size_t n = bytes_per_array / sizeof(double) / 64 * 64;
  double* a = alloc(n);
  double* b = alloc(n);
  double* c = alloc(n);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = 1.0;
    b[i] = 2.0;
    c[i] = 0.5;
  }
  using clock = std::chrono::steady_clock;
  auto time_it = [&](auto&& body) {
    std::vector<double> seconds;
    body();  // warm-up
    for (int r = 0; r < repetitions; ++r) {
      const auto t0 = clock::now();
      body();
      seconds.push_back(std::chrono::duration<double>(clock::now() - t0).count());
    }
    return median(seconds);
  };
  const double s = 1.0000001;
  const double t_copy = time_it([&] {
#pragma omp parallel num_threads(threads)
    {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < n; i += 4) stream_store(c + i, a + i);
      store_fence();
    }
  });
  const double t_triad = time_it([&] {
#pragma omp parallel num_threads(threads)
    {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < n; i += 4) {
        double v[4];
        for (int k = 0; k < 4; ++k) v[k] = b[i + k] + s * c[i + k];
        stream_store(a + i, v);
      }
      store_fence();
    }
  });
  const double t_update = time_it([&] {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::size_t i = 0; i < n; ++i) b[i] *= s;
  });
  // The exact traffic shape of the AA lattice step without its arithmetic:
  // 19 arrays (padded like the lattice's direction arrays) updated in place.
  // Many concurrent streams keep more memory requests in flight than one, so
  // this is often the highest figure and the honest limit for that kernel.
  constexpr int kStreams = 19;
  const std::size_t per = (3 * n / kStreams) / 512 * 512;
  const std::size_t stride = per + 24;  // 4 KiB multiple + 192 bytes
  std::free(a);
  std::free(b);
  std::free(c);
  double* streams = alloc(stride * kStreams);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < per; ++i)
    for (int k = 0; k < kStreams; ++k) streams[k * stride + i] = 1.0;
  const double t_streams = time_it([&] {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::size_t i = 0; i < per; ++i) {
#pragma GCC unroll 19
      for (int k = 0; k < kStreams; ++k) streams[k * stride + i] *= s;
    }
  });
  std::free(streams);
  const double bytes = static_cast<double>(n * sizeof(double));
  const double stream_bytes = static_cast<double>(per * kStreams * sizeof(double));
  return {{"copy (NT stores)", threads, 2 * bytes / t_copy},
          {"triad (NT stores)", threads, 3 * bytes / t_triad},
          {"update (read+write)", threads, 2 * bytes / t_update},
          {"update x19 streams", threads, 2 * stream_bytes / t_streams}};
}

double measure_read_bandwidth(int threads, std::size_t bytes, int repetitions) {
  const std::size_t n = bytes / sizeof(double) / 64 * 64;
  double* a = alloc(n);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < n; ++i) a[i] = 1.0 + 1e-9 * static_cast<double>(i % 7);
  std::vector<double> seconds;
  double keep = 0;
  for (int r = 0; r <= repetitions; ++r) {  // the first is a warm-up
    const auto t0 = std::chrono::steady_clock::now();
    double sum = 0;
#pragma omp parallel num_threads(threads) reduction(+ : sum)
    {
      // eight independent partial sums: one accumulator would wait on each
      // addition's latency (no reassociation without -ffast-math), not on memory
      double lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < n; i += 8)
        for (int k = 0; k < 8; ++k) lane[k] += a[i + k];
      for (double l : lane) sum += l;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    keep += sum;  // used, so the sum is not optimised away
    if (r > 0) seconds.push_back(s);
  }
  std::free(a);
  if (!(keep > 0)) return 0;
  return static_cast<double>(n * sizeof(double)) / median(seconds);
}

}  // namespace flocsim::bench
