#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/lattice_gpu/cuda_check.hpp"
#include "engine/lattice_gpu/cuda_launch.hpp"
#include "engine/lattice_gpu/gpu_runtime.hpp"

namespace flocsim::gpu {

bool built_with_cuda() {
  return true;
}

GpuQuery query_gpus() {
  GpuQuery q;
  int count = 0;
  const cudaError_t status = cudaGetDeviceCount(&count);
  if (status != cudaSuccess || count == 0) {
    // without a driver, or with one older than this runtime (CUDA 13 wants
    // driver 580 or newer), the runtime says the driver is "insufficient"
    const bool no_driver = status == cudaErrorInsufficientDriver;
    q.why_none =
        std::string(no_driver ? "no NVIDIA driver on this machine, or one too old for the CUDA "
                                "runtime flocsim was built with (CUDA 13: driver 580 or newer)"
                              : "no CUDA GPU is visible to this process") +
        " (CUDA: " + (status != cudaSuccess ? cudaGetErrorString(status) : "no device found") + ")";
    if (const char* visible = std::getenv("CUDA_VISIBLE_DEVICES"))
      q.why_none += std::string(", CUDA_VISIBLE_DEVICES=\"") + visible + "\"";
    cudaGetLastError();  // clear the sticky error of a failed query
    return q;
  }
  std::string too_old, unavailable;
  // cudaGetDevice answers 0 even before anything chose a GPU: restored below
  // only if that GPU proves usable (setting an unusable one would leave an
  // error for the next launch to report)
  int current = 0;
  const bool had_current = cudaGetDevice(&current) == cudaSuccess;
  for (int d = 0; d < count; ++d) {
    cudaDeviceProp p{};
    if (cudaGetDeviceProperties(&p, d) != cudaSuccess) continue;
    // The build carries machine code for FLOCSIM_CUDA_MIN_ARCH (Hopper, 90)
    // and PTX that newer GPUs compile; older ones cannot run it.
    if (FLOCSIM_CUDA_MIN_ARCH > 0 && p.major * 10 + p.minor < FLOCSIM_CUDA_MIN_ARCH) {
      too_old += std::string(too_old.empty() ? "" : "; ") + p.name + " (compute capability " +
                 std::to_string(p.major) + "." + std::to_string(p.minor) + ")";
      continue;
    }
    // Its free memory needs a context on it; a GPU that gives none (held by
    // another process in exclusive mode, or failed) cannot run a case here.
    std::size_t free = 0, total = 0;
    cudaError_t got = cudaSetDevice(d);
    if (got == cudaSuccess) got = cudaMemGetInfo(&free, &total);
    if (got != cudaSuccess) {
      unavailable += std::string(unavailable.empty() ? "" : "; ") + p.name + " (CUDA index " +
                     std::to_string(d) + "): " + cudaGetErrorString(got);
      cudaGetLastError();  // not sticky: the next GPU is asked afresh
      continue;
    }
    q.devices.push_back({d, p.name, static_cast<double>(p.totalGlobalMem) / (1u << 30),
                         static_cast<double>(free) / (1u << 30), p.major, p.minor});
  }
  // the caller's current GPU stays current (the loop made each one current)
  const bool current_usable =
      std::any_of(q.devices.begin(), q.devices.end(),
                  [current](const GpuDevice& d) { return d.index == current; });
  if (had_current && current_usable) cudaSetDevice(current);
  cudaGetLastError();  // nothing of the query is left for the next call to report
  if (q.devices.empty() && !too_old.empty())
    q.why_none = "the visible GPUs are older than this build's code (compute capability " +
                 std::to_string(FLOCSIM_CUDA_MIN_ARCH / 10) + "." +
                 std::to_string(FLOCSIM_CUDA_MIN_ARCH % 10) + " and newer): " + too_old +
                 "; configure with -DCMAKE_CUDA_ARCHITECTURES=<theirs> to build for them";
  if (q.devices.empty() && !unavailable.empty())
    q.why_none += std::string(q.why_none.empty() ? "" : "; ") +
                  "the visible GPUs cannot be used by this process (busy in exclusive mode, "
                  "or failed; nvidia-smi says which): " +
                  unavailable;
  if (q.devices.empty() && q.why_none.empty())
    q.why_none = "no visible GPU answered the query of its properties";
  return q;
}

void release_gpus() {
  int count = 0;
  if (cudaGetDeviceCount(&count) != cudaSuccess) {
    cudaGetLastError();
    return;
  }
  for (int d = 0; d < count; ++d)
    if (cudaSetDevice(d) == cudaSuccess) cudaDeviceReset();
  cudaGetLastError();
}

GpuDevice use_first_gpu() {
  const GpuQuery q = query_gpus();
  if (q.devices.empty()) throw std::runtime_error(q.why_none);
  cuda_check(cudaSetDevice(q.devices.front().index), "cudaSetDevice");
  return q.devices.front();
}

namespace {
// The copy the lattice's step is measured against: every byte read once and
// written once, in wide coalesced loads and stores.
__global__ void copy_kernel(const double2* __restrict__ in, double2* __restrict__ out,
                            std::size_t n) {
  for (std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x; i < n;
       i += static_cast<std::size_t>(gridDim.x) * blockDim.x)
    out[i] = in[i];
}
}  // namespace

double measure_copy_bandwidth_gbs(std::size_t bytes, int reps) {
  if (reps < 1) throw std::invalid_argument("copy bandwidth: reps must be >= 1");
  const std::size_t n = bytes / sizeof(double2);
  // everything this takes is given back however it ends (a failed call
  // throws from the middle of the loop)
  struct Held {
    double2 *in = nullptr, *out = nullptr;
    cudaEvent_t start = nullptr, stop = nullptr;
    ~Held() {
      if (start) cudaEventDestroy(start);
      if (stop) cudaEventDestroy(stop);
      cudaFree(in);
      cudaFree(out);
    }
  } h;
  cuda_check(cudaMalloc(&h.in, n * sizeof(double2)), "cudaMalloc (copy benchmark)");
  cuda_check(cudaMalloc(&h.out, n * sizeof(double2)), "cudaMalloc (copy benchmark)");
  cuda_check(cudaMemset(h.in, 0, n * sizeof(double2)), "cudaMemset");
  int sms = 0;
  int device = 0;
  cuda_check(cudaGetDevice(&device), "cudaGetDevice");
  cuda_check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device),
             "device attribute");
  const int blocks = sms * 8, threads = 256;
  cuda_check(cudaEventCreate(&h.start), "cudaEventCreate (copy benchmark)");
  cuda_check(cudaEventCreate(&h.stop), "cudaEventCreate (copy benchmark)");
  FLOCSIM_LAUNCH(blocks, threads, 0, copy_kernel)(h.in, h.out, n);  // warm-up
  cuda_check(cudaGetLastError(), "launch of the copy benchmark");
  std::vector<double> rates;
  for (int r = 0; r < reps; ++r) {
    cuda_check(cudaEventRecord(h.start), "cudaEventRecord (copy benchmark)");
    FLOCSIM_LAUNCH(blocks, threads, 0, copy_kernel)(h.in, h.out, n);
    cuda_check(cudaEventRecord(h.stop), "cudaEventRecord (copy benchmark)");
    cuda_check(cudaEventSynchronize(h.stop), "copy benchmark");
    float ms = 0;
    cuda_check(cudaEventElapsedTime(&ms, h.start, h.stop), "cudaEventElapsedTime (copy benchmark)");
    if (!(ms > 0)) throw std::runtime_error("copy benchmark: the GPU's timer gave no time");
    rates.push_back(2.0 * n * sizeof(double2) / (ms * 1e-3) / 1e9);
  }
  std::sort(rates.begin(), rates.end());
  return rates[rates.size() / 2];
}

}  // namespace flocsim::gpu
