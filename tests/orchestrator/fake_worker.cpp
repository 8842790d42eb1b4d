// A stand-in for `flocsim run` that honours the worker contract exactly and
// whose behaviour the case chooses, so the orchestrator's fault handling can
// be tested in seconds:
//   fake_worker run CASE.json --out DIR [--resume] [--quiet] [--device D]
// Case fields read: "x" (number, default 0) and "fake": {
//   "steps": 10, "step_ms": 50,      work: steps of step_ms each
//   "exit": 0,                       exit code at the end (0 writes result.json)
//   "truncate": false,               write a cut-off result.json, then exit 0
//   "refuse": false,                 exit 2 at once, as bad input
//   "busy": false,                   exit 4 at once, as when another worker holds DIR
//   "crash_at": -1,                  abort() at this step
//   "hang_at": -1,                   stop heart-beating (but keep living) at this step
//   "by_x": {"2": {...}} }           overrides of these fields for the run with x = 2
// Each step rewrites progress.json and checkpoint.h5 (the step number), both
// atomically. SIGTERM/SIGINT: checkpoint, exit 3. --resume: continue from the
// checkpoint. Every start appends "start STEP" to DIR/starts.log, and
// "device D gpu G" to DIR/devices.log (D the --device given, G the
// CUDA_VISIBLE_DEVICES it got; "-" for none).
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

void write_atomic(const std::string& file, const std::string& text) {
  const std::string tmp = file + ".tmp";
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) std::exit(1);
  if (write(fd, text.data(), text.size()) != static_cast<ssize_t>(text.size())) std::exit(1);
  fsync(fd);
  close(fd);
  if (rename(tmp.c_str(), file.c_str()) != 0) std::exit(1);
}

double now_s() {
  using namespace std::chrono;
  return duration<double>(system_clock::now().time_since_epoch()).count();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5 || std::string(argv[1]) != "run" || std::string(argv[3]) != "--out") {
    std::cerr << "usage: fake_worker run CASE.json --out DIR [--resume] [--quiet]\n";
    return 2;
  }
  const std::string case_file = argv[2], dir = argv[4];
  bool resume = false;
  std::string device = "-";
  for (int i = 5; i < argc; ++i) {
    resume = resume || std::string(argv[i]) == "--resume";
    if (std::string(argv[i]) == "--device" && i + 1 < argc) device = argv[++i];
  }
  const char* gpu = std::getenv("CUDA_VISIBLE_DEVICES");
  std::ofstream(dir + "/devices.log", std::ios::app)
      << "device " << device << " gpu " << (gpu ? gpu : "-") << "\n";
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);

  std::ifstream cf(case_file);
  const nlohmann::json c = nlohmann::json::parse(cf);
  nlohmann::json fake = c.value("fake", nlohmann::json::object());
  // "by_x": {"2": {"exit": 1}}: overrides for the run whose x is 2
  if (fake.contains("by_x")) {
    char key[32];
    std::snprintf(key, sizeof key, "%g", c.value("x", 0.0));
    if (fake["by_x"].contains(key)) fake.update(fake["by_x"][key]);
  }
  const long steps = fake.value("steps", 10L);
  const long step_ms = fake.value("step_ms", 50L);
  const int exit_code = fake.value("exit", 0);
  const long crash_at = fake.value("crash_at", -1L);
  const long hang_at = fake.value("hang_at", -1L);
  const double x = c.value("x", 0.0);
  if (fake.value("refuse", false)) {
    std::cerr << "case: fake.refuse = true: refused (allowed: false)\n";
    return 2;
  }
  if (fake.value("busy", false)) {
    std::cerr << "--out " << dir
              << ": another flocsim (process 1) is writing to this directory now\n";
    return 4;
  }

  long step = 0;
  if (resume) {
    std::ifstream ck(dir + "/checkpoint.h5");
    if (ck) ck >> step;
  }
  const long first = step;
  std::ofstream(dir + "/starts.log", std::ios::app) << "start " << step << "\n";
  std::ofstream log(dir + "/run.log", std::ios::app);
  log << "fake worker pid " << getpid() << " starting at step " << step << "\n" << std::flush;
  const double t0 = now_s();
  bool beating = true;
  while (step < steps) {
    if (g_stop) {
      write_atomic(dir + "/checkpoint.h5", std::to_string(step) + "\n");
      log << "stopped by a signal at step " << step << " after writing a checkpoint\n";
      return 3;
    }
    if (step == crash_at) {
      std::cerr << "fake worker: crashing at step " << step << "\n";
      std::abort();
    }
    if (step == hang_at) beating = false;
    std::this_thread::sleep_for(std::chrono::milliseconds(step_ms));
    ++step;
    if (beating) {
      write_atomic(dir + "/checkpoint.h5", std::to_string(step) + "\n");
      const double frac = static_cast<double>(step) / static_cast<double>(steps);
      nlohmann::json p{{"step", step},
                       {"steps_total", steps},
                       {"fraction", frac},
                       {"eta_s", 0.001 * static_cast<double>((steps - step) * step_ms)},
                       {"mlups", 1.5},
                       {"updated_at", now_s()},
                       {"pid", getpid()},
                       // where the run stands in its own terms, as flocsim's sphere scenes write it
                       {"stage", 2 * step < steps ? "stage 1" : "statistics"},
                       {"time", 0.5 * static_cast<double>(step)},
                       {"time_total", 0.5 * static_cast<double>(steps)},
                       {"time_unit", "a/U_inf"}};
      write_atomic(dir + "/progress.json", p.dump());
    } else {
      --step;  // hung: no progress at all
    }
  }
  if (exit_code != 0) {
    std::cerr << "fake worker: numerical blow-up at step " << step << " (exit " << exit_code
              << ")\n";
    return exit_code;
  }
  nlohmann::json r{{"status", "completed"},
                   {"flocsim_version", "fake"},
                   {"case", c},
                   {"observables",
                    {{"twice_x", {{"mean", 2 * x}, {"error", 0.5}}},
                     {"first_step", first},
                     {"window", {0.5, 1.0}}}},
                   {"cost", {{"wall_s", now_s() - t0}, {"MLUPS", 1.5}, {"steps", steps}}},
                   {"completed_at", "2024-01-01T00:00:00Z"}};
  std::string text = r.dump(2);
  if (fake.value("truncate", false)) text = text.substr(0, text.size() / 2);
  write_atomic(dir + "/result.json", text);
  return 0;
}
