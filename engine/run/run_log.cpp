#include "engine/run/run_log.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <nlohmann/json.hpp>

#include "engine/output/atomic_file.hpp"
#include "engine/text/printable.hpp"

namespace flocsim::run {

namespace {
std::string timestamp() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", std::localtime(&t));
  return buf;
}
}  // namespace

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--:--";
  const long s = std::lround(seconds);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

RunLog::RunLog(const std::filesystem::path& file, bool quiet)
    : file_(file, std::ios::app), quiet_(quiet), terminal_(::isatty(STDERR_FILENO) == 1) {
  if (!file_) throw std::runtime_error("cannot open log file " + file.string());
}

void RunLog::break_progress_line() {
  if (progress_open_) {
    std::fputc('\n', stderr);
    progress_open_ = false;
  }
}

void RunLog::info(const std::string& line) {
  file_ << timestamp() << "  " << line << "\n";
  file_.flush();
  if (quiet_) return;
  break_progress_line();
  // a line may name the case's files and folders: shown, never obeyed
  std::fprintf(stderr, "%s\n", text::printable(line).c_str());
}

void RunLog::progress_line(const std::string& line) {
  file_ << timestamp() << "  " << line << "\n";
  file_.flush();
  if (quiet_) return;
  if (terminal_) {
    std::fprintf(stderr, "\r%-100s", text::printable(line).c_str());
    std::fflush(stderr);
    progress_open_ = true;
  } else {
    std::fprintf(stderr, "%s\n", text::printable(line).c_str());
  }
}

ProgressReporter::ProgressReporter(RunLog& log, std::filesystem::path progress_json,
                                   long first_step, long steps_total, long cells, double every_s)
    : log_(log),
      progress_json_(std::move(progress_json)),
      first_step_(first_step),
      steps_total_(steps_total),
      cells_(cells),
      every_s_(every_s),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_),
      last_json_(start_) {}

double ProgressReporter::mlups(long step) const {
  const double sec =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return sec > 0 ? static_cast<double>(step - first_step_) * static_cast<double>(cells_) / sec / 1e6
                 : 0.0;
}

void ProgressReporter::update(long step, const std::string& extra) {
  const auto now = std::chrono::steady_clock::now();
  const double since_print = std::chrono::duration<double>(now - last_print_).count();
  const double since_json = std::chrono::duration<double>(now - last_json_).count();
  if (since_print < every_s_ && since_json < std::min(every_s_, 5.0)) return;
  report(step, extra);
  if (since_print >= every_s_) last_print_ = now;
  last_json_ = now;
}

void ProgressReporter::finish(long step) {
  report(step, "", true);
}

void ProgressReporter::set_steps_total(long steps_total) {
  steps_total_ = steps_total;
}

void ProgressReporter::report(long step, const std::string& extra, bool last) {
  // a sphere scene's total is an estimate (stage 1 ends when the suspension
  // is stationary): one overrun grows it, so that progress never reads above
  // 100 % or a negative ETA
  if (step > steps_total_) steps_total_ = step;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const long done = step - first_step_;
  const double rate = elapsed > 0 ? done / elapsed : 0.0;  // steps per second
  const double eta = rate > 0 ? (steps_total_ - step) / rate : INFINITY;
  const double fraction = steps_total_ > 0 ? static_cast<double>(step) / steps_total_ : 1.0;
  const double m = mlups(step);
  if (std::chrono::duration<double>(now - last_print_).count() >= every_s_ || last) {
    char line[256];
    char rate_text[32] = "";
    if (cells_ > 0) std::snprintf(rate_text, sizeof rate_text, " | %7.1f MLUPS", m);
    std::snprintf(line, sizeof line, "step %ld/%ld (%5.1f%%)%s | ETA %s%s%s", step, steps_total_,
                  100 * fraction, rate_text, format_duration(eta).c_str(),
                  extra.empty() ? "" : " | ", extra.c_str());
    log_.progress_line(line);
  }
  nlohmann::json j = {{"step", step},
                      {"steps_total", steps_total_},
                      {"fraction", fraction},
                      {"eta_s", std::isfinite(eta) ? eta : -1.0},
                      {"mlups", m},
                      {"updated_at", static_cast<double>(std::time(nullptr))},
                      {"pid", static_cast<long>(::getpid())}};
  for (auto it = state_.begin(); it != state_.end(); ++it) j[it.key()] = it.value();
  output::write_file_atomically(progress_json_, j.dump() + "\n");
}

}  // namespace flocsim::run
