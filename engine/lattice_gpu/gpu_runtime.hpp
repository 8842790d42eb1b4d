#pragma once
// What this build and this machine offer the CUDA back-end: whether the build
// has it at all (a CUDA compiler was found when it was configured), which GPUs
// the process sees, and why none can be used when none can. Every caller that
// may run on a GPU asks here first, so a case that wants one is refused
// before any work with the reason (docs/gpu.md).
#include <string>
#include <vector>

namespace flocsim::gpu {

struct GpuDevice {
  int index = 0;  // CUDA's index among the visible devices
  std::string name;
  double memory_gib = 0;
  double free_gib = 0;  // free when queried (other processes may hold the rest)
  int compute_major = 0, compute_minor = 0;
};

struct GpuQuery {
  std::vector<GpuDevice> devices;  // the usable ones
  std::string why_none;            // empty when devices is not empty
};

// True when this build carries the CUDA back-end.
bool built_with_cuda();
// The GPUs this process can run on; with none, the reason (no CUDA in the
// build, no driver, no device visible, a device too old for the build's code).
GpuQuery query_gpus();
// Lets go of what query_gpus took on each GPU (a context, hundreds of MB of
// the GPU's memory, and in exclusive mode the GPU itself) for a process that
// only asks and runs nothing there (the sweep's orchestrator, whose workers
// then take the GPUs; a GPU test before it starts `flocsim run` as a child).
// Destroys every allocation of this process on them.
void release_gpus();
// Makes the first usable GPU the current one for this thread (what every
// allocation and launch of the back-end uses) and returns it; throws with
// the reason when there is none.
GpuDevice use_first_gpu();

// Device-to-device copy bandwidth of the current GPU (bytes read + bytes written per
// second, GB/s): the roofline of a memory-bound kernel, measured with a copy
// of `bytes` repeated `reps` times; the median of the repetitions.
double measure_copy_bandwidth_gbs(std::size_t bytes, int reps);

}  // namespace flocsim::gpu
