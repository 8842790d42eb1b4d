// The CPU emulation of the CUDA runtime that include/cuda_runtime.h declares
// (what it is for, and what it cannot show: there).
//
// A launch runs its blocks one after another. A block's threads are fibers
// on the calling thread, each with its own stack, run in turn until
// each ends or waits at __syncthreads; when all of them wait, the next round
// starts. A kernel that one launch showed never to reach a barrier runs its
// threads as plain calls afterwards (no fibers: the lattice step's thousands
// of cells a launch stay quick).
//
// Settings (environment), for tests that want another device than the default:
//   FLOCSIM_CUDA_EMULATION_GPUS           devices in the machine (default 1; 0: none)
//   FLOCSIM_CUDA_EMULATION_SMS            multiprocessors a device (default 4)
//   FLOCSIM_CUDA_EMULATION_SHARED_OPTIN   shared memory a block may opt into, bytes
//                                         (default 232448, an H100's)
//   FLOCSIM_CUDA_EMULATION_ORDER          forward (default) or reverse: the order
//                                         of blocks, and of threads between barriers
//   FLOCSIM_CUDA_EMULATION_FIBERS         always: every launch on fibers
// CUDA_VISIBLE_DEVICES selects among the devices as CUDA's does.
//
// In this file, in order: the settings and the last error; the machine (its
// devices, their memory, the kernels' attributes); the fibers and the switch
// between them; a launch; then the runtime's calls, each checked as CUDA's.
#include <ucontext.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "cuda_runtime.h"

dim3 threadIdx, blockIdx, blockDim, gridDim;

struct CUevent_st {
  std::chrono::steady_clock::time_point at{};
};

namespace flocsim_cuda_emulation {
namespace {

constexpr std::size_t kDeviceMemory = std::size_t(8) << 30;  // a device's memory
constexpr std::size_t kSharedWithoutOptIn = 48 * 1024;       // as on every CUDA GPU
constexpr std::size_t kFiberStack = 64 * 1024;               // a kernel's frames take a few KB
constexpr std::size_t kStackGuard = 4096;  // lowest bytes of a fiber stack, never to be written
constexpr unsigned char kPoison = 0xFF;    // a NaN in every float and double

long setting(const char* name, long fallback) {
  const char* text = std::getenv(name);
  if (!text || !*text) return fallback;
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value < 0) {
    std::fprintf(stderr, "CUDA emulation: %s=\"%s\" is not a whole number >= 0\n", name, text);
    std::abort();
  }
  return value;
}

[[noreturn]] void fatal(const std::string& what) {
  std::fprintf(stderr, "CUDA emulation: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// What cudaGetLastError returns next: the last error of any call of this
// host thread (a launch's among them), as CUDA's runtime keeps it.
thread_local cudaError_t last_error = cudaSuccess;

cudaError_t record(cudaError_t error) {
  if (error != cudaSuccess) last_error = error;
  return error;
}

cudaError_t complain(cudaError_t error, const std::string& what) {
  std::fprintf(stderr, "CUDA emulation: %s (%s)\n", what.c_str(), cudaGetErrorString(error));
  return record(error);
}

struct Allocation {
  std::size_t bytes = 0;
  int device = 0;  // the machine's index
};

struct Machine {
  std::mutex lock;
  std::vector<int> visible;  // CUDA index -> the machine's index
  int sms = 4;
  std::size_t shared_optin = 232448;
  bool reverse = false;
  bool always_fibers = false;
  std::map<std::uintptr_t, Allocation> device_memory;  // by start address
  std::vector<std::size_t> used;                       // bytes a device
  std::set<void*> pinned;
  // per device (the machine's index) and kernel, where raised
  std::map<std::pair<int, const void*>, int> max_dynamic_shared;
  std::map<const void*, bool> reaches_barrier;  // per kernel, once launched

  Machine() {
    const long gpus = setting("FLOCSIM_CUDA_EMULATION_GPUS", 1);
    sms = static_cast<int>(std::max(1L, setting("FLOCSIM_CUDA_EMULATION_SMS", 4)));
    shared_optin = static_cast<std::size_t>(setting("FLOCSIM_CUDA_EMULATION_SHARED_OPTIN", 232448));
    const char* order = std::getenv("FLOCSIM_CUDA_EMULATION_ORDER");
    reverse = order && std::string(order) == "reverse";
    if (order && !reverse && std::string(order) != "forward")
      fatal(std::string("FLOCSIM_CUDA_EMULATION_ORDER=\"") + order +
            "\": must be forward or reverse");
    const char* fibers = std::getenv("FLOCSIM_CUDA_EMULATION_FIBERS");
    always_fibers = fibers && std::string(fibers) == "always";
    used.assign(static_cast<std::size_t>(gpus), 0);
    // CUDA_VISIBLE_DEVICES: indices in the order given; the list ends at the
    // first entry that names no device (or one named before), as CUDA's does
    if (const char* list = std::getenv("CUDA_VISIBLE_DEVICES")) {
      std::string entries(list);
      std::size_t start = 0;
      while (start <= entries.size() && !entries.empty()) {
        const std::size_t comma = std::min(entries.find(',', start), entries.size());
        const std::string entry = entries.substr(start, comma - start);
        char* end = nullptr;
        const long index = std::strtol(entry.c_str(), &end, 10);
        if (entry.empty() || *end != '\0' || index < 0 || index >= gpus ||
            std::find(visible.begin(), visible.end(), index) != visible.end())
          break;
        visible.push_back(static_cast<int>(index));
        start = comma + 1;
      }
    } else {
      for (int d = 0; d < gpus; ++d) visible.push_back(d);
    }
  }

  // the allocation holding [p, p + bytes), or nullptr
  const Allocation* device_range(const void* p, std::size_t bytes) const {
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    auto it = device_memory.upper_bound(at);
    if (it == device_memory.begin()) return nullptr;
    --it;
    if (at + bytes > it->first + it->second.bytes) return nullptr;
    return &it->second;
  }
  bool on_device(const void* p) const { return device_range(p, 1) != nullptr; }
};

Machine& machine() {
  static Machine m;
  return m;
}

thread_local int current_device = 0;  // CUDA's index, per host thread

// ---- fibers ----
//
// A fiber's context is switched by switch_to(from, to): it saves what the
// running code must find again (on x86-64 the callee-saved registers and the
// floating-point control words, on its own stack) and resumes `to`. On x86-64
// that is a few instructions (below); elsewhere glibc's swapcontext, which
// also makes two system calls a switch (the signal mask), 10-50 times slower.

enum class FiberState { ready, at_barrier, done };

void fiber_entry();

// (ELF x86-64 only; with hardware shadow stacks enabled, __CET__ & 2, a
// `ret` onto another stack would fault: swapcontext knows how there.)
#if defined(__x86_64__) && defined(__ELF__) && !(defined(__CET__) && (__CET__ & 2))
// flocsim_emulation_switch(&from_sp, to_sp): pushes the System V callee-saved
// registers and the MXCSR and x87 control words, stores the stack pointer in
// from_sp, loads to_sp and pops the same from there.
extern "C" void flocsim_emulation_switch(void** from_sp, void* to_sp);
asm(R"(
  .pushsection .text
  .globl flocsim_emulation_switch
  .type flocsim_emulation_switch, @function
flocsim_emulation_switch:
  pushq %rbp
  pushq %rbx
  pushq %r12
  pushq %r13
  pushq %r14
  pushq %r15
  subq $8, %rsp
  stmxcsr (%rsp)
  fnstcw 4(%rsp)
  movq %rsp, (%rdi)
  movq %rsi, %rsp
  ldmxcsr (%rsp)
  fldcw 4(%rsp)
  addq $8, %rsp
  popq %r15
  popq %r14
  popq %r13
  popq %r12
  popq %rbx
  popq %rbp
  ret
  .size flocsim_emulation_switch, .-flocsim_emulation_switch
  .popsection
)");

struct Context {
  void* sp = nullptr;
};

// A fresh context on `stack` that starts in fiber_entry: the frame the switch
// pops (control words as the caller's, six zero registers), then fiber_entry
// as the return address and a zero slot above it, so that fiber_entry starts
// with the stack aligned as after a call.
void make_context(Context& c, char* stack, std::size_t bytes) {
  auto top = reinterpret_cast<std::uintptr_t>(stack + bytes) & ~std::uintptr_t(15);
  auto* sp = reinterpret_cast<std::uint64_t*>(top);
  *--sp = 0;
  *--sp = reinterpret_cast<std::uint64_t>(&fiber_entry);
  for (int r = 0; r < 6; ++r) *--sp = 0;
  --sp;
  std::uint32_t mxcsr = 0;
  std::uint16_t x87 = 0;
  asm volatile("stmxcsr %0" : "=m"(mxcsr));
  asm volatile("fnstcw %0" : "=m"(x87));
  std::memcpy(reinterpret_cast<char*>(sp), &mxcsr, 4);
  std::memcpy(reinterpret_cast<char*>(sp) + 4, &x87, 2);
  c.sp = sp;
}
void switch_to(Context& from, Context& to) {
  flocsim_emulation_switch(&from.sp, to.sp);
}
#else
struct Context {
  ucontext_t uc{};
  bool made = false;
};
void make_context(Context& c, char* stack, std::size_t bytes) {
  if (!c.made) getcontext(&c.uc);  // once: makecontext reuses it
  c.made = true;
  c.uc.uc_stack.ss_sp = stack;
  c.uc.uc_stack.ss_size = bytes;
  c.uc.uc_link = nullptr;  // fiber_entry never returns
  makecontext(&c.uc, fiber_entry, 0);
}
void switch_to(Context& from, Context& to) {
  swapcontext(&from.uc, &to.uc);
}
#endif

struct Fiber {
  Context context;
  std::unique_ptr<char[]> stack;
  FiberState state = FiberState::ready;
};

struct Block {
  Context scheduler;
  // never moved once made (a ucontext_t points into itself)
  std::vector<std::unique_ptr<Fiber>> fibers;
  const Body* body = nullptr;
  int current = -1;     // the fiber running, -1 when none
  bool direct = false;  // threads as plain calls (no barrier expected)
  bool barrier_seen = false;
  std::vector<unsigned char> shared;  // dynamic shared memory
};
Block block_state;

// Every fiber starts here; it ends by handing back to the scheduler for
// good (make_context gives the next launch a fresh start).
void fiber_entry() {
  Block& b = block_state;
  (*b.body)();
  Fiber& f = *b.fibers[static_cast<std::size_t>(b.current)];
  f.state = FiberState::done;
  switch_to(f.context, b.scheduler);
  fatal("a finished thread was resumed");
}

dim3 thread_of(unsigned t, dim3 block) {
  return {t % block.x, (t / block.x) % block.y, t / (block.x * block.y)};
}

void run_block_on_fibers(unsigned threads, dim3 block, bool reverse) {
  Block& b = block_state;
  while (b.fibers.size() < threads) b.fibers.push_back(std::make_unique<Fiber>());
  for (unsigned t = 0; t < threads; ++t) {
    Fiber& f = *b.fibers[t];
    if (!f.stack) {
      // NaN bytes, not the zero pages the system gives: a local read before it
      // is written must not pass as zero (the kernels are also built with
      // -ftrivial-auto-var-init=pattern)
      f.stack.reset(new char[kFiberStack]);
      std::memset(f.stack.get(), kPoison, kFiberStack);
    }
    make_context(f.context, f.stack.get(), kFiberStack);
    f.state = FiberState::ready;
  }
  for (;;) {
    for (unsigned k = 0; k < threads; ++k) {
      const unsigned t = reverse ? threads - 1 - k : k;
      Fiber& f = *b.fibers[t];
      if (f.state == FiberState::done) continue;
      f.state = FiberState::ready;
      b.current = static_cast<int>(t);
      threadIdx = thread_of(t, block);
      switch_to(b.scheduler, f.context);
    }
    b.current = -1;
    unsigned done = 0;
    for (unsigned t = 0; t < threads; ++t) done += b.fibers[t]->state == FiberState::done;
    if (done == threads) return;
    if (done > 0)
      fatal("block (" + std::to_string(blockIdx.x) + ", " + std::to_string(blockIdx.y) + ", " +
            std::to_string(blockIdx.z) + "): " + std::to_string(done) + " of " +
            std::to_string(threads) +
            " threads ended while the others wait at __syncthreads (a barrier every thread of a "
            "block must reach; on a GPU: a hang or undefined behaviour)");
  }
}

// The fiber stacks have no guard page: a kernel whose frames outgrow
// kFiberStack would write into the heap below. Their lowest kStackGuard bytes
// keep the poison they were filled with unless that happened, so a launch that
// ran on fibers checks them once at its end (the blocks reuse the fibers).
void check_stack_guards(unsigned threads) {
  for (unsigned t = 0; t < threads; ++t) {
    const char* low = block_state.fibers[t]->stack.get();
    for (std::size_t i = 0; i < kStackGuard; ++i)
      if (static_cast<unsigned char>(low[i]) != kPoison)
        fatal("thread " + std::to_string(t) + "'s stack overflowed its " +
              std::to_string(kFiberStack / 1024) +
              " KB (the kernel's locals are larger than any here so far; raise kFiberStack)");
  }
}

}  // namespace

void sync_threads() {
  Block& b = block_state;
  if (b.direct)
    fatal(
        "__syncthreads reached by a kernel whose earlier launch never reached one, so it runs "
        "without fibers; run with FLOCSIM_CUDA_EMULATION_FIBERS=always");
  if (b.current < 0) fatal("__syncthreads outside a kernel");
  b.barrier_seen = true;
  Fiber& f = *b.fibers[static_cast<std::size_t>(b.current)];
  f.state = FiberState::at_barrier;
  switch_to(f.context, b.scheduler);
}

void* dynamic_shared() {
  return block_state.shared.data();
}

void launch(const void* kernel, dim3 grid, dim3 block, std::size_t shared_bytes, const Body& body) {
  Machine& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  auto fail = [&](cudaError_t e, const std::string& what) { complain(e, what); };
  if (current_device < 0 || current_device >= static_cast<int>(m.visible.size()))
    return fail(cudaErrorNoDevice, "kernel launch without a device");
  const unsigned long threads = static_cast<unsigned long>(block.x) * block.y * block.z;
  if (block.x < 1 || block.y < 1 || block.z < 1 || block.x > 1024 || block.y > 1024 ||
      block.z > 64 || threads > 1024)
    return fail(cudaErrorInvalidConfiguration,
                "launch of " + std::to_string(block.x) + " x " + std::to_string(block.y) + " x " +
                    std::to_string(block.z) +
                    " threads a block: each side at least 1, x and y at most 1024, z at most 64, "
                    "1024 in all");
  if (grid.x < 1 || grid.y < 1 || grid.z < 1 || grid.x > 2147483647u || grid.y > 65535 ||
      grid.z > 65535)
    return fail(cudaErrorInvalidConfiguration,
                "launch of a grid of " + std::to_string(grid.x) + " x " + std::to_string(grid.y) +
                    " x " + std::to_string(grid.z) +
                    " blocks: each side at least 1, y and z at most 65535");
  if (shared_bytes > kSharedWithoutOptIn) {
    const auto raised =
        m.max_dynamic_shared.find({m.visible[static_cast<std::size_t>(current_device)], kernel});
    if (raised == m.max_dynamic_shared.end() ||
        shared_bytes > static_cast<std::size_t>(raised->second))
      return fail(cudaErrorInvalidValue,
                  "launch with " + std::to_string(shared_bytes) +
                      " bytes of dynamic shared memory: over 48 KB needs the kernel's "
                      "cudaFuncAttributeMaxDynamicSharedMemorySize raised to it first");
  }
  Block& b = block_state;
  const auto known = m.reaches_barrier.find(kernel);
  b.direct = !m.always_fibers && known != m.reaches_barrier.end() && !known->second;
  b.barrier_seen = false;
  b.body = &body;
  b.shared.assign(shared_bytes, kPoison);
  gridDim = grid;
  blockDim = block;
  const unsigned long blocks = static_cast<unsigned long>(grid.x) * grid.y * grid.z;
  for (unsigned long k = 0; k < blocks; ++k) {
    const unsigned long n = m.reverse ? blocks - 1 - k : k;
    blockIdx = {static_cast<unsigned>(n % grid.x), static_cast<unsigned>((n / grid.x) % grid.y),
                static_cast<unsigned>(n / (static_cast<unsigned long>(grid.x) * grid.y))};
    std::fill(b.shared.begin(), b.shared.end(), kPoison);  // shared memory starts undefined
    if (b.direct) {
      for (unsigned long i = 0; i < threads; ++i) {
        const unsigned t = static_cast<unsigned>(m.reverse ? threads - 1 - i : i);
        threadIdx = thread_of(t, block);
        body();
      }
    } else {
      run_block_on_fibers(static_cast<unsigned>(threads), block, m.reverse);
    }
  }
  if (!b.direct) check_stack_guards(static_cast<unsigned>(threads));
  if (known == m.reaches_barrier.end()) m.reaches_barrier[kernel] = b.barrier_seen;
  b.direct = false;
  b.body = nullptr;
}

cudaError_t set_max_dynamic_shared(const void* kernel, int bytes) {
  Machine& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (bytes < 0 || static_cast<std::size_t>(bytes) > m.shared_optin)
    return complain(cudaErrorInvalidValue,
                    "cudaFuncAttributeMaxDynamicSharedMemorySize " + std::to_string(bytes) +
                        ": the device allows at most " + std::to_string(m.shared_optin));
  if (current_device < 0 || current_device >= static_cast<int>(m.visible.size()))
    return record(cudaErrorNoDevice);
  m.max_dynamic_shared[{m.visible[static_cast<std::size_t>(current_device)], kernel}] = bytes;
  return cudaSuccess;
}

int occupancy_blocks_per_multiprocessor(int block_threads) {
  return std::clamp(2048 / std::max(1, block_threads), 1, 32);
}

}  // namespace flocsim_cuda_emulation

using flocsim_cuda_emulation::complain;
using flocsim_cuda_emulation::machine;

const char* cudaGetErrorString(cudaError_t error) {
  switch (error) {
    case cudaSuccess:
      return "no error";
    case cudaErrorInvalidValue:
      return "invalid argument";
    case cudaErrorMemoryAllocation:
      return "out of memory";
    case cudaErrorInvalidConfiguration:
      return "invalid configuration argument";
    case cudaErrorInvalidDeviceFunction:
      return "invalid device function";
    case cudaErrorNoDevice:
      return "no CUDA-capable device is detected";
    case cudaErrorInvalidDevice:
      return "invalid device ordinal";
    case cudaErrorInsufficientDriver:
      return "CUDA driver version is insufficient for CUDA runtime version";
    case cudaErrorLaunchFailure:
      return "unspecified launch failure";
  }
  return "unrecognized error code";
}

cudaError_t cudaGetLastError() {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  const cudaError_t e = flocsim_cuda_emulation::last_error;
  flocsim_cuda_emulation::last_error = cudaSuccess;
  return e;
}

cudaError_t cudaPeekAtLastError() {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  return flocsim_cuda_emulation::last_error;
}

namespace {
bool valid_device(int device) {
  return device >= 0 && device < static_cast<int>(machine().visible.size());
}
}  // namespace

cudaError_t cudaGetDeviceCount(int* count) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  *count = static_cast<int>(m.visible.size());
  return m.visible.empty() ? flocsim_cuda_emulation::record(cudaErrorNoDevice) : cudaSuccess;
}

cudaError_t cudaGetDeviceProperties(cudaDeviceProp* prop, int device) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (!valid_device(device)) return flocsim_cuda_emulation::record(cudaErrorInvalidDevice);
  *prop = cudaDeviceProp{};
  std::snprintf(prop->name, sizeof prop->name, "CUDA emulation on the CPU (device %d)",
                m.visible[static_cast<std::size_t>(device)]);
  prop->totalGlobalMem = flocsim_cuda_emulation::kDeviceMemory;
  prop->major = 9;
  prop->minor = 0;
  prop->multiProcessorCount = m.sms;
  prop->sharedMemPerBlockOptin = m.shared_optin;
  return cudaSuccess;
}

cudaError_t cudaSetDevice(int device) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (m.visible.empty()) return flocsim_cuda_emulation::record(cudaErrorNoDevice);
  if (!valid_device(device)) return flocsim_cuda_emulation::record(cudaErrorInvalidDevice);
  flocsim_cuda_emulation::current_device = device;
  return cudaSuccess;
}

cudaError_t cudaGetDevice(int* device) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (m.visible.empty()) return flocsim_cuda_emulation::record(cudaErrorNoDevice);
  *device = flocsim_cuda_emulation::current_device;
  return cudaSuccess;
}

cudaError_t cudaDeviceGetAttribute(int* value, cudaDeviceAttr attr, int device) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (!valid_device(device)) return flocsim_cuda_emulation::record(cudaErrorInvalidDevice);
  switch (attr) {
    case cudaDevAttrMultiProcessorCount:
      *value = m.sms;
      return cudaSuccess;
    case cudaDevAttrMaxSharedMemoryPerBlockOptin:
      *value = static_cast<int>(m.shared_optin);
      return cudaSuccess;
  }
  return flocsim_cuda_emulation::record(cudaErrorInvalidValue);
}

cudaError_t cudaMemGetInfo(std::size_t* free, std::size_t* total) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (!valid_device(flocsim_cuda_emulation::current_device))
    return flocsim_cuda_emulation::record(cudaErrorNoDevice);
  const int d = m.visible[static_cast<std::size_t>(flocsim_cuda_emulation::current_device)];
  *total = flocsim_cuda_emulation::kDeviceMemory;
  *free = *total - m.used[static_cast<std::size_t>(d)];
  return cudaSuccess;
}

cudaError_t cudaDeviceSynchronize() {
  return cudaSuccess;  // every launch and copy has finished when it returns
}

cudaError_t cudaDeviceReset() {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (!valid_device(flocsim_cuda_emulation::current_device))
    return flocsim_cuda_emulation::record(cudaErrorNoDevice);
  const int d = m.visible[static_cast<std::size_t>(flocsim_cuda_emulation::current_device)];
  // the device's context goes, and every allocation in it
  for (auto it = m.device_memory.begin(); it != m.device_memory.end();) {
    if (it->second.device == d) {
      m.used[static_cast<std::size_t>(d)] -= it->second.bytes;
      std::free(reinterpret_cast<void*>(it->first));
      it = m.device_memory.erase(it);
    } else {
      ++it;
    }
  }
  for (auto it = m.max_dynamic_shared.begin(); it != m.max_dynamic_shared.end();)
    it = it->first.first == d ? m.max_dynamic_shared.erase(it) : std::next(it);
  flocsim_cuda_emulation::last_error = cudaSuccess;
  return cudaSuccess;
}

cudaError_t cudaMalloc(void** pointer, std::size_t bytes) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  *pointer = nullptr;
  if (!valid_device(flocsim_cuda_emulation::current_device))
    return flocsim_cuda_emulation::record(cudaErrorNoDevice);
  const int d = m.visible[static_cast<std::size_t>(flocsim_cuda_emulation::current_device)];
  if (bytes == 0) return cudaSuccess;
  if (bytes > flocsim_cuda_emulation::kDeviceMemory - m.used[static_cast<std::size_t>(d)])
    return flocsim_cuda_emulation::record(cudaErrorMemoryAllocation);
  const std::size_t rounded = (bytes + 255) / 256 * 256;  // cudaMalloc aligns to 256 bytes
  void* p = std::aligned_alloc(256, rounded);
  if (!p) return flocsim_cuda_emulation::record(cudaErrorMemoryAllocation);
  std::memset(p, flocsim_cuda_emulation::kPoison, rounded);
  m.device_memory[reinterpret_cast<std::uintptr_t>(p)] = {bytes, d};
  m.used[static_cast<std::size_t>(d)] += bytes;
  *pointer = p;
  return cudaSuccess;
}

cudaError_t cudaFree(void* pointer) {
  if (!pointer) return cudaSuccess;
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  const auto it = m.device_memory.find(reinterpret_cast<std::uintptr_t>(pointer));
  if (it == m.device_memory.end())
    return complain(cudaErrorInvalidValue, "cudaFree of a pointer cudaMalloc did not give");
  m.used[static_cast<std::size_t>(it->second.device)] -= it->second.bytes;
  std::free(pointer);
  m.device_memory.erase(it);
  return cudaSuccess;
}

cudaError_t cudaMallocHost(void** pointer, std::size_t bytes) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  *pointer = nullptr;
  if (m.visible.empty()) return flocsim_cuda_emulation::record(cudaErrorNoDevice);
  void* p = std::aligned_alloc(64, std::max<std::size_t>(64, (bytes + 63) / 64 * 64));
  if (!p) return flocsim_cuda_emulation::record(cudaErrorMemoryAllocation);
  std::memset(p, flocsim_cuda_emulation::kPoison, bytes);
  m.pinned.insert(p);
  *pointer = p;
  return cudaSuccess;
}

cudaError_t cudaFreeHost(void* pointer) {
  if (!pointer) return cudaSuccess;
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (m.pinned.erase(pointer) == 0)
    return complain(cudaErrorInvalidValue, "cudaFreeHost of a pointer cudaMallocHost did not give");
  std::free(pointer);
  return cudaSuccess;
}

namespace {
const char* kind_name(cudaMemcpyKind kind) {
  switch (kind) {
    case cudaMemcpyHostToHost:
      return "HostToHost";
    case cudaMemcpyHostToDevice:
      return "HostToDevice";
    case cudaMemcpyDeviceToHost:
      return "DeviceToHost";
    case cudaMemcpyDeviceToDevice:
      return "DeviceToDevice";
    case cudaMemcpyDefault:
      return "Default";
  }
  return "?";
}
}  // namespace

cudaError_t cudaMemcpy(void* to, const void* from, std::size_t bytes, cudaMemcpyKind kind) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (bytes == 0) return cudaSuccess;
  const bool to_device = kind == cudaMemcpyHostToDevice || kind == cudaMemcpyDeviceToDevice;
  const bool from_device = kind == cudaMemcpyDeviceToHost || kind == cudaMemcpyDeviceToDevice;
  const std::string what =
      std::string("cudaMemcpy ") + kind_name(kind) + " of " + std::to_string(bytes) + " bytes: ";
  if (kind != cudaMemcpyDefault) {
    if (to_device && !m.device_range(to, bytes))
      return complain(cudaErrorInvalidValue,
                      what + (m.on_device(to) ? "runs past the end of the destination's allocation"
                                              : "the destination is not device memory"));
    if (!to_device && m.on_device(to))
      return complain(cudaErrorInvalidValue, what + "the destination is device memory");
    if (from_device && !m.device_range(from, bytes))
      return complain(cudaErrorInvalidValue,
                      what + (m.on_device(from) ? "runs past the end of the source's allocation"
                                                : "the source is not device memory"));
    if (!from_device && m.on_device(from))
      return complain(cudaErrorInvalidValue, what + "the source is device memory");
  }
  std::memmove(to, from, bytes);
  return cudaSuccess;
}

cudaError_t cudaMemcpyAsync(void* to, const void* from, std::size_t bytes, cudaMemcpyKind kind,
                            cudaStream_t) {
  return cudaMemcpy(to, from, bytes, kind);
}

cudaError_t cudaMemset(void* to, int value, std::size_t bytes) {
  auto& m = machine();
  std::lock_guard<std::mutex> guard(m.lock);
  if (bytes == 0) return cudaSuccess;
  if (!m.device_range(to, bytes))
    return complain(
        cudaErrorInvalidValue,
        "cudaMemset of " + std::to_string(bytes) + " bytes: " +
            (m.on_device(to) ? "runs past the end of the allocation" : "not device memory"));
  std::memset(to, value, bytes);
  return cudaSuccess;
}

cudaError_t cudaMemsetAsync(void* to, int value, std::size_t bytes, cudaStream_t) {
  return cudaMemset(to, value, bytes);
}

cudaError_t cudaEventCreate(cudaEvent_t* event) {
  *event = new CUevent_st;
  return cudaSuccess;
}

cudaError_t cudaEventDestroy(cudaEvent_t event) {
  delete event;
  return cudaSuccess;
}

cudaError_t cudaEventRecord(cudaEvent_t event, cudaStream_t) {
  event->at = std::chrono::steady_clock::now();
  return cudaSuccess;
}

cudaError_t cudaEventSynchronize(cudaEvent_t) {
  return cudaSuccess;
}

cudaError_t cudaEventElapsedTime(float* ms, cudaEvent_t start, cudaEvent_t stop) {
  *ms = std::chrono::duration<float, std::milli>(stop->at - start->at).count();
  return cudaSuccess;
}
