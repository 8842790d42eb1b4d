#pragma once
// Which device runs a case's lattice: the CPU (the reference, every scene) or
// a CUDA GPU (engine/lattice_gpu; today the fluid scene). The case field
// "device" (top level, beside "precision") chooses it; `flocsim run --device`
// and `flocsim sweep launch|resume --device` override it. Like the thread
// count it is how a run is computed, not what: a checkpoint written on one
// device continues on the other (run/output_directory.cpp leaves it out of
// the comparison), and result.json records where each run ran.
#include <string>
#include <string_view>

namespace flocsim::cases {

enum class Device { cpu, cuda };

inline const char* device_name(Device d) {
  return d == Device::cuda ? "cuda" : "cpu";
}

// The allowed names, for choices and messages.
inline constexpr const char* kDeviceNames[] = {"cpu", "cuda"};

inline bool parse_device_name(std::string_view name, Device& out) {
  if (name == "cpu")
    out = Device::cpu;
  else if (name == "cuda")
    out = Device::cuda;
  else
    return false;
  return true;
}

}  // namespace flocsim::cases
