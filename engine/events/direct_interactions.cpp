#include "engine/events/direct_interactions.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <unordered_set>

#include "engine/events/hard_sphere_collision.hpp"
#include "engine/events/pair_kinematics.hpp"
#include "engine/events/square_well.hpp"

namespace flocsim::events {

namespace {

// Overlaps and excursions beyond the well edge larger than this (relative to
// a) cannot come from round-off (positions carry ~1e-16 relative error); they
// mean a missed event or a corrupt state, and stop the run.
constexpr double kStateTolerance = 1e-9;
constexpr std::size_t kRecentEvents = 16;

std::string describe_range(const std::string& field, double value, const std::string& allowed) {
  std::ostringstream os;
  os << "direct interactions: " << field << " = " << value << " is outside the allowed range "
     << allowed;
  return os.str();
}

}  // namespace

void DirectInteractionParams::check() const {
  if (!(restitution >= 0 && restitution <= 1))
    throw std::invalid_argument(describe_range("restitution", restitution, "[0, 1]"));
  if (!(friction >= 0 && std::isfinite(friction)))
    throw std::invalid_argument(describe_range("friction", friction, "[0, inf)"));
  if (!(escape_velocity >= 0 && std::isfinite(escape_velocity)))
    throw std::invalid_argument(describe_range("escape_velocity", escape_velocity, "[0, inf)"));
  if (!(well_width > 0 && std::isfinite(well_width)))
    throw std::invalid_argument(describe_range("well_width", well_width, "(0, inf)"));
  if (!(contact_duration >= 0 && std::isfinite(contact_duration)))
    throw std::invalid_argument(describe_range("contact_duration", contact_duration, "[0, inf)"));
  if (!(max_events_per_sphere > 0))
    throw std::invalid_argument(
        describe_range("max_events_per_sphere", max_events_per_sphere, "(0, inf)"));
}

DirectInteractions::DirectInteractions(DirectInteractionParams params) : params_(params) {
  params_.check();
}

const char* DirectInteractions::name(Kind k) {
  switch (k) {
    case Kind::collision:
      return "collision";
    case Kind::well_entry:
      return "well entry";
    case Kind::well_edge:
      return "well edge";
  }
  return "?";
}

void DirectInteractions::set_escape_velocity(double du) {
  DirectInteractionParams p = params_;
  p.escape_velocity = du;
  p.check();
  params_ = p;
  if (!wells_on()) attached_.clear();
}

void DirectInteractions::attach_pairs_within_well(const SphereSet& s, const PeriodicBox& box) {
  if (!wells_on())
    throw std::invalid_argument("attach_pairs_within_well: the well is off (escape_velocity 0)");
  const double well_edge = 2.0 * (s.radius + params_.well_width);
  for (const auto& p : neighbours::pairs_within(s.position, box, well_edge))
    attached_.insert(key(p.i, p.j));
}

std::vector<std::pair<int, int>> DirectInteractions::attached_pairs() const {
  std::vector<std::pair<int, int>> out;
  out.reserve(attached_.size());
  for (auto k : attached_)
    out.emplace_back(static_cast<int>(k >> 32), static_cast<int>(k & 0xffffffffu));
  std::sort(out.begin(), out.end());
  return out;
}

void DirectInteractions::set_attached_pairs(const std::vector<std::pair<int, int>>& pairs) {
  if (!pairs.empty() && !wells_on())
    throw std::invalid_argument("set_attached_pairs: attached pairs given while the well is off");
  std::unordered_set<std::uint64_t> next;
  for (auto [i, j] : pairs) {
    if (!(0 <= i && i < j))
      throw std::invalid_argument("set_attached_pairs: pair (" + std::to_string(i) + ", " +
                                  std::to_string(j) + ") must have 0 <= i < j");
    next.insert(key(i, j));
  }
  attached_ = std::move(next);
}

double DirectInteractions::well_energy(const SphereSet& s) const {
  const double du = params_.escape_velocity;
  return -s.mass() * du * du * static_cast<double>(attached_.size());
}

// Brings every sphere to time t, wraps it into the box and lists every pair
// that could meet an event before dt: pairs closer than the interaction range
// (2(a + delta) with wells, 2a without) plus a skin covering the largest
// approach possible in the time left, 2 * speed bound * (dt - t).
void DirectInteractions::build_pairs(SphereSet& s, const PeriodicBox& box, double t, double dt) {
  const int n = static_cast<int>(s.size());
  double vmax = 0;
  for (int i = 0; i < n; ++i) {
    s.position[i] = box.wrap(position_at(s, i, t));
    local_time_[i] = t;
    vmax = std::max(vmax, s.velocity[i].norm());
  }
  // A well entry raises a sphere's speed by at most du; collisions share speed
  // between partners. A sphere that outgrows the bound anyway triggers a rebuild.
  speed_bound_ = 1.5 * vmax + 2.0 * params_.escape_velocity;
  const double a = s.radius;
  const double range = wells_on() ? 2.0 * (a + params_.well_width) : 2.0 * a;
  const double cutoff = range + 2.0 * speed_bound_ * (dt - t) + kStateTolerance * a;

  const auto near = neighbours::pairs_within(s.position, box, cutoff);
  pairs_.clear();
  pairs_.reserve(near.size());
  std::size_t attached_found = 0;
  for (const auto& p : near) {
    const bool attached = !attached_.empty() && attached_.count(key(p.i, p.j)) > 0;
    attached_found += attached;
    pairs_.push_back({p.i, p.j, p.shift, attached});
  }
  if (attached_found != attached_.size()) {
    std::unordered_set<std::uint64_t> listed;
    for (const auto& p : pairs_) listed.insert(key(p.i, p.j));
    for (auto [i, j] : attached_pairs()) {
      if (listed.count(key(i, j))) continue;
      std::ostringstream os;
      os << "direct interactions: attached pair (" << i << ", " << j << ") ";
      if (j >= n)
        os << "names a sphere beyond the " << n << " spheres present";
      else
        os << "is " << box.minimum_image(s.position[j] - s.position[i]).norm()
           << " apart, beyond the well edge " << range << " (corrupt attachment state)";
      throw std::runtime_error(os.str());
    }
  }

  pairs_of_start_.assign(n + 1, 0);
  for (const auto& p : pairs_) {
    ++pairs_of_start_[p.i + 1];
    ++pairs_of_start_[p.j + 1];
  }
  for (int i = 0; i < n; ++i) pairs_of_start_[i + 1] += pairs_of_start_[i];
  pairs_of_.resize(pairs_of_start_[n]);
  std::vector<int> fill(pairs_of_start_.begin(), pairs_of_start_.end() - 1);
  for (int p = 0; p < static_cast<int>(pairs_.size()); ++p) {
    pairs_of_[fill[pairs_[p].i]++] = p;
    pairs_of_[fill[pairs_[p].j]++] = p;
  }

  queue_.clear();
  for (int p = 0; p < static_cast<int>(pairs_.size()); ++p) predict(s, p, t, dt);
}

// The next event of pair p after time t, queued if it falls within the step.
// An unattached pair outside the well can only enter it first; a pair inside
// the core range can collide; an attached one can also reach the well edge.
// An unattached pair inside the well (present when the well was switched on
// without attaching) interacts through its hard core only.
void DirectInteractions::predict(const SphereSet& s, int p, double t, double dt) {
  const Pair& pair = pairs_[p];
  const Vec3 r = position_at(s, pair.j, t) - position_at(s, pair.i, t) + pair.shift;
  const Vec3 v = s.velocity[pair.j] - s.velocity[pair.i];
  const double a = s.radius;
  const double well_edge = 2.0 * (a + params_.well_width);
  const double speed_floor = radial_speed_floor(s.velocity[pair.i], s.velocity[pair.j]);
  double wait;
  Kind kind;
  if (wells_on() && !pair.attached && r.squaredNorm() > well_edge * well_edge) {
    wait = time_to_close_to(r, v, well_edge, speed_floor);
    kind = Kind::well_entry;
  } else {
    wait = time_to_close_to(r, v, 2.0 * a, speed_floor);
    kind = Kind::collision;
    if (pair.attached) {
      const double to_edge = time_to_open_to(r, v, well_edge, speed_floor);
      if (to_edge < wait) {
        wait = to_edge;
        kind = Kind::well_edge;
      }
    }
  }
  if (t + wait <= dt) {
    queue_.push_back({t + wait, p, kind, event_count_[pair.i], event_count_[pair.j]});
    std::push_heap(queue_.begin(), queue_.end(), std::greater<>{});
  }
}

void DirectInteractions::execute(SphereSet& s, const Event& e) {
  Pair& pair = pairs_[e.pair];
  const int i = pair.i, j = pair.j;
  s.position[i] = position_at(s, i, e.time);
  s.position[j] = position_at(s, j, e.time);
  local_time_[i] = local_time_[j] = e.time;
  const Vec3 r = s.position[j] - s.position[i] + pair.shift;
  const double distance = r.norm();
  const Vec3 n = r / distance;
  const double radial_velocity = (s.velocity[j] - s.velocity[i]).dot(n);
  const double du = params_.escape_velocity;
  // The same closing/separating test as the prediction (pair_kinematics.hpp).
  const double speed_floor = radial_speed_floor(s.velocity[i], s.velocity[j]);

  switch (e.kind) {
    case Kind::collision: {
      const bool within_contact = e.time - last_collision_[i] < params_.contact_duration ||
                                  e.time - last_collision_[j] < params_.contact_duration;
      const HardSphereCollision collide{within_contact ? 1.0 : params_.restitution,
                                        params_.friction};
      if (radial_velocity < -speed_floor &&
          collide(s.velocity[i], s.angular_velocity[i], s.velocity[j], s.angular_velocity[j], n,
                  s.radius)) {
        ++counters_.collisions;
        last_collision_[i] = last_collision_[j] = e.time;
      }
      break;
    }
    case Kind::well_entry:
      if (radial_velocity < -speed_floor) {
        enter_well(s.velocity[i], s.velocity[j], n, du);
        pair.attached = true;
        attached_.insert(key(i, j));
        ++counters_.well_entries;
      }
      break;
    case Kind::well_edge:
      if (!(radial_velocity > speed_floor)) break;
      if (reach_well_edge(s.velocity[i], s.velocity[j], n, du)) {
        pair.attached = false;
        attached_.erase(key(i, j));
        ++counters_.escapes;
      } else {
        ++counters_.edge_bounces;
      }
      break;
  }
  ++event_count_[i];
  ++event_count_[j];
  if (recent_.size() == kRecentEvents) recent_.erase(recent_.begin());
  recent_.push_back({e.time, i, j, e.kind, distance - 2.0 * s.radius, radial_velocity});
}

void DirectInteractions::throw_event_cap(const SphereSet& s, double t, double dt,
                                         std::size_t cap) const {
  std::ostringstream os;
  os.precision(17);
  os << "direct interactions: more than " << cap << " events (" << params_.max_events_per_sphere
     << " per sphere) in one step of " << dt << ", stopped at time " << t << " into the step with "
     << s.size() << " spheres and " << attached_.size()
     << " attached pairs. Typical causes: inelastic collapse (restitution " << params_.restitution
     << " < 1 with spheres in lasting contact), a pair grazing the well edge, or speeds far "
        "above the lattice scale. Last events (time, pair, kind, gap, radial velocity):";
  for (const auto& r : recent_)
    os << "\n  " << r.time << "  (" << r.i << ", " << r.j << ")  " << name(r.kind) << "  " << r.gap
       << "  " << r.radial_velocity;
  throw EventCapExceeded(os.str());
}

void DirectInteractions::advance(SphereSet& s, const PeriodicBox& box, double dt) {
  if (!(dt > 0 && std::isfinite(dt)))
    throw std::invalid_argument("direct interactions: time step must be positive, got " +
                                std::to_string(dt));
  const int n = static_cast<int>(s.size());
  if (s.velocity.size() != s.size() || s.angular_velocity.size() != s.size())
    throw std::invalid_argument("direct interactions: sphere arrays differ in length");
  local_time_.assign(n, 0.0);
  event_count_.assign(n, 0);
  last_collision_.assign(n, -kNever);
  recent_.clear();
  if (n < 2) {
    for (int i = 0; i < n; ++i) s.position[i] = box.wrap(s.position[i] + s.velocity[i] * dt);
    ++counters_.steps;
    return;
  }

  const double a = s.radius;
  const double tolerance = kStateTolerance * a;
  const double well_edge = 2.0 * (a + params_.well_width);
  build_pairs(s, box, 0.0, dt);
  for (const auto& p : pairs_) {
    const double gap = (s.position[p.j] - s.position[p.i] + p.shift).norm() - 2.0 * a;
    if (gap < -tolerance) {
      std::ostringstream os;
      os << "direct interactions: spheres " << p.i << " and " << p.j << " overlap by " << -gap
         << " (more than round-off) at the start of the step";
      throw std::runtime_error(os.str());
    }
  }

  const std::size_t cap = static_cast<std::size_t>(params_.max_events_per_sphere * n) + 1;
  std::size_t executed = 0;
  while (!queue_.empty()) {
    std::pop_heap(queue_.begin(), queue_.end(), std::greater<>{});
    const Event e = queue_.back();
    queue_.pop_back();
    const Pair& pair = pairs_[e.pair];
    const int i = pair.i, j = pair.j;
    if (e.count_i != event_count_[i] || e.count_j != event_count_[j]) continue;  // outdated
    if (++executed > cap) throw_event_cap(s, e.time, dt, cap);
    execute(s, e);
    const double bound_sq = speed_bound_ * speed_bound_;
    if (s.velocity[i].squaredNorm() > bound_sq || s.velocity[j].squaredNorm() > bound_sq) {
      ++counters_.neighbour_rebuilds;
      build_pairs(s, box, e.time, dt);
      continue;
    }
    for (int m = pairs_of_start_[i]; m < pairs_of_start_[i + 1]; ++m)
      predict(s, pairs_of_[m], e.time, dt);
    for (int m = pairs_of_start_[j]; m < pairs_of_start_[j + 1]; ++m)
      if (pairs_of_[m] != e.pair) predict(s, pairs_of_[m], e.time, dt);
  }

  for (int i = 0; i < n; ++i) {
    s.position[i] = position_at(s, i, dt);
    local_time_[i] = dt;
  }
  for (const auto& p : pairs_) {
    const double distance = (s.position[p.j] - s.position[p.i] + p.shift).norm();
    worst_overlap_ = std::max(worst_overlap_, 2.0 * a - distance);
    if (distance < 2.0 * a - tolerance || (p.attached && distance > well_edge + tolerance)) {
      std::ostringstream os;
      os.precision(17);
      os << "direct interactions: after the step spheres " << p.i << " and " << p.j << " are "
         << distance << " apart (" << (p.attached ? "attached, " : "") << "contact at " << 2.0 * a
         << ", well edge at " << well_edge << "): an event was missed";
      throw std::runtime_error(os.str());
    }
  }
  for (int i = 0; i < n; ++i) s.position[i] = box.wrap(s.position[i]);
  ++counters_.steps;
}

}  // namespace flocsim::events
