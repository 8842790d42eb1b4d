#include "engine/calibration/hydrodynamic_radius.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "engine/calibration/shipped_table.hpp"
#include "engine/calibration/table_scheme.hpp"
#include "engine/coupling_schemes/make_coupling.hpp"
#include "engine/lattice/fluid_lattice.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::calibration {

namespace {
constexpr std::array<double, 31> kSanganiAcrivos = {
    1.000000,  1.418649,  2.012564,   2.331523,  2.564809, 2.584787, 2.873609, 3.340163,
    3.536763,  3.504092,  3.253622,   2.689757,  2.037769, 1.809341, 1.877347, 1.534685,
    0.9034708, 0.2857896, -0.5512626, -1.278724, 1.013350, 5.492491, 4.615388, -0.5736023,
    -2.865924, -4.709215, -6.870076,  0.1455304, 12.51891, 9.742811, -5.566269};
}  // namespace

double sangani_acrivos_drag(double chi) {
  if (!(chi >= 0.0 && chi < 1.0))
    throw std::invalid_argument("Sangani-Acrivos drag: chi = " + std::to_string(chi) +
                                ": must be in [0, 1)");
  double k = 0, p = 1;
  for (double q : kSanganiAcrivos) {
    k += q * p;
    p *= chi;
  }
  return k;
}

double hasimoto_drag(double chi) {
  const double phi = M_PI / 6.0 * chi * chi * chi;
  return 1.0 / (1.0 - 1.7601 * std::cbrt(phi) + phi - 1.5593 * phi * phi);
}

double ArrayDragResult::drag_coefficient(double a, double viscosity) const {
  const double force = body_force * box * box * box;
  return force / (6.0 * M_PI * viscosity * a * superficial_velocity);
}

double hydrodynamic_radius_from_drag(double force, double superficial_velocity, double viscosity,
                                     int box) {
  // g(a) = F / (6 pi nu a U) - K(2a/L) falls monotonically in a.
  auto g = [&](double a) {
    return force / (6.0 * M_PI * viscosity * a * superficial_velocity) -
           sangani_acrivos_drag(2.0 * a / box);
  };
  double lo = 1e-3, hi = 0.4999 * box;
  if (g(lo) < 0 || g(hi) > 0)
    throw std::runtime_error(
        "hydrodynamic radius: no radius in (0, L/2) matches the Sangani-Acrivos drag");
  for (int i = 0; i < 200 && hi - lo > 1e-13 * box; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

// The flow through one simple cubic array, kept between the passes of a
// calibration: a new input radius changes the steady flow only slightly, so
// each pass starts from the last one's flow instead of from rest (the steady
// state reached is the same; the transient, most of the steps at low
// viscosity, is not repeated).
class ArrayFlow {
 public:
  ArrayFlow(int box, const ArrayDragSettings& settings, double grid_offset)
      : box_(box),
        grid_offset_(grid_offset),
        settings_(settings),
        fluid_({box, box, box}, {settings.viscosity, 0.25}) {
    sphere_.resize(1);
    sphere_.position[0] =
        spheres::Vec3::Constant(grid_offset < 0 ? 0.5 * box : box / 2 + grid_offset);
  }

  ArrayDragResult run_to_steady(double input_radius) {
    // The previous sphere's force leaves the lattice with it.
    if (coupling_) coupling_->remove(fluid_);
    coupling_ = coupling::make_coupling<double>(settings_.scheme, input_radius);
    sphere_.radius = input_radius;
    // Body force from the reference drag of a sphere of radius a_g, so that U
    // comes out near the requested superficial velocity.
    const double cells = static_cast<double>(box_) * box_ * box_;
    const double chi = std::min(0.95, 2.0 * input_radius / box_);
    const double body_force = 6.0 * M_PI * settings_.viscosity * input_radius *
                              sangani_acrivos_drag(chi) * settings_.superficial_velocity / cells;
    fluid_.set_body_force({body_force, 0, 0});

    ArrayDragResult r;
    r.input_radius = input_radius;
    r.box = box_;
    r.grid_offset = grid_offset_;
    r.body_force = body_force;
    constexpr int kCheck = 100;
    double previous = 0;
    int calm = 0;
    long step = 0;
    while (step < settings_.max_steps) {
      for (int s = 0; s < kCheck; ++s, ++step) {
        coupling_->apply(fluid_, sphere_);
        fluid_.step();
        coupling_->after_liquid_step(fluid_, sphere_);
      }
      const double u = fluid_.total_momentum().x / fluid_.total_mass();
      if (!std::isfinite(u)) throw std::runtime_error("simple cubic array: velocity not finite");
      calm = std::abs(u - previous) <= settings_.tolerance * std::abs(u) ? calm + 1 : 0;
      previous = u;
      if (calm >= 3) break;
    }
    if (calm < 3)
      throw std::runtime_error("simple cubic array (a_g = " + std::to_string(input_radius) +
                               ", L = " + std::to_string(box_) + "): no steady state within " +
                               std::to_string(settings_.max_steps) + " steps");
    r.superficial_velocity = previous;
    r.ib_force = std::abs(coupling_->force()[0].x());
    r.steps = step;
    r.hydrodynamic_radius = hydrodynamic_radius_from_drag(
        body_force * cells, r.superficial_velocity, settings_.viscosity, box_);
    return r;
  }

 private:
  int box_;
  double grid_offset_;
  ArrayDragSettings settings_;
  lattice::FluidLattice<double> fluid_;
  spheres::SphereSet sphere_;
  std::unique_ptr<coupling::SphereCoupling<double>> coupling_;
};

}  // namespace

ArrayDragResult simple_cubic_array_drag(double input_radius, int box,
                                        const ArrayDragSettings& settings, double grid_offset) {
  return ArrayFlow(box, settings, grid_offset).run_to_steady(input_radius);
}

std::vector<std::pair<int, double>> CalibrationEntry::box_radii() const {
  std::vector<std::pair<int, double>> radii;
  std::vector<int> runs;
  for (const auto& c : checks) {
    auto it =
        std::find_if(radii.begin(), radii.end(), [&](const auto& r) { return r.first == c.box; });
    if (it == radii.end()) {
      radii.emplace_back(c.box, 0.0);
      runs.push_back(0);
      it = radii.end() - 1;
    }
    it->second += c.hydrodynamic_radius;
    ++runs[static_cast<std::size_t>(it - radii.begin())];
  }
  for (std::size_t k = 0; k < radii.size(); ++k) radii[k].second /= runs[k];
  return radii;
}

CalibrationEntry calibrate_input_radius(double hydrodynamic_radius, const std::vector<int>& boxes,
                                        const ArrayDragSettings& settings,
                                        void (*progress)(const ArrayDragResult&)) {
  if (boxes.empty()) throw std::invalid_argument("calibration: no box sizes given");
  CalibrationEntry e;
  e.hydrodynamic_radius = hydrodynamic_radius;
  e.viscosity = settings.viscosity;
  e.scheme = settings.scheme;
  std::vector<std::unique_ptr<ArrayFlow>> flows;
  const std::vector<double> offsets =
      settings.grid_offsets.empty() ? std::vector<double>{-1.0} : settings.grid_offsets;
  for (int L : boxes)
    for (double d : offsets) flows.push_back(std::make_unique<ArrayFlow>(L, settings, d));
  double ag = hydrodynamic_radius - 0.3;  // typical offset, refined below
  // Passes of fixed-point updates, a_g = a - (mean a - a_g) of the last
  // pass; from the third on, where the offset itself moves with a_g (control
  // forcing: its marker count and the lattice cells its kernels reach change
  // in steps), secant updates through the last two passes.
  double previous_ag = 0, previous_a = 0;
  for (int pass = 0; pass < 6; ++pass) {
    e.checks.clear();
    double mean_a = 0;
    for (auto& flow : flows) {
      e.checks.push_back(flow->run_to_steady(ag));
      if (progress) progress(e.checks.back());
      mean_a += e.checks.back().hydrodynamic_radius;
    }
    mean_a /= static_cast<double>(flows.size());
    e.input_radius = ag;
    const double miss = mean_a - hydrodynamic_radius;
    if (pass > 0 && std::abs(miss) <= 0.01) break;
    double next = ag - miss;  // the fixed point
    if (pass >= 2 && std::abs(ag - previous_ag) > 1e-6) {
      const double slope = (mean_a - previous_a) / (ag - previous_ag);
      if (slope > 0.2 && slope < 5) next = ag - miss / slope;
    }
    previous_ag = ag;
    previous_a = mean_a;
    ag = next;
  }
  return e;
}

namespace {
nlohmann::json to_json(const ArrayDragResult& r, double viscosity) {
  nlohmann::json j = {
      {"box", r.box},
      {"chi", 2.0 * r.hydrodynamic_radius / r.box},
      {"body_force", r.body_force},
      {"superficial_velocity", r.superficial_velocity},
      {"steps", r.steps},
      {"hydrodynamic_radius", r.hydrodynamic_radius},
      {"K_with_input_radius", r.drag_coefficient(r.input_radius, viscosity)},
      {"K_sangani_acrivos_at_input_radius", sangani_acrivos_drag(2.0 * r.input_radius / r.box)}};
  if (r.grid_offset >= 0) j["grid_offset"] = r.grid_offset;
  return j;
}
}  // namespace

void CalibrationTable::add(const CalibrationEntry& entry) {
  std::erase_if(entries_, [&](const CalibrationEntry& e) {
    return std::abs(e.hydrodynamic_radius - entry.hydrodynamic_radius) < 1e-6 &&
           std::abs(e.viscosity - entry.viscosity) < 1e-9 &&
           e.scheme.same_calibration(entry.scheme);
  });
  entries_.push_back(entry);
  std::sort(entries_.begin(), entries_.end(), [](const auto& a, const auto& b) {
    return a.hydrodynamic_radius != b.hydrodynamic_radius
               ? a.hydrodynamic_radius < b.hydrodynamic_radius
               : a.viscosity < b.viscosity;
  });
}

void CalibrationTable::save(const std::string& filename) const {
  nlohmann::json j;
  j["note"] = note;
  j["entries"] = nlohmann::json::array();
  for (const auto& e : entries_) {
    nlohmann::json checks = nlohmann::json::array();
    for (const auto& c : e.checks) checks.push_back(to_json(c, e.viscosity));
    nlohmann::json je = {{"hydrodynamic_radius", e.hydrodynamic_radius},
                         {"viscosity", e.viscosity},
                         {"input_radius", e.input_radius},
                         {"checks", checks}};
    write_scheme(je, e.scheme);
    j["entries"].push_back(je);
  }
  std::ofstream out(filename);
  if (!out) throw std::runtime_error("cannot write calibration table " + filename);
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error("error writing calibration table " + filename);
}

CalibrationTable CalibrationTable::load(const std::string& filename) {
  std::ifstream in(filename);
  if (!in) throw std::runtime_error("cannot read calibration table " + filename);
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), filename);
}

const CalibrationTable& CalibrationTable::shipped() {
  static const CalibrationTable table = parse(kShippedTableJson, "the shipped calibration table");
  return table;
}

CalibrationTable CalibrationTable::parse(const std::string& json_text, const std::string& origin) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("calibration table " + origin + ": " + e.what());
  }
  CalibrationTable t;
  t.note = j.value("note", "");
  for (const auto& je : j.at("entries")) {
    CalibrationEntry e;
    e.hydrodynamic_radius = je.at("hydrodynamic_radius").get<double>();
    e.viscosity = je.at("viscosity").get<double>();
    e.input_radius = je.at("input_radius").get<double>();
    e.scheme = scheme_from_entry(je, origin);
    for (const auto& jc : je.value("checks", nlohmann::json::array())) {
      ArrayDragResult r;
      r.input_radius = e.input_radius;
      r.box = jc.at("box").get<int>();
      r.body_force = jc.at("body_force").get<double>();
      r.superficial_velocity = jc.at("superficial_velocity").get<double>();
      r.steps = jc.at("steps").get<long>();
      r.hydrodynamic_radius = jc.at("hydrodynamic_radius").get<double>();
      r.grid_offset = jc.value("grid_offset", -1.0);
      e.checks.push_back(r);
    }
    t.entries_.push_back(e);
  }
  return t;
}

namespace {
// An entry for this a made with this immersed-boundary scheme.
bool same_scheme(const CalibrationEntry& e, double hydrodynamic_radius,
                 const coupling::Scheme& scheme) {
  return std::abs(e.hydrodynamic_radius - hydrodynamic_radius) <= 1e-6 &&
         e.scheme.same_calibration(scheme);
}
}  // namespace

bool CalibrationTable::has(double hydrodynamic_radius, const coupling::Scheme& scheme) const {
  return std::any_of(entries_.begin(), entries_.end(), [&](const CalibrationEntry& e) {
    return same_scheme(e, hydrodynamic_radius, scheme);
  });
}

const CalibrationEntry& CalibrationTable::lookup(double hydrodynamic_radius, double viscosity,
                                                 const coupling::Scheme& scheme) const {
  const CalibrationEntry* best = nullptr;
  for (const auto& e : entries_) {
    if (!same_scheme(e, hydrodynamic_radius, scheme)) continue;
    if (!best || std::abs(std::log(e.viscosity / viscosity)) <
                     std::abs(std::log(best->viscosity / viscosity)))
      best = &e;
  }
  if (!best) {
    std::ostringstream msg;
    msg << "no hydrodynamic-radius calibration for a = " << hydrodynamic_radius << " dx with "
        << scheme.describe() << "; calibrated:";
    std::vector<std::string> seen;
    for (const auto& e : entries_) {
      std::ostringstream one;
      one << " a = " << e.hydrodynamic_radius << " (" << e.scheme.describe() << ")";
      if (std::find(seen.begin(), seen.end(), one.str()) == seen.end()) seen.push_back(one.str());
    }
    for (const auto& one : seen) msg << one;
    msg << ". Run `flocsim calibrate`.";
    throw std::out_of_range(msg.str());
  }
  return *best;
}

double CalibrationTable::input_radius(double hydrodynamic_radius, double viscosity,
                                      const coupling::Scheme& scheme) const {
  const CalibrationEntry& nearest = lookup(hydrodynamic_radius, viscosity, scheme);
  const CalibrationEntry *below = nullptr, *above = nullptr;
  for (const auto& e : entries_) {
    if (!same_scheme(e, hydrodynamic_radius, scheme)) continue;
    if (e.viscosity <= viscosity && (!below || e.viscosity > below->viscosity)) below = &e;
    if (e.viscosity >= viscosity && (!above || e.viscosity < above->viscosity)) above = &e;
  }
  if (!below || !above || below->viscosity == above->viscosity) return nearest.input_radius;
  const double s =
      std::log(viscosity / below->viscosity) / std::log(above->viscosity / below->viscosity);
  return below->input_radius + s * (above->input_radius - below->input_radius);
}

}  // namespace flocsim::calibration
