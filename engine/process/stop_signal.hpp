#pragma once
// SIGTERM and SIGINT ask a process to stop: the handler only records the
// signal; the process notices it at a safe point. A run writes a checkpoint
// and exits with kExitInterrupted, so nothing computed is lost; an
// orchestrator asks its workers to do so, and kills them at a second signal.
// One handler for both (the solver and the orchestrator).
namespace flocsim::process {

enum class SecondSignal {
  ends_the_process,  // the default action returns: a second Ctrl-C ends a run stuck writing
  is_counted,        // every signal is counted (stop_requests) and handled by the caller
};

void install_stop_handlers(SecondSignal second);
// The last signal received (0 when none).
int stop_requested();
// How many stop signals arrived.
int stop_requests();
// For tests: pretend a signal arrived / forget every one.
void request_stop(int signal);
void clear_stop_request();

}  // namespace flocsim::process
