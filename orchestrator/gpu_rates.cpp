#include "orchestrator/gpu_rates.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "engine/immersed_boundary/sphere_markers.hpp"
#include "engine/input/input_reader.hpp"
#include "engine/partially_saturated/covered_cell_body.hpp"

namespace flocsim::orchestrator {

using nlohmann::json;

namespace {

// A positive finite number at results[i].key, else an error naming the file
// and the field.
double positive(const json& r, const char* key, const std::string& where) {
  const auto it = r.find(key);
  if (it == r.end() || !it->is_number())
    throw input::InputError(where + "." + key + ": missing or not a number");
  const double v = it->get<double>();
  if (!std::isfinite(v) || v <= 0)
    throw input::InputError(where + "." + key + " = " + input::shown(*it) +
                            ": must be a positive finite number");
  return v;
}

bool precision_of(const json& r, const std::string& where) {
  const auto it = r.find("precision");
  if (it == r.end() || !it->is_string() || (*it != "float" && *it != "double"))
    throw input::InputError(where + ".precision: must be \"float\" or \"double\"");
  return *it == "float";
}

}  // namespace

GpuRates read_gpu_rates(const std::vector<std::string>& files) {
  GpuRates rates;
  for (const std::string& file : files) {
    const json doc = input::read_json_file(file);
    if (!doc.is_object() || !doc.contains("gpu") || !doc["gpu"].is_string() ||
        !doc.contains("results") || !doc["results"].is_array())
      throw input::InputError(file +
                              ": not a GPU benchmark's output (want an object with \"gpu\" and "
                              "\"results\", as bench_fluid_gpu --json and bench_coupling_gpu "
                              "--json write)");
    const std::string gpu = doc["gpu"];
    if (!rates.gpu.empty() && gpu != rates.gpu)
      throw input::InputError(file + ": measured on " + gpu + ", the other file(s) on " +
                              rates.gpu + ": give files of one GPU");
    rates.gpu = gpu;
    rates.file += (rates.file.empty() ? "" : ", ") + file;
    for (std::size_t i = 0; i < doc["results"].size(); ++i) {
      const json& r = doc["results"][i];
      const std::string where = file + ": results[" + std::to_string(i) + "]";
      if (!r.is_object()) throw input::InputError(where + ": not an object");
      if (r.contains("MLUPS")) {  // bench_fluid_gpu
        GpuFluidRate f;
        f.single_precision = precision_of(r, where);
        f.force_field = r.value("force_field", false);
        f.mlups = positive(r, "MLUPS", where);
        rates.fluid.push_back(f);
      } else if (r.contains("coupling_ms")) {  // bench_coupling_gpu
        GpuCouplingRate c;
        c.single_precision = precision_of(r, where);
        if (!r.contains("option") || !r["option"].is_string())
          throw input::InputError(where + ".option: missing or not a string");
        c.option = r["option"];
        c.fluid_mlups = positive(r, "fluid_MLUPS", where);
        c.coupling_ms = positive(r, "coupling_ms", where);
        const char* per_sphere =
            r.contains("markers_per_sphere") ? "markers_per_sphere" : "cube_cells_per_sphere";
        c.work = positive(r, "spheres", where) * positive(r, per_sphere, where);
        rates.coupling.push_back(c);
      } else {
        throw input::InputError(
            where + ": neither a fluid result (MLUPS) nor a coupled-step result (coupling_ms)");
      }
    }
  }
  return rates;
}

std::optional<double> GpuRates::step_s(const cases::ParsedCase& c, const run::CaseSize& size,
                                       std::string& why) const {
  const char* precision = size.single_precision ? "float" : "double";
  if (c.fluid_scene) {
    for (const GpuFluidRate& f : fluid)
      if (f.single_precision == size.single_precision && !f.force_field)
        return static_cast<double>(size.cells) / (f.mlups * 1e6);
    why =
        std::string("no fluid benchmark in ") + precision + " with a uniform body force in " + file;
    return std::nullopt;
  }
  if (size.cells == 0) {
    why = "a scene without a liquid runs on the CPU only";
    return std::nullopt;
  }
  const coupling::Scheme& scheme = c.spheres.numerics.coupling;
  const double a_g = c.spheres.numerics.input_radius;
  double per_sphere = 0;
  if (scheme.immersed_boundary()) {
    per_sphere = immersed_boundary::marker_count(a_g, scheme.marker_spacing);
  } else {
    const double edge = partially_saturated::covering_box_edge(a_g);
    per_sphere = edge * edge * edge;
  }
  const std::string option = scheme.describe();
  for (const GpuCouplingRate& r : coupling)
    if (r.single_precision == size.single_precision && r.option == option)
      return static_cast<double>(size.cells) / (r.fluid_mlups * 1e6) +
             r.coupling_ms * 1e-3 * static_cast<double>(size.spheres) * per_sphere / r.work;
  why = std::string("no coupled-step benchmark of ") + option + " in " + precision + " in " + file;
  return std::nullopt;
}

}  // namespace flocsim::orchestrator
