#include "engine/calibration/pair_resistance.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/calibration/shipped_pair_table.hpp"
#include "engine/calibration/table_scheme.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/lubrication/two_sphere_resistance.hpp"

namespace flocsim::calibration {

namespace {

// The input radius the pair is measured with: given, or the shipped calibration's.
double input_radius_of(double a, const PairResistanceSettings& set) {
  return set.input_radius > 0
             ? set.input_radius
             : CalibrationTable::shipped().input_radius(a, set.viscosity, set.scheme);
}

// Two spheres of hydrodynamic radius a held on the x axis of a periodic box
// L x L/2 x L/2, moving along their line of centres at +-V, without lubrication.
class HeldPair {
 public:
  HeldPair(double a, bool separating, const PairResistanceSettings& set)
      : a_(a),
        nu_(set.viscosity),
        box_(static_cast<int>(std::lround(set.box_over_a * a / 2)) * 2),
        towards_(separating ? -1.0 : 1.0),
        V_(0.5 * set.reynolds * set.viscosity / a),
        set_(set),
        fluid_({box_, box_ / 2, box_ / 2}, {set.viscosity, 0.25}),
        coupling_(coupling::make_coupling<double>(set.scheme, input_radius_of(a, set))) {
    fluid_.initialise_equilibrium([](int, int, int) { return lattice::Macroscopic{}; });
    pair_.radius = a;
    pair_.resize(2);
    pair_.velocity[0] = {towards_ * V_, 0, 0};
    pair_.velocity[1] = {-towards_ * V_, 0, 0};
  }

  // Moves the pair to gap s and runs until the force is steady.
  PairResistancePoint measure(double gap_over_a) {
    // off the lattice's symmetry planes, so that no marker sits on a node by design
    const double cx = 0.5 * box_, cy = 0.25 * box_ + 0.37, cz = 0.25 * box_ + 0.21;
    pair_.position[0] = {cx - a_ - 0.5 * gap_over_a * a_, cy, cz};
    pair_.position[1] = {cx + a_ + 0.5 * gap_over_a * a_, cy, cz};
    PairResistancePoint p{.gap_over_a = gap_over_a,
                          .lambda_exact = lubrication::brenner_pair_resistance(gap_over_a)};
    double last = 0;
    int quiet_checks = 0;  // consecutive checks below the tolerance
    for (long step = 1; step <= set_.max_steps; ++step) {
      coupling_->apply(fluid_, pair_);
      fluid_.step();
      coupling_->after_liquid_step(fluid_, pair_);
      if (step % 200 != 0) continue;
      // the force on sphere 0 opposes its motion, which is +x when approaching
      const double lambda = -towards_ * coupling_->force()[0].x() / (6 * M_PI * nu_ * a_ * V_);
      if (!std::isfinite(lambda))
        throw std::runtime_error("pair resistance: the measurement blew up at gap " +
                                 std::to_string(gap_over_a) + " a");
      p.lambda_measured = lambda;
      p.steps = step;
      quiet_checks =
          std::abs(lambda - last) < set_.tolerance * std::abs(lambda) ? quiet_checks + 1 : 0;
      if (step > 1000 && quiet_checks >= 3) return p;
      last = lambda;
    }
    throw std::runtime_error("pair resistance: not steady after " + std::to_string(set_.max_steps) +
                             " steps at gap " + std::to_string(gap_over_a) + " a");
  }

  int box() const { return box_; }

 private:
  double a_, nu_;
  int box_;
  double towards_, V_;
  PairResistanceSettings set_;
  lattice::FluidLattice<double> fluid_;
  std::unique_ptr<coupling::SphereCoupling<double>> coupling_;
  spheres::SphereSet pair_;
};

}  // namespace

PairResistancePoint measure_pair_resistance(double a, double gap_over_a, bool separating,
                                            const PairResistanceSettings& set) {
  HeldPair pair(a, separating, set);
  return pair.measure(gap_over_a);
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
  HeldPair pair(a, separating, s);
  PairResistanceEntry e{.hydrodynamic_radius = a,
                        .viscosity = s.viscosity,
                        .scheme = s.scheme,
                        .box = pair.box(),
                        .separating = separating};
  for (double g : gaps) {
    e.points.push_back(pair.measure(g));
    if (progress) progress(e.points.back());
  }
  e.box_offset = e.points.back().lambda_measured - e.points.back().lambda_exact;
  e.input_radius = input_radius_of(a, s);
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
    nlohmann::json je = {{"hydrodynamic_radius", e.hydrodynamic_radius},
                         {"viscosity", e.viscosity},
                         {"box", e.box},
                         {"separating", e.separating},
                         {"box_offset", e.box_offset},
                         {"input_radius", e.input_radius},
                         {"points", points}};
    write_scheme(je, e.scheme);
    j["entries"].push_back(je);
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
      e.scheme = scheme_from_entry(je, origin);
      e.box = je.at("box").get<int>();
      e.separating = je.at("separating").get<bool>();
      e.box_offset = je.at("box_offset").get<double>();
      e.input_radius = je.value("input_radius", 0.0);
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
bool same_scheme(const PairResistanceEntry& e, double a, const coupling::Scheme& scheme) {
  return !e.separating && std::abs(e.hydrodynamic_radius - a) <= 1e-6 &&
         e.scheme.same_calibration(scheme);
}

// The approaching entries of this a and scheme nearest nu from below and from
// above (either null where none lies on that side).
struct Bracket {
  const PairResistanceEntry* below = nullptr;
  const PairResistanceEntry* above = nullptr;
};
Bracket bracket(const std::vector<PairResistanceEntry>& entries, double a, double nu,
                const coupling::Scheme& scheme) {
  Bracket b;
  for (const auto& e : entries) {
    if (!same_scheme(e, a, scheme)) continue;
    if (e.viscosity <= nu && (!b.below || e.viscosity > b.below->viscosity)) b.below = &e;
    if (e.viscosity >= nu && (!b.above || e.viscosity < b.above->viscosity)) b.above = &e;
  }
  return b;
}
}  // namespace

void PairResistanceTable::add(const PairResistanceEntry& entry) {
  std::erase_if(entries_, [&](const PairResistanceEntry& e) {
    return e.separating == entry.separating &&
           std::abs(e.hydrodynamic_radius - entry.hydrodynamic_radius) <= 1e-6 &&
           std::abs(e.viscosity - entry.viscosity) <= 1e-12 &&
           e.scheme.same_calibration(entry.scheme);
  });
  entries_.push_back(entry);
}

bool PairResistanceTable::has(double a, const coupling::Scheme& scheme) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const auto& e) { return same_scheme(e, a, scheme); });
}

std::vector<std::pair<double, double>> PairResistanceTable::lattice_share(
    double a, double nu, const coupling::Scheme& scheme) const {
  auto [below, above] = bracket(entries_, a, nu, scheme);
  if (!below && !above) {
    std::ostringstream msg;
    msg << "no close-pair calibration for a = " << a << " dx with " << scheme.describe()
        << "; calibrated:";
    std::vector<std::string> seen;
    for (const auto& e : entries_) {
      if (e.separating) continue;
      std::ostringstream one;
      one << " a = " << e.hydrodynamic_radius << " (" << e.scheme.describe() << ")";
      if (std::find(seen.begin(), seen.end(), one.str()) == seen.end()) seen.push_back(one.str());
    }
    for (std::size_t k = 0; k < seen.size(); ++k) msg << (k ? "," : "") << seen[k];
    msg << ". Run `" << close_pair_calibrate_command(a, nu, scheme)
        << "` and rebuild, or set lubrication_model to nguyen-ladd.";
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

double PairResistanceTable::viscosity_gap(double a, double nu,
                                          const coupling::Scheme& scheme) const {
  const auto [below, above] = bracket(entries_, a, nu, scheme);
  if (!below && !above) return std::numeric_limits<double>::infinity();
  if (below && above) return 1.0;
  return below ? nu / below->viscosity : above->viscosity / nu;
}

std::string close_pair_calibrate_command(double a, double nu, const coupling::Scheme& scheme) {
  std::ostringstream cmd;
  cmd << "flocsim calibrate --close-pairs --radius " << a << " --viscosity " << nu;
  if (a >= 6) cmd << " --pair-box 12";
  cmd << calibrate_options(scheme) << " --table engine/calibration/pair_resistance.json";
  return cmd.str();
}

}  // namespace flocsim::calibration
