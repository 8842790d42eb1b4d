#pragma once
// Seconds spent per named stage of a run: the stages of the coupled step
// (immersed_boundary, fluid, spheres, lubrication, events) and the work around
// it (observables, output, checkpoint). As waLBerla's timing pools: a stage is
// declared once by name, timed each time it runs, and reported by name
// (result.json's cost.modules_s). A stage declared but never run reports 0 s,
// so a scene reports the same keys whatever happened in this invocation.
#include <chrono>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace flocsim::run {

class TimedStages {
 public:
  using Clock = std::chrono::steady_clock;
  using Id = std::size_t;

  // The stage of this name, declared on first use.
  Id declare(std::string_view name) {
    for (Id i = 0; i < names_.size(); ++i)
      if (names_[i] == name) return i;
    names_.emplace_back(name);
    seconds_.push_back(0.0);
    return names_.size() - 1;
  }

  // Adds the time from construction to destruction to one stage, so that a
  // stage left early (a return, an exception) is still counted.
  class Scope {
   public:
    Scope(TimedStages& stages, Id id) : stages_(stages), id_(id), start_(Clock::now()) {}
    ~Scope() { stages_.seconds_[id_] += since(start_); }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    TimedStages& stages_;
    Id id_;
    Clock::time_point start_;
  };
  [[nodiscard]] Scope time(Id id) { return Scope(*this, id); }

  // Runs `body` as stage `id`.
  template <class Body>
  void run(Id id, Body&& body) {
    const Scope scope(*this, id);
    body();
  }

  double seconds(Id id) const { return seconds_.at(id); }
  double seconds(std::string_view name) const {
    for (Id i = 0; i < names_.size(); ++i)
      if (names_[i] == name) return seconds_[i];
    throw std::logic_error("no timed stage " + std::string(name));
  }
  // {stage name: seconds} for every declared stage.
  nlohmann::json seconds_by_name() const {
    nlohmann::json out = nlohmann::json::object();
    for (Id i = 0; i < names_.size(); ++i) out[names_[i]] = seconds_[i];
    return out;
  }

  static double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

 private:
  std::vector<std::string> names_;
  std::vector<double> seconds_;
};

}  // namespace flocsim::run
