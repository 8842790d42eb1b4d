// A bonded pair sheared and rolled (docs/validation/bonded-pair.md): the
// lattice's own resistance of two held spheres to the
// tangential relative motions an aggregate's bonds make, per coupling scheme,
// beside the exact creeping-flow values near contact. The close-pair
// correction acts along the line of centres only, so this resistance is the
// lattice's alone in every run.
//
//   bench_pair_tangential [--radius A] [--viscosity NU] [--box L_OVER_A]
//                         [--options OPTION,...] [--motions slide,roll]
//                         [--gaps S,...] [--json FILE]
//
// Options as bench_coupling (direct:KERNEL:SPACING:SWEEPS,
// control:KERNEL:SPACING[:G:P], psm), each with the input radius the shipped
// calibration gives at a and nu. Per option and motion, the pair is held at
// each gap s/a (increasing; each gap starts from the steady flow of the one
// before) in a box L x L/2 x L/2 (L = L_OVER_A a, default 16), at a surface
// speed V with 2 a V / nu = 0.01, double precision, until steady to 2e-6 per
// 200 steps (engine/calibration/pair_resistance.hpp, measure_pair_tangential).
// Printed per gap: the force on sphere 0 along y and its torque about z, in
// units of 6 pi rho nu a V and 8 pi rho nu a^2 V (signed: an isolated sphere
// reads -1 for the force when sliding and -1 for the torque when rolling),
// beside the same for the exact pair in unbounded liquid (Jeffrey & Onishi's
// series, engine/lubrication/two_sphere_tangential.hpp). The measured values
// include what the box's periodic images and the scheme's own radius for
// rotation add; the study's tables remove it as the
// measured-minus-exact at the largest gap (scripts/pair-tangential-table.py).
#include <omp.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/coupling_options.hpp"
#include "engine/calibration/pair_resistance.hpp"
#include "engine/lubrication/two_sphere_tangential.hpp"

using namespace flocsim;

namespace {

int refuse(const std::string& what) {
  std::fprintf(stderr, "bench_pair_tangential: %s\n", what.c_str());
  return 2;
}

// The exact pair's force_y and torque_z in the measurement's signed units.
struct Exact {
  double force_y, torque_z;
};
Exact exact_pair(calibration::TangentialMotion motion, double gap_over_a) {
  if (motion == calibration::TangentialMotion::slide)
    return {-lubrication::sliding_pair_force(gap_over_a),
            lubrication::sliding_pair_torque(gap_over_a)};
  return {lubrication::rolling_pair_force(gap_over_a),
          -lubrication::rolling_pair_torque(gap_over_a)};
}

void print_point(calibration::TangentialMotion motion, const calibration::PairTangentialPoint& p) {
  const Exact e = exact_pair(motion, p.gap_over_a);
  std::printf(
      "  s/a = %6.3f  force_y = %+9.5f (exact %+8.5f)  torque_z = %+9.5f (exact %+8.5f)"
      "  steps %7ld\n",
      p.gap_over_a, p.force_y, e.force_y, p.torque_z, e.torque_z, p.steps);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  double a = 4, nu = 0.02, box = 16;
  std::string options = "direct:roma3:0.7:2,psm", motions = "slide,roll";
  std::vector<double> gaps = {0.005, 0.01, 0.02, 0.035, 0.05, 0.1, 0.2, 0.5};
  std::string json_file;
  for (int i = 1; i < argc; i += 2) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::printf(
          "bench_pair_tangential [--radius A] [--viscosity NU] [--box L_OVER_A]\n"
          "                      [--options OPTION,...] [--motions slide,roll]\n"
          "                      [--gaps S,...] [--json FILE]\n"
          "A held pair of spheres sliding and rolling, per coupling scheme, against the exact\n"
          "pair (docs/validation/bonded-pair.md). OPTION: %s.\n",
          bench::kOptionsSyntax);
      return 0;
    }
    if (i + 1 >= argc) return refuse(arg + ": needs a value");
    const std::string v = argv[i + 1];
    try {
      if (arg == "--radius")
        a = std::stod(v);
      else if (arg == "--viscosity")
        nu = std::stod(v);
      else if (arg == "--box")
        box = std::stod(v);
      else if (arg == "--options")
        options = v;
      else if (arg == "--motions")
        motions = v;
      else if (arg == "--json")
        json_file = v;
      else if (arg == "--gaps") {
        gaps.clear();
        for (const auto& g : bench::split(v, ',')) gaps.push_back(std::stod(g));
      } else
        return refuse("unknown option " + arg);
    } catch (const std::exception&) {
      return refuse(arg + " " + v + ": not a number");
    }
  }
  if (!(a >= 2 && a <= 16)) return refuse("--radius " + std::to_string(a) + ": allowed 2-16 dx");
  if (!(nu >= 0.005 && nu <= 0.5))
    return refuse("--viscosity " + std::to_string(nu) + ": allowed 0.005-0.5");
  if (!(box >= 8 && box <= 64)) return refuse("--box " + std::to_string(box) + ": allowed 8-64");
  for (std::size_t k = 0; k < gaps.size(); ++k)
    if (!(gaps[k] > 0 && gaps[k] <= 2) || (k > 0 && gaps[k] <= gaps[k - 1]))
      return refuse("--gaps: each in (0, 2], increasing");
  std::vector<coupling::Scheme> schemes;
  for (const auto& text : bench::split(options, ',')) {
    const auto s = bench::parse_option(text);
    if (!s) return refuse("--options " + text + ": allowed " + bench::kOptionsSyntax);
    schemes.push_back(*s);
  }
  std::vector<calibration::TangentialMotion> wanted;
  for (const auto& m : bench::split(motions, ',')) {
    if (m == "slide")
      wanted.push_back(calibration::TangentialMotion::slide);
    else if (m == "roll")
      wanted.push_back(calibration::TangentialMotion::roll);
    else
      return refuse("--motions " + m + ": allowed slide, roll");
  }

  if (!json_file.empty() && !std::ofstream(json_file, std::ios::app))  // before minutes of work
    return refuse("--json " + json_file + ": cannot be written");

  std::printf("bench_pair_tangential: a = %g dx, nu = %g, box %g a, %d threads\n", a, nu, box,
              omp_get_max_threads());
  nlohmann::json out = {{"radius", a}, {"viscosity", nu}, {"box_over_a", box}, {"runs", {}}};
  for (const auto& scheme : schemes) {
    calibration::PairResistanceSettings set;
    set.viscosity = nu;
    set.scheme = scheme;
    set.box_over_a = box;
    for (auto motion : wanted) {
      const bool slide = motion == calibration::TangentialMotion::slide;
      std::printf("%s, %s:\n", scheme.describe().c_str(), slide ? "slide" : "roll");
      std::vector<calibration::PairTangentialPoint> points;
      try {  // no calibration for this a and nu, a run that blew up or never settled
        points = calibration::measure_pair_tangential(
            a, gaps, motion, set, [motion](const auto& p) { print_point(motion, p); });
      } catch (const std::exception& e) {
        return refuse(e.what());
      }
      nlohmann::json run = {{"scheme", scheme.describe()},
                            {"motion", slide ? "slide" : "roll"},
                            {"points", nlohmann::json::array()}};
      for (const auto& p : points) {
        const Exact e = exact_pair(motion, p.gap_over_a);
        run["points"].push_back({{"gap_over_a", p.gap_over_a},
                                 {"force_y", p.force_y},
                                 {"torque_z", p.torque_z},
                                 {"exact_force_y", e.force_y},
                                 {"exact_torque_z", e.torque_z},
                                 {"steps", p.steps}});
      }
      out["runs"].push_back(run);
      if (!json_file.empty()) {  // after every run, so a long study keeps what it has
        std::ofstream f(json_file);
        f << out.dump(2) << "\n";
        if (!f) return refuse("cannot write " + json_file);
      }
    }
  }
  return 0;
}
