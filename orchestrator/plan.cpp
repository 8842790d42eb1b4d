#include "orchestrator/plan.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "db/results_db.hpp"
#include "engine/case/case_support.hpp"
#include "engine/input/input_reader.hpp"
#include "orchestrator/report.hpp"
#include "orchestrator/terminal_table.hpp"

namespace flocsim::orchestrator {

namespace {

using nlohmann::json;

std::string bytes_text(double b) {
  char buf[32];
  if (b >= 1e9)
    std::snprintf(buf, sizeof buf, "%.1f GB", b / 1e9);
  else if (b >= 1e6)
    std::snprintf(buf, sizeof buf, "%.0f MB", b / 1e6);
  else
    std::snprintf(buf, sizeof buf, "%.0f kB", b / 1e3);
  return buf;
}

// "2.1e8" for large counts (C's %g writes "2.1e+08"), plain below a million.
std::string number_text(double v) {
  char buf[32];
  if (v < 1e6) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  int exponent = static_cast<int>(std::floor(std::log10(v)));
  double mantissa = std::round(v / std::pow(10.0, exponent) * 10) / 10;
  if (mantissa >= 10) mantissa /= 10, ++exponent;
  std::snprintf(buf, sizeof buf, "%.1fe%d", mantissa, exponent);
  return buf;
}

// "a-b", or "a" when both ends agree to the shown digits; a unit both share
// is written once ("15-20 s").
std::string range_text(const std::string& low, const std::string& high) {
  if (low == high) return low;
  const auto space = low.find(' ');
  if (space != std::string::npos && high.size() > space &&
      low.substr(space) ==
          high.substr(high.find(' ') == std::string::npos ? high.size() : high.find(' ')))
    return low.substr(0, space) + "-" + high;
  return low + "-" + high;
}

// A time per step: "4.73 ms", "652 ms", "2.16 s".
std::string step_time_text(double seconds) {
  char buf[32];
  if (seconds < 1)
    std::snprintf(buf, sizeof buf, "%.3g ms", 1e3 * seconds);
  else
    std::snprintf(buf, sizeof buf, "%.3g s", seconds);
  return buf;
}

// Hours as counted: "0.0232", "12.5", "16100".
std::string hours_text(double h) {
  char buf[32];
  if (h >= 1000)
    std::snprintf(buf, sizeof buf, "%.0f", std::round(h / 100) * 100);
  else
    std::snprintf(buf, sizeof buf, "%.3g", h);
  return buf;
}

std::string describe(const run::CaseSize& z, const json& key) {
  std::string d = z.scene;
  if (z.cells > 0)
    d += ", " + std::to_string(z.box.nx) + " x " + std::to_string(z.box.ny) + " x " +
         std::to_string(z.box.nz) + " cells";
  if (z.spheres > 0) d += ", " + std::to_string(z.spheres) + " spheres";
  d += z.single_precision ? ", float" : ", double";
  const auto ib = get_path(key, "numerics.immersed_boundary");
  const auto coupling = get_path(key, "numerics.coupling");
  auto text = [](const std::optional<json>& v) { return v.value_or(json()).dump(); };
  if (ib && ib->is_object()) {
    d += ", IB markers " + text(get_path(*ib, "marker_spacing")) + " dx, ";
    if (get_path(*ib, "forcing").value_or(json()) == "control")
      d += "control forcing";
    else
      d += text(get_path(*ib, "sweeps")) + " sweep(s)";
  } else if (coupling && coupling->is_string()) {
    d += ", " + coupling->get<std::string>();
  }
  return d;
}

// The median of the completed runs' wall seconds per step whose configuration
// is `key`, with their threads.
void from_database(db::ResultsDb& db, StepCost& cost) {
  std::vector<double> per_step;
  std::vector<int> threads;
  const std::string wanted = canonical_text(cost.key);
  for (const db::ResultsDb::ResultRow& r : db.result_rows()) {
    if (!r.has_result || !r.wall_s || !r.steps || *r.steps <= 0) continue;
    try {
      const run::CaseSize z = run::case_size(cases::parse_case(json::parse(r.run.case_json)));
      if (canonical_text(z.cost_key) != wanted) continue;
    } catch (const std::exception&) {
      continue;  // a case this version no longer reads: not comparable
    }
    per_step.push_back(*r.wall_s / static_cast<double>(*r.steps));
    const json res = json::parse(r.result_json, nullptr, false);
    threads.push_back(res.is_object() ? res.value("cost", json::object()).value("threads", 0) : 0);
  }
  if (per_step.empty()) return;
  std::vector<std::size_t> order(per_step.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return per_step[a] < per_step[b]; });
  const std::size_t mid = order[order.size() / 2];
  cost.db_runs = static_cast<int>(per_step.size());
  cost.db_step_s = per_step[mid];
  cost.db_threads = threads[mid];
}

// End of the last of `durations` run in order on `lanes` lanes, each next one
// on the lane that frees first (what the worker pool does).
double schedule(const std::vector<double>& durations, int lanes) {
  std::vector<double> free_at(static_cast<std::size_t>(std::max(1, lanes)), 0.0);
  for (double d : durations) *std::min_element(free_at.begin(), free_at.end()) += d;
  return *std::max_element(free_at.begin(), free_at.end());
}

}  // namespace

std::optional<double> StepCost::step_s() const {
  if (gpu_step_s) return gpu_step_s;
  if (db_runs > 0) return db_step_s;
  if (measured_together && measured_together->steps > 0) return measured_together->step_s;
  if (measured && measured->steps > 0) return measured->step_s;
  return std::nullopt;
}

int StepCost::threads() const {
  if (gpu_step_s) return 1;  // one GPU, its worker's one host thread
  if (db_runs > 0 && db_threads > 0) return db_threads;
  return measured ? measured->threads : 0;
}

std::string StepCost::basis() const {
  if (gpu_step_s)
    return "on the GPU " + gpu_name + ": " + step_time_text(*gpu_step_s) +
           " per step from its benchmark figures (--gpu-rate; setup not included)";
  std::string out;
  if (measured && measured->steps > 0)
    out = "measured here: " + step_time_text(measured->step_s) + " per step alone (" +
          std::to_string(measured->steps) + " steps after a warm-up one), " +
          std::to_string(measured->threads) + " thread" + (measured->threads == 1 ? "" : "s") +
          ", setup " + step_time_text(measured->setup_s);
  if (measured_together && measured_together->steps > 0)
    out += "; " + step_time_text(measured_together->step_s) + " per step each with " +
           std::to_string(copies_together) + " at once, as the workers will run";
  if (db_runs > 0)
    out += (out.empty() ? "" : "; used: ") + std::to_string(db_runs) + " completed run" +
           (db_runs == 1 ? "" : "s") + " in the database: " + step_time_text(db_step_s) +
           " per step (median, wall time over steps" +
           (db_threads > 0 ? ", " + std::to_string(db_threads) + " threads" : "") + ")";
  if (!gpu_why.empty()) out += (out.empty() ? "" : "; ") + ("not on the GPU: " + gpu_why);
  return out.empty() ? "no rate: not measured (--measure-steps 0) and no completed run of it "
                       "in a database"
                     : out;
}

std::optional<double> slurm_time_limit_s(const std::string& limit) {
  long days = 0;
  std::string rest = limit;
  const auto dash = limit.find('-');
  std::vector<long> parts;
  auto parse_parts = [&parts](const std::string& s) {
    std::size_t start = 0;
    while (true) {
      const auto colon = s.find(':', start);
      const std::string p =
          s.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
      // at most 9 digits: twenty overflowed std::stol ("error: stol")
      if (p.empty() || p.size() > 9 || p.find_first_not_of("0123456789") != std::string::npos)
        return false;
      parts.push_back(std::stol(p));
      if (colon == std::string::npos) return true;
      start = colon + 1;
    }
  };
  if (dash != std::string::npos) {
    const std::string d = limit.substr(0, dash);
    if (d.empty() || d.size() > 9 || d.find_first_not_of("0123456789") != std::string::npos)
      return std::nullopt;
    days = std::stol(d);
    rest = limit.substr(dash + 1);
    if (!parse_parts(rest) || parts.size() > 3) return std::nullopt;
    // days-hours[:minutes[:seconds]]
    const double h = parts[0], m = parts.size() > 1 ? parts[1] : 0,
                 s = parts.size() > 2 ? parts[2] : 0;
    return days * 86400.0 + h * 3600 + m * 60 + s;
  }
  if (!parse_parts(rest) || parts.size() > 3) return std::nullopt;
  if (parts.size() == 1) return parts[0] * 60.0;             // minutes
  if (parts.size() == 2) return parts[0] * 60.0 + parts[1];  // minutes:seconds
  return parts[0] * 3600.0 + parts[1] * 60.0 + parts[2];     // hours:minutes:seconds
}

SweepPlan plan_sweep(const SweepSpec& spec, const PlanOptions& o) {
  if (o.jobs < 1)
    throw input::InputError("--jobs " + std::to_string(o.jobs) + ": must be at least 1");
  SweepPlan plan;
  plan.sweep = spec.name;
  plan.backend = o.backend;
  plan.jobs = o.jobs;
  plan.cores = static_cast<int>(std::max(1L, sysconf(_SC_NPROCESSORS_ONLN)));
  std::map<std::string, int> cost_of_key;
  std::vector<cases::ParsedCase> first_case;  // per cost: the case it is measured with
  for (RunPoint& p : expand(spec)) {
    PlannedRun r;
    r.point = std::move(p);
    if (o.db) {
      const auto known = o.db->find_run(r.point.id);
      r.complete = known && known->status == db::RunState::kCompleted;
    }
    try {
      const cases::ParsedCase parsed = cases::parse_case(r.point.case_json);
      r.size = run::case_size(parsed);
      const std::string key = canonical_text(r.size.cost_key);
      auto it = cost_of_key.find(key);
      if (it == cost_of_key.end()) {
        StepCost c;
        c.key = r.size.cost_key;
        c.description = describe(r.size, r.size.cost_key);
        plan.costs.push_back(c);
        first_case.push_back(parsed);
        it = cost_of_key.emplace(key, static_cast<int>(plan.costs.size()) - 1).first;
      }
      r.cost = it->second;
      if (o.gpu) {
        std::string why;
        r.gpu_step_s = o.gpu->step_s(parsed, r.size, why);
      }
      if (!r.complete) {
        ++plan.costs[r.cost].runs;
        ++plan.to_run;
        plan.lattice_updates_min += static_cast<double>(r.size.cells) * r.size.steps_min;
        plan.lattice_updates_max += static_cast<double>(r.size.cells) * r.size.steps_max;
      }
    } catch (const input::InputError& e) {
      r.refused = e.what();
      ++plan.refused;
    }
    if (r.complete) ++plan.complete;
    plan.runs.push_back(std::move(r));
  }

  for (std::size_t i = 0; i < plan.costs.size(); ++i) {
    StepCost& c = plan.costs[i];
    if (c.runs == 0) continue;
    if (o.gpu) {
      c.gpu_name = o.gpu->gpu;
      c.gpu_step_s = o.gpu->step_s(first_case[i], run::case_size(first_case[i]), c.gpu_why);
      if (c.gpu_step_s) continue;  // nothing to measure here
    }
    if (o.db) from_database(*o.db, c);
    if (o.measure_steps > 0) {
      if (o.progress)
        *o.progress << "measuring configuration " << i + 1 << " of " << plan.costs.size() << " ("
                    << printable(c.description) << ")\n"
                    << std::flush;
      c.measured = run::measure_steps(first_case[i], o.measure_steps, o.measure_seconds);
      plan.memory_per_run_max = std::max(plan.memory_per_run_max, c.measured->memory_bytes);
      // the workers share this machine: their rate is measured with as many at
      // once, where that many copies fit in memory (the one just measured says
      // how much one takes): --jobs 4096 built 4096 copies to time them, 29 GB
      // on a 23 GB machine, and died of bad_alloc. Where they do not fit, the
      // one copy's rate is scaled by the sharing of the cores, and the plan
      // says the runs at once need more memory than there is (below).
      const int together = std::min(o.jobs, plan.to_run);
      double room = cases::physical_memory_bytes();
      struct rlimit limit {};
      if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
          (room <= 0 || static_cast<double>(limit.rlim_cur) < room))
        room = static_cast<double>(limit.rlim_cur);
      const bool fit = room <= 0 || c.measured->memory_bytes <= 0 ||
                       (together + 1) * c.measured->memory_bytes <= 0.8 * room;
      if (o.backend == "local" && together > 1 && fit) {
        c.measured_together =
            run::measure_steps(first_case[i], o.measure_steps, o.measure_seconds, together);
        c.copies_together = together;
      }
    }
  }

  // Runs that share the cores run slower: jobs x threads against the cores.
  const int lanes = std::max(1, std::min(o.jobs, plan.to_run));
  std::vector<double> fastest, slowest;
  double core_s_min = 0, core_s_max = 0;
  bool every_rate = true;
  for (PlannedRun& r : plan.runs) {
    if (r.cost < 0 || r.complete || !r.refused.empty()) continue;
    const StepCost& c = plan.costs[r.cost];
    const auto step_s = r.gpu_step_s ? r.gpu_step_s : c.step_s();
    if (!step_s) {
      every_rate = false;
      continue;
    }
    const int threads = std::max(1, c.threads());
    // A rate measured with the workers running at once holds their sharing of
    // the cores; any other, where they outnumber the cores, is scaled by it.
    const bool shared_in_rate = c.db_runs == 0 && c.measured_together;
    const double slowdown = o.backend == "local" && !shared_in_rate && !c.gpu_step_s
                                ? std::max(1.0, static_cast<double>(lanes) * threads / plan.cores)
                                : 1.0;
    plan.slowdown = std::max(plan.slowdown, slowdown);
    // a database's wall time per step already holds the setup and output
    const double setup = c.db_runs > 0 || c.gpu_step_s ? 0.0 : c.measured->setup_s;
    const double alone_min = setup + *step_s * static_cast<double>(r.size.steps_min);
    const double alone_max = setup + *step_s * static_cast<double>(r.size.steps_max);
    r.wall_min_s = alone_min * slowdown;
    r.wall_max_s = alone_max * slowdown;
    fastest.push_back(*r.wall_min_s);
    slowest.push_back(*r.wall_max_s);
    if (c.gpu_step_s) {
      plan.gpu_hours_min += alone_min / 3600;
      plan.gpu_hours_max += alone_max / 3600;
    } else {
      core_s_min += alone_min * threads;
      core_s_max += alone_max * threads;
    }
  }
  if (every_rate && plan.to_run > 0) {
    plan.core_hours_min = core_s_min / 3600;
    plan.core_hours_max = core_s_max / 3600;
    if (o.backend == "local") {
      plan.wall_min_s = schedule(fastest, lanes);
      plan.wall_max_s = schedule(slowest, lanes);
    } else {
      // Slurm: tasks of runs_per_task runs one after another, max_parallel at once
      const int per_task = std::max(1, spec.slurm.runs_per_task);
      std::vector<double> task_min, task_max;
      for (std::size_t i = 0; i < fastest.size(); i += per_task) {
        double a = 0, b = 0;
        for (std::size_t k = i; k < std::min(fastest.size(), i + per_task); ++k)
          a += fastest[k], b += slowest[k];
        task_min.push_back(a);
        task_max.push_back(b);
      }
      const int parallel =
          spec.slurm.max_parallel > 0 ? spec.slurm.max_parallel : static_cast<int>(task_min.size());
      plan.wall_min_s = schedule(task_min, parallel);
      plan.wall_max_s = schedule(task_max, parallel);
      const auto limit = slurm_time_limit_s(spec.slurm.time_limit);
      const double longest_task =
          task_max.empty() ? 0 : *std::max_element(task_max.begin(), task_max.end());
      if (limit && longest_task > *limit)
        plan.notes.push_back(
            "the longest Slurm task (" + std::to_string(per_task) + " run(s)) may take " +
            duration_text(longest_task) +
            " on nodes as fast as this machine, beyond slurm.time_limit = " +
            spec.slurm.time_limit +
            ": a task cut off at its limit is lost and resumed from its checkpoint; "
            "raise the limit or lower runs_per_task");
    }
  }
  if (o.gpu && std::any_of(plan.runs.begin(), plan.runs.end(),
                           [](const PlannedRun& r) { return r.gpu_step_s && r.size.spheres > 0; }))
    plan.notes.push_back(
        "sphere scenes' GPU figures project the benchmark's coupled step (the coupling and the "
        "lattice on the GPU) onto each configuration; the sphere side (on the CPU while the GPU "
        "steps, about 1 ms a step at N = 1320 on 2 cores; docs/gpu.md) is not in them");
  const double memory = cases::physical_memory_bytes();
  if (o.backend == "local" && memory > 0 && lanes * plan.memory_per_run_max > 0.8 * memory)
    plan.notes.push_back(std::to_string(lanes) + " runs at once need about " +
                         bytes_text(lanes * plan.memory_per_run_max) +
                         ", more than 80 % of this machine's " + bytes_text(memory) +
                         ": lower --jobs");
  return plan;
}

void write_plan(const SweepPlan& p, std::ostream& out, bool every_run) {
  out << "plan of sweep " << printable(p.sweep) << ": " << p.runs.size() << " points, " << p.to_run
      << " to run";
  if (p.complete > 0) out << ", " << p.complete << " already complete in the database";
  out << ", " << p.refused << " refused\n";

  if (every_run && p.refused < static_cast<int>(p.runs.size())) {
    std::vector<std::vector<std::string>> rows{
        {"point", "box (cells)", "N", "steps", "lattice updates", "memory", "wall time (est.)"}};
    for (const PlannedRun& r : p.runs) {
      if (!r.refused.empty()) continue;
      const run::CaseSize& z = r.size;
      const StepCost* c = r.cost >= 0 ? &p.costs[r.cost] : nullptr;
      std::string wall = r.complete ? "complete" : "?";
      if (!r.complete && r.wall_min_s)
        wall = range_text(duration_text(*r.wall_min_s), duration_text(*r.wall_max_s));
      rows.push_back({point_text(r.point.point.dump()),
                      z.cells > 0 ? std::to_string(z.box.nx) + "x" + std::to_string(z.box.ny) +
                                        "x" + std::to_string(z.box.nz)
                                  : "-",
                      z.spheres > 0 ? std::to_string(z.spheres) : "-",
                      range_text(std::to_string(z.steps_min), std::to_string(z.steps_max)),
                      range_text(number_text(static_cast<double>(z.cells) * z.steps_min),
                                 number_text(static_cast<double>(z.cells) * z.steps_max)),
                      c && c->measured ? bytes_text(c->measured->memory_bytes) : "?", wall});
    }
    std::vector<std::size_t> w(rows.front().size(), 0);
    for (const auto& row : rows)
      for (std::size_t i = 0; i < row.size(); ++i) w[i] = std::max(w[i], row[i].size());
    for (const auto& row : rows) {
      std::string line = "  ";
      for (std::size_t i = 0; i < row.size(); ++i)
        line += row[i] + (i + 1 < row.size() ? std::string(w[i] - row[i].size() + 2, ' ') : "");
      out << line << "\n";
    }
  }

  if (p.refused > 0) {
    out << "refused (" << p.refused << "), as `flocsim run` refuses them, with what would work:\n";
    // one line per distinct message, with its points; on one screen at most 6 messages
    std::vector<std::pair<std::string, std::vector<std::string>>> by_message;
    for (const PlannedRun& r : p.runs) {
      if (r.refused.empty()) continue;
      auto it = std::find_if(by_message.begin(), by_message.end(),
                             [&](const auto& m) { return m.first == r.refused; });
      if (it == by_message.end()) {
        by_message.push_back({r.refused, {}});
        it = by_message.end() - 1;
      }
      it->second.push_back(point_text(r.point.point.dump()));
    }
    const std::size_t shown =
        every_run ? by_message.size() : std::min<std::size_t>(6, by_message.size());
    for (std::size_t i = 0; i < shown; ++i) {
      const auto& [message, points] = by_message[i];
      out << "  " << points.front();
      if (points.size() > 1) out << " and " << points.size() - 1 << " more";
      out << ": " << printable(message) << "\n";
      if (every_run)
        for (std::size_t k = 1; k < points.size(); ++k) out << "    also " << points[k] << "\n";
    }
    if (shown < by_message.size())
      out << "  ... " << by_message.size() - shown
          << " more reasons; `flocsim sweep plan` lists every refused point\n";
  }

  out << "configurations (each timed once; runs of one configuration share its rate):\n";
  int index = 0;
  for (const StepCost& c : p.costs) {
    ++index;
    if (c.runs == 0) continue;
    out << "  " << index << ". " << printable(c.description) << ": " << c.runs << " run"
        << (c.runs == 1 ? "" : "s");
    if (c.measured) out << ", " << bytes_text(c.measured->memory_bytes) << " of memory each";
    out << "\n     " << printable(c.basis()) << "\n";
  }

  if (p.to_run == 0) {
    out << "nothing to run\n";
  } else {
    out << "total: "
        << range_text(number_text(p.lattice_updates_min), number_text(p.lattice_updates_max))
        << " lattice updates";
    if (p.core_hours_min && (*p.core_hours_max > 0 || p.gpu_hours_max == 0))
      out << ", " << range_text(hours_text(*p.core_hours_min), hours_text(*p.core_hours_max))
          << " core-hours (wall time x threads)";
    if (p.gpu_hours_max > 0)
      out << ", " << range_text(hours_text(p.gpu_hours_min), hours_text(p.gpu_hours_max))
          << " GPU-hours";
    out << "\n";
    if (p.wall_min_s) {
      out << "estimated wall time: "
          << range_text(duration_text(*p.wall_min_s), duration_text(*p.wall_max_s));
      if (p.gpu_hours_max > 0) {
        out << " at --jobs " << p.jobs << ", each worker on a GPU as fast as the benchmark's\n";
      } else if (p.backend == "local") {
        out << " at --jobs " << p.jobs << " on this machine (" << p.cores << " cores";
        if (p.slowdown > 1) {
          char buf[96];
          std::snprintf(buf, sizeof buf, "; runs sharing cores taken %.2gx slower", p.slowdown);
          out << buf;
        }
        out << ")\n";
      } else {
        out << " on Slurm nodes as fast as this machine (tasks as the sweep's \"slurm\" sets "
               "them)\n";
      }
      out << "  (the range: stage 1 ends when stationary, between its minimum and maximum; "
             "a run's time is its setup plus steps x the rate above)\n";
    } else {
      out << "estimated wall time: unknown (no rate for every configuration: measure with "
             "--measure-steps N, or give --db with completed runs)\n";
    }
  }
  for (const std::string& n : p.notes) out << "note: " << printable(n) << "\n";
}

}  // namespace flocsim::orchestrator
