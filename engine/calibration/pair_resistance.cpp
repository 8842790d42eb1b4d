#include "engine/calibration/pair_resistance.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/calibration/shipped_pair_table.hpp"
#include "engine/immersed_boundary/immersed_boundary.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lubrication/two_sphere_resistance.hpp"

namespace flocsim::calibration {

PairResistancePoint measure_pair_resistance(double a, double gap_over_a, bool separating,
                                            const PairResistanceSettings& set) {
  const int box = static_cast<int>(std::lround(set.box_over_a * a / 2)) * 2;
  const double nu = set.viscosity;
  lattice::FluidLattice<double> fluid({box, box / 2, box / 2}, {nu, 0.25});
  fluid.initialise_equilibrium([](int, int, int) { return lattice::Macroscopic{}; });
  const double a_g =
      CalibrationTable::shipped().input_radius(a, nu, set.marker_spacing, set.iterations);
  immersed_boundary::ImmersedBoundary<double> ib({a_g, set.marker_spacing, set.iterations, false});
  spheres::SphereSet pair;
  pair.radius = a;
  pair.resize(2);
  const double V = 0.5 * set.reynolds * nu / a;
  // off the lattice's symmetry planes, so that no marker sits on a node by design
  const double cx = 0.5 * box, cy = 0.25 * box + 0.37, cz = 0.25 * box + 0.21;
  pair.position[0] = {cx - a - 0.5 * gap_over_a * a, cy, cz};
  pair.position[1] = {cx + a + 0.5 * gap_over_a * a, cy, cz};
  const double towards = separating ? -1.0 : 1.0;
  pair.velocity[0] = {towards * V, 0, 0};
  pair.velocity[1] = {-towards * V, 0, 0};
  PairResistancePoint p{.gap_over_a = gap_over_a,
                        .lambda_exact = lubrication::brenner_pair_resistance(gap_over_a)};
  double last = 0;
  int quiet_checks = 0;  // consecutive checks below the tolerance
  for (long step = 1; step <= set.max_steps; ++step) {
    ib.apply(fluid, pair);
    fluid.step();
    if (step % 200 != 0) continue;
    // the force on sphere 0 opposes its motion, which is +x when approaching
    const double lambda = -towards * ib.force()[0].x() / (6 * M_PI * nu * a * V);
    if (!std::isfinite(lambda))
      throw std::runtime_error("pair resistance: the measurement blew up at gap " +
                               std::to_string(gap_over_a) + " a");
    p.lambda_measured = lambda;
    p.steps = step;
    quiet_checks =
        std::abs(lambda - last) < set.tolerance * std::abs(lambda) ? quiet_checks + 1 : 0;
    if (step > 1000 && quiet_checks >= 3) return p;
    last = lambda;
  }
  throw std::runtime_error("pair resistance: not steady after " + std::to_string(set.max_steps) +
                           " steps at gap " + std::to_string(gap_over_a) + " a");
}

std::vector<double> default_pair_gaps() {
  return {0.005, 0.01, 0.02, 0.035, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.5};
}

double PairResistanceEntry::lattice_share(double e) const {
  if (points.empty()) throw std::logic_error("pair resistance entry without points");
  double measured = points.front().lambda_measured;
  if (e >= points.back().gap_over_a) {
    measured = points.back().lambda_measured;
  } else if (e > points.front().gap_over_a) {
    std::size_t k = 1;
    while (points[k].gap_over_a < e) ++k;
    const auto &lo = points[k - 1], &hi = points[k];
    const double f = (e - lo.gap_over_a) / (hi.gap_over_a - lo.gap_over_a);
    measured = lo.lambda_measured + f * (hi.lambda_measured - lo.lambda_measured);
  }
  return measured - box_offset;
}

PairResistanceEntry calibrate_pair_resistance(double a, const std::vector<double>& gaps,
                                              bool separating, const PairResistanceSettings& s,
                                              void (*progress)(const PairResistancePoint&)) {
  if (gaps.empty()) throw std::invalid_argument("pair resistance: no gaps to measure");
  for (std::size_t k = 0; k < gaps.size(); ++k)
    if (!(gaps[k] > 0) || (k > 0 && gaps[k] <= gaps[k - 1]))
      throw std::invalid_argument("pair resistance: gaps must be positive and increasing");
  PairResistanceEntry e{.hydrodynamic_radius = a,
                        .viscosity = s.viscosity,
                        .marker_spacing = s.marker_spacing,
                        .iterations = s.iterations,
                        .box = static_cast<int>(std::lround(s.box_over_a * a / 2)) * 2,
                        .separating = separating};
  for (double g : gaps) {
    e.points.push_back(measure_pair_resistance(a, g, separating, s));
    if (progress) progress(e.points.back());
  }
  e.box_offset = e.points.back().lambda_measured - e.points.back().lambda_exact;
  return e;
}

// ---- the table ----

void PairResistanceTable::save(const std::string& filename) const {
  nlohmann::json j;
  j["note"] = note;
  j["entries"] = nlohmann::json::array();
  for (const auto& e : entries_) {
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : e.points)
      points.push_back({{"gap_over_a", p.gap_over_a},
                        {"lambda_measured", p.lambda_measured},
                        {"lambda_exact", p.lambda_exact},
                        {"steps", p.steps}});
    j["entries"].push_back({{"hydrodynamic_radius", e.hydrodynamic_radius},
                            {"viscosity", e.viscosity},
                            {"marker_spacing", e.marker_spacing},
                            {"iterations", e.iterations},
                            {"box", e.box},
                            {"separating", e.separating},
                            {"box_offset", e.box_offset},
                            {"points", points}});
  }
  std::ofstream out(filename);
  if (!out) throw std::runtime_error("cannot write pair-resistance table " + filename);
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error("error writing pair-resistance table " + filename);
}

PairResistanceTable PairResistanceTable::load(const std::string& filename) {
  std::ifstream in(filename);
  if (!in) throw std::runtime_error("cannot read pair-resistance table " + filename);
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), filename);
}

const PairResistanceTable& PairResistanceTable::shipped() {
  static const PairResistanceTable table =
      parse(kShippedPairTableJson, "the shipped pair-resistance table");
  return table;
}

PairResistanceTable PairResistanceTable::parse(const std::string& json_text,
                                               const std::string& origin) {
  PairResistanceTable t;
  try {
    const auto j = nlohmann::json::parse(json_text);
    t.note = j.value("note", "");
    for (const auto& je : j.at("entries")) {
      PairResistanceEntry e;
      e.hydrodynamic_radius = je.at("hydrodynamic_radius").get<double>();
      e.viscosity = je.at("viscosity").get<double>();
      e.marker_spacing = je.at("marker_spacing").get<double>();
      e.iterations = je.at("iterations").get<int>();
      e.box = je.at("box").get<int>();
      e.separating = je.at("separating").get<bool>();
      e.box_offset = je.at("box_offset").get<double>();
      for (const auto& jp : je.at("points"))
        e.points.push_back({jp.at("gap_over_a").get<double>(),
                            jp.at("lambda_measured").get<double>(),
                            jp.at("lambda_exact").get<double>(), jp.at("steps").get<long>()});
      if (e.points.empty()) throw std::runtime_error("an entry without points");
      t.entries_.push_back(e);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("pair-resistance table " + origin + ": " + e.what());
  }
  return t;
}

namespace {
bool same_scheme(const PairResistanceEntry& e, double a, double spacing, int iterations) {
  return !e.separating && std::abs(e.hydrodynamic_radius - a) <= 1e-6 &&
         std::abs(e.marker_spacing - spacing) <= 1e-9 && e.iterations == iterations;
}
}  // namespace

void PairResistanceTable::add(const PairResistanceEntry& entry) {
  std::erase_if(entries_, [&](const PairResistanceEntry& e) {
    return e.separating == entry.separating &&
           std::abs(e.hydrodynamic_radius - entry.hydrodynamic_radius) <= 1e-6 &&
           std::abs(e.viscosity - entry.viscosity) <= 1e-12 &&
           std::abs(e.marker_spacing - entry.marker_spacing) <= 1e-9 &&
           e.iterations == entry.iterations;
  });
  entries_.push_back(entry);
}

bool PairResistanceTable::has(double a, double spacing, int iterations) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const auto& e) { return same_scheme(e, a, spacing, iterations); });
}

std::vector<std::pair<double, double>> PairResistanceTable::lattice_share(double a, double nu,
                                                                          double spacing,
                                                                          int iterations) const {
  const PairResistanceEntry *below = nullptr, *above = nullptr;
  for (const auto& e : entries_) {
    if (!same_scheme(e, a, spacing, iterations)) continue;
    if (e.viscosity <= nu && (!below || e.viscosity > below->viscosity)) below = &e;
    if (e.viscosity >= nu && (!above || e.viscosity < above->viscosity)) above = &e;
  }
  if (!below && !above) {
    std::ostringstream msg;
    msg << "no close-pair calibration for a = " << a << " dx (marker spacing " << spacing << ", "
        << iterations << " iterations); calibrated:";
    for (const auto& e : entries_)
      if (!e.separating)
        msg << " a = " << e.hydrodynamic_radius << " (nu = " << e.viscosity << ", spacing "
            << e.marker_spacing << ", " << e.iterations << " it)";
    msg << ". Run `flocsim calibrate --close-pairs`, or set lubrication_model to nguyen-ladd.";
    throw std::out_of_range(msg.str());
  }
  if (!below) below = above;
  if (!above) above = below;
  const double f = below == above ? 0.0
                                  : std::log(nu / below->viscosity) /
                                        std::log(above->viscosity / below->viscosity);
  std::vector<std::pair<double, double>> share;
  for (const auto& p : below->points) {
    const double lo = below->lattice_share(p.gap_over_a), hi = above->lattice_share(p.gap_over_a);
    share.emplace_back(p.gap_over_a, lo + f * (hi - lo));
  }
  return share;
}

}  // namespace flocsim::calibration
