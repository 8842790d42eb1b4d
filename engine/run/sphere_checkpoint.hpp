#pragma once
// The checkpoint of a sphere scene (OUT/checkpoint.h5, written atomically):
// sphere states, attached pairs and event counters, the lattice populations
// and the immersed boundary's inside-liquid momenta (scenes with a liquid),
// the time series and accumulators, and the protocol's state. A resumed run
// continues bit-identically.
#include <filesystem>

#include "engine/case/suspension_case.hpp"
#include "engine/events/direct_interactions.hpp"
#include "engine/run/coupled_step.hpp"
#include "engine/run/protocol.hpp"
#include "engine/run/sphere_run_state.hpp"

namespace flocsim::run {

// `liquid` is null in scenes without one; `wall_s` is the wall time of every
// invocation so far.
template <class Real>
void write_checkpoint(const std::filesystem::path& dir, const cases::SuspensionCase& c,
                      const SphereRunState& s, const Protocol& protocol,
                      const events::DirectInteractions& contacts, const Liquid<Real>* liquid,
                      double wall_s);

// Refuses (input::InputError) a checkpoint of another case.
template <class Real>
void read_checkpoint(const std::filesystem::path& file, const cases::SuspensionCase& c,
                     SphereRunState& s, Protocol& protocol, events::DirectInteractions& contacts,
                     Liquid<Real>* liquid);

}  // namespace flocsim::run
