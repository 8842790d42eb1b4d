#pragma once
// STREAM-like memory bandwidth probes, measured in the same run as the kernel
// they bound. Arrays are far larger than the last-level cache. Stores that do
// not read their line first (copy, triad) use non-temporal stores, as STREAM
// does when tuned; "update" (a[i] = s * a[i]) reads and writes the same line,
// which is the traffic shape of the in-place AA lattice-Boltzmann step.
#include <cstddef>
#include <string>
#include <vector>

namespace flocsim::bench {

struct BandwidthFigure {
  std::string kernel;
  int threads;
  double bytes_per_second;  // median over repetitions
};

// Measures copy (NT stores), triad (NT stores) and in-place update with the
// given number of threads; `repetitions` timings each, median reported.
std::vector<BandwidthFigure> measure_memory_bandwidth(int threads, std::size_t bytes_per_array,
                                                      int repetitions);

// A read-only stream (a sum over one array, `threads` threads): the traffic
// shape of a reduction over the lattice, such as the liquid averages.
// Median over `repetitions`, bytes read per second.
double measure_read_bandwidth(int threads, std::size_t bytes, int repetitions);

double median(std::vector<double> v);

}  // namespace flocsim::bench
