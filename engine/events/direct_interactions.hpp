#pragma once
// Event-driven direct interactions inside one time step (docs/model.md section 3):
// after the time-step velocity update the spheres fly ballistically to the
// end of the step, and every hard-sphere collision, square-well entry and
// well-edge arrival on the way is executed in exact time order over all
// spheres (the two spheres involved change velocity, all others fly on).
//
// Which pairs are attached (inside each other's well) is state kept here and
// checkpointed with attached_pairs()/set_attached_pairs(); it is never
// re-derived from distances.
//
//   DirectInteractions contacts({.escape_velocity = 4e-4, .well_width = 0.15});
//   for (each time step) { ...velocity update...; contacts.advance(spheres, box, 1.0); }
#include <cstdint>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "engine/neighbours/pair_search.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::events {

using spheres::PeriodicBox;
using spheres::SphereSet;
using spheres::Vec3;

struct DirectInteractionParams {
  double restitution = 1.0;      // e, in [0, 1]
  double friction = 0.0;         // mu_f >= 0
  double escape_velocity = 0.0;  // du (lattice units); 0: no square well at all
  double well_width = 0.15;      // delta (lattice units); default 0.025 a at a = 6
  // TC model (Luding & McNamara 1998) against inelastic collapse: a collision
  // of a sphere that already collided less than this time ago (within the
  // same step) is elastic. Only matters for e < 1, where a cluster of touching
  // spheres can otherwise need infinitely many collisions at one instant.
  double contact_duration = 1e-6;  // lattice time units
  // A step that needs more events than this per sphere is stopped with a
  // diagnosis (EventCapExceeded) instead of hanging; realistic suspensions
  // need far below one event per sphere per step.
  double max_events_per_sphere = 1000.0;

  void check() const;  // std::invalid_argument naming the field, value and allowed range
};

// Events executed since construction (or since set_counters), by kind.
struct EventCounters {
  std::uint64_t collisions = 0;
  std::uint64_t well_entries = 0;
  std::uint64_t escapes = 0;             // well-edge arrivals that left the well
  std::uint64_t edge_bounces = 0;        // well-edge arrivals reflected back in
  std::uint64_t neighbour_rebuilds = 0;  // mid-step pair-list rebuilds (a speed outgrew the skin)
  std::uint64_t steps = 0;
  std::uint64_t events() const { return collisions + well_entries + escapes + edge_bounces; }
};

// Thrown when one step needs more events than the cap; the message lists the
// last events (pair, kind, time, gap, radial velocity) to show why.
class EventCapExceeded : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class DirectInteractions {
 public:
  explicit DirectInteractions(DirectInteractionParams params = {});

  // Moves all spheres over dt, executing every event in time order, and
  // wraps positions into the box. Throws std::runtime_error when the state
  // handed in is inconsistent (spheres overlapping beyond round-off, an
  // attached pair beyond the well edge) and EventCapExceeded on the cap.
  void advance(SphereSet& spheres, const PeriodicBox& box, double dt);

  const DirectInteractionParams& params() const { return params_; }
  bool wells_on() const { return params_.escape_velocity > 0; }

  // Changes the well strength between steps (start-up: du = 0, then the
  // target). Switching the well off (du = 0) releases all attached pairs.
  void set_escape_velocity(double du);
  // Attaches every pair whose centres are within 2 (a + delta): the state of a
  // well switched on instantaneously (pairs inside it are bound).
  void attach_pairs_within_well(const SphereSet& spheres, const PeriodicBox& box);

  // Attached pairs as (i, j), i < j, sorted; for checkpoints and observables.
  std::vector<std::pair<int, int>> attached_pairs() const;
  void set_attached_pairs(const std::vector<std::pair<int, int>>& pairs);
  std::size_t attached_count() const { return attached_.size(); }
  // Potential energy of the wells: -(pair depth m_p du^2) per attached pair.
  double well_energy(const SphereSet& spheres) const;

  const EventCounters& counters() const { return counters_; }
  void set_counters(const EventCounters& counters) { counters_ = counters; }
  // Largest overlap 2a - |x_j - x_i| seen at the end of any step (0 if none).
  double worst_overlap() const { return worst_overlap_; }

 private:
  enum class Kind : std::uint8_t { collision, well_entry, well_edge };
  struct Pair {
    int i, j;
    Vec3 shift;  // x_j - x_i + shift is the separation for the whole step
    bool attached;
  };
  struct Event {
    double time;
    int pair;
    Kind kind;
    std::uint32_t count_i, count_j;  // event counts of i and j when predicted
    bool operator>(const Event& o) const { return time > o.time; }
  };
  struct Record {  // for the diagnosis on the event cap
    double time;
    int i, j;
    Kind kind;
    double gap, radial_velocity;
  };

  static std::uint64_t key(int i, int j) {
    return (static_cast<std::uint64_t>(i) << 32) | static_cast<std::uint32_t>(j);
  }
  static const char* name(Kind k);
  Vec3 position_at(const SphereSet& s, int i, double t) const {
    return s.position[i] + s.velocity[i] * (t - local_time_[i]);
  }
  void build_pairs(SphereSet& s, const PeriodicBox& box, double t, double dt);
  void predict(const SphereSet& s, int p, double t, double dt);
  void execute(SphereSet& s, const Event& e);
  [[noreturn]] void throw_event_cap(const SphereSet& s, double t, double dt, std::size_t cap) const;

  DirectInteractionParams params_;
  std::unordered_set<std::uint64_t> attached_;
  EventCounters counters_;
  double worst_overlap_ = 0.0;

  // Per-step work arrays, kept to reuse their storage.
  std::vector<Pair> pairs_;
  std::vector<int> pairs_of_start_, pairs_of_;  // pairs of each sphere (CSR)
  std::vector<double> local_time_;              // time each sphere's position refers to
  std::vector<std::uint32_t> event_count_;
  std::vector<double> last_collision_;  // time of each sphere's last collision in this step
  std::vector<Event> queue_;            // binary min-heap on time
  std::vector<Record> recent_;
  double speed_bound_ = 0.0;  // no sphere is faster while the pair list is valid
};

}  // namespace flocsim::events
