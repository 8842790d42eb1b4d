// GoogleTest's main, but a process that finds no usable GPU runs no test and
// exits with CTest's skip code, naming the reason. Listing the tests (CTest's
// discovery) needs no GPU.
#include <gtest/gtest.h>

#include <cstdio>

#include "engine/lattice_gpu/gpu_runtime.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (!::testing::GTEST_FLAG(list_tests)) {
    const flocsim::gpu::GpuQuery q = flocsim::gpu::query_gpus();
    if (q.devices.empty()) {
      std::printf("no GPU: %s; skipped\n", q.why_none.c_str());
      return 77;
    }
    std::printf("GPU: %s (%.0f GiB, compute capability %d.%d)\n", q.devices[0].name.c_str(),
                q.devices[0].memory_gib, q.devices[0].compute_major, q.devices[0].compute_minor);
  }
  return RUN_ALL_TESTS();
}
