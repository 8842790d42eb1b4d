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

// How the held pair moves; sphere 0 sits at -x of the box's centre, sphere 1
// at +x, each sphere's surface moving at V where it faces the other.
enum class PairMotion { approach, separate, slide, roll };

// The force and torque on sphere 0 once steady, in units of 6 pi rho nu a V
// and 8 pi rho nu a^2 V.
struct HeldPairReading {
  spheres::Vec3 force = spheres::Vec3::Zero(), torque = spheres::Vec3::Zero();
  long steps = 0;
};

// Two spheres of hydrodynamic radius a held on the x axis of a periodic box
// L x L/2 x L/2, moving at speed V, without lubrication.
class HeldPair {
 public:
  HeldPair(double a, PairMotion motion, const PairResistanceSettings& set)
      : a_(a),
        nu_(set.viscosity),
        box_(static_cast<int>(std::lround(set.box_over_a * a / 2)) * 2),
        V_(0.5 * set.reynolds * set.viscosity / a),
        motion_(motion),
        set_(set),
        fluid_({box_, box_ / 2, box_ / 2}, {set.viscosity, 0.25}),
        coupling_(coupling::make_coupling<double>(set.scheme, input_radius_of(a, set))) {
    fluid_.initialise_equilibrium([](int, int, int) { return lattice::Macroscopic{}; });
    pair_.radius = a;
    pair_.resize(2);
    switch (motion) {
      case PairMotion::approach:
      case PairMotion::separate: {
        const double towards = motion == PairMotion::approach ? 1.0 : -1.0;
        pair_.velocity[0] = {towards * V_, 0, 0};
        pair_.velocity[1] = {-towards * V_, 0, 0};
        break;
      }
      case PairMotion::slide:  // the facing surfaces slip past each other at 2V
        pair_.velocity[0] = {0, V_, 0};
        pair_.velocity[1] = {0, -V_, 0};
        break;
      case PairMotion::roll:  // counter-rotating: the facing surfaces both move at +V along y
        pair_.angular_velocity[0] = {0, 0, V_ / a};
        pair_.angular_velocity[1] = {0, 0, -V_ / a};
        break;
    }
  }

  // Moves the pair to gap s and runs until the force and torque on sphere 0
  // are steady: the component that resists the motion (`primary`, of
  // `force` or `torque`) changes by less than the tolerance per 200 steps,
  // three checks running, and the other one by less than the tolerance
  // relative to the primary's size.
  HeldPairReading measure(double gap_over_a) {
    // off the lattice's symmetry planes, so that no marker sits on a node by design
    const double cx = 0.5 * box_, cy = 0.25 * box_ + 0.37, cz = 0.25 * box_ + 0.21;
    pair_.position[0] = {cx - a_ - 0.5 * gap_over_a * a_, cy, cz};
    pair_.position[1] = {cx + a_ + 0.5 * gap_over_a * a_, cy, cz};
    HeldPairReading r;
    const double force_unit = 6 * M_PI * nu_ * a_ * V_, torque_unit = 8 * M_PI * nu_ * a_ * a_ * V_;
    const bool tangential = motion_ == PairMotion::slide || motion_ == PairMotion::roll;
    auto primary = [&](const HeldPairReading& x) {
      return motion_ == PairMotion::roll ? x.torque.z() : tangential ? x.force.y() : x.force.x();
    };
    auto secondary = [&](const HeldPairReading& x) {
      return motion_ == PairMotion::roll    ? x.force.y()
             : motion_ == PairMotion::slide ? x.torque.z()
                                            : 0.0;
    };
    HeldPairReading last;
    int quiet_checks = 0;  // consecutive checks below the tolerance
    for (long step = 1; step <= set_.max_steps; ++step) {
      coupling_->apply(fluid_, pair_);
      fluid_.step();
      coupling_->after_liquid_step(fluid_, pair_);
      if (tangential) {
        // Rolling pushes both spheres the same way (and the lattice's grid
        // need not cancel sliding's two forces exactly): a body force returns
        // their sum to the liquid, whose mean momentum a periodic box would
        // otherwise grow until the spheres' drag on the drift cancelled it.
        // The radial motions' two forces cancel by the pair's symmetry, and
        // they run as the shipped close-pair table was measured, so that
        // `flocsim calibrate --close-pairs` reproduces it bit for bit.
        const spheres::Vec3 back = (coupling_->force()[0] + coupling_->force()[1]) /
                                   (static_cast<double>(box_) * (box_ / 2) * (box_ / 2));
        fluid_.set_body_force({back.x(), back.y(), back.z()});
      }
      if (step % 200 != 0) continue;
      r.force = coupling_->force()[0] / force_unit;
      r.torque = coupling_->torque()[0] / torque_unit;
      r.steps = step;
      const double p = primary(r);
      if (!std::isfinite(p) || !std::isfinite(secondary(r)))
        throw std::runtime_error("pair resistance: the measurement blew up at gap " +
                                 std::to_string(gap_over_a) + " a");
      const double tol = set_.tolerance * std::abs(p);
      quiet_checks =
          std::abs(p - primary(last)) < tol && std::abs(secondary(r) - secondary(last)) < tol
              ? quiet_checks + 1
              : 0;
      if (step > 1000 && quiet_checks >= 3) return r;
      last = r;
    }
    throw std::runtime_error("pair resistance: not steady after " + std::to_string(set_.max_steps) +
                             " steps at gap " + std::to_string(gap_over_a) + " a");
  }

  int box() const { return box_; }

 private:
  double a_, nu_;
  int box_;
  double V_;
  PairMotion motion_;
  PairResistanceSettings set_;
  lattice::FluidLattice<double> fluid_;
  std::unique_ptr<coupling::SphereCoupling<double>> coupling_;
  spheres::SphereSet pair_;
};

PairMotion radial_motion(bool separating) {
  return separating ? PairMotion::separate : PairMotion::approach;
}

// lambda: the force on sphere 0 against its radial motion (+x when approaching)
PairResistancePoint radial_point(double gap_over_a, bool separating, const HeldPairReading& r) {
  return {.gap_over_a = gap_over_a,
          .lambda_measured = (separating ? 1.0 : -1.0) * r.force.x(),
          .lambda_exact = lubrication::brenner_pair_resistance(gap_over_a),
          .steps = r.steps};
}

}  // namespace

PairResistancePoint measure_pair_resistance(double a, double gap_over_a, bool separating,
                                            const PairResistanceSettings& set) {
  HeldPair pair(a, radial_motion(separating), set);
  return radial_point(gap_over_a, separating, pair.measure(gap_over_a));
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
  HeldPair pair(a, radial_motion(separating), s);
  PairResistanceEntry e{.hydrodynamic_radius = a,
                        .viscosity = s.viscosity,
                        .scheme = s.scheme,
                        .box = pair.box(),
                        .separating = separating};
  for (double g : gaps) {
    e.points.push_back(radial_point(g, separating, pair.measure(g)));
    if (progress) progress(e.points.back());
  }
  e.box_offset = e.points.back().lambda_measured - e.points.back().lambda_exact;
  e.input_radius = input_radius_of(a, s);
  return e;
}

std::vector<PairTangentialPoint> measure_pair_tangential(
    double a, const std::vector<double>& gaps, TangentialMotion motion,
    const PairResistanceSettings& s,
    const std::function<void(const PairTangentialPoint&)>& progress) {
  if (gaps.empty()) throw std::invalid_argument("pair resistance: no gaps to measure");
  HeldPair pair(a, motion == TangentialMotion::slide ? PairMotion::slide : PairMotion::roll, s);
  std::vector<PairTangentialPoint> points;
  for (double g : gaps) {
    const HeldPairReading r = pair.measure(g);
    points.push_back(
        {.gap_over_a = g, .force_y = r.force.y(), .torque_z = r.torque.z(), .steps = r.steps});
    if (progress) progress(points.back());
  }
  return points;
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
