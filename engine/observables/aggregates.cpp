#include "engine/observables/aggregates.hpp"

#include <numeric>

#include "engine/neighbours/pair_search.hpp"

namespace flocsim::observables {

namespace {

// Union-find with path halving; the root of a group is its smallest member so
// that aggregate ids come out in a deterministic order.
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(int n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  int root(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(int i, int j) {
    i = root(i);
    j = root(j);
    if (i == j) return;
    if (i < j)
      parent[j] = i;
    else
      parent[i] = j;
  }
};

}  // namespace

Aggregates find_aggregates(const std::vector<spheres::Vec3>& position,
                           const spheres::PeriodicBox& box, double bond_distance) {
  const int n = static_cast<int>(position.size());
  Aggregates out;
  out.size_distribution.assign(static_cast<std::size_t>(n) + 1, 0.0);
  if (n == 0) return out;
  DisjointSets sets(n);
  const auto bonds = neighbours::pairs_within(position, box, bond_distance);
  for (const auto& b : bonds) sets.join(b.i, b.j);
  out.contacts_per_sphere = 2.0 * static_cast<double>(bonds.size()) / n;

  std::vector<int> id_of_root(static_cast<std::size_t>(n), -1);
  out.aggregate_of.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const int r = sets.root(i);
    if (id_of_root[r] < 0) {
      id_of_root[r] = static_cast<int>(out.aggregate_size.size());
      out.aggregate_size.push_back(0);
    }
    out.aggregate_of[i] = id_of_root[r];
    ++out.aggregate_size[id_of_root[r]];
  }
  // p(n): each aggregate of size s holds s spheres, a fraction s / N of all.
  for (int s : out.aggregate_size) out.size_distribution[s] += static_cast<double>(s) / n;
  for (int s = 1; s <= n; ++s) out.mean_size += s * out.size_distribution[s];
  return out;
}

}  // namespace flocsim::observables
