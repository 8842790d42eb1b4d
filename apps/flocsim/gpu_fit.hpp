#pragma once
// Whether this machine can run a case that asks for the GPU: a usable GPU
// there, and the lattice within 90 % of its free memory. `flocsim run` asks
// before any output is written, `flocsim case check` so that it refuses what
// `run` would refuse.
#include <string>

#include "engine/case/case_file.hpp"

namespace flocsim::app {

// "" where the case runs on the CPU or fits the GPU found; otherwise why not,
// with what would work (a message to follow "input error in FILE: ").
std::string gpu_refusal(const cases::ParsedCase& parsed);

}  // namespace flocsim::app
