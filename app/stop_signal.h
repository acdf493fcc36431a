// Ctrl-C, SIGTERM and SIGHUP as a request to stop: a render finishes the frame it is on, writes
// everything, and exits with 128 + the signal, as a shell reports it. `pxf render` and its camera
// paths share this, so that a stop never loses finished work.
#pragma once

namespace pxf {

// Installs the stop handler for each stop signal that is not ignored (a background job of a shell
// script must stay immune to the terminal's Ctrl-C, a nohup'ed one to SIGHUP) and clears any earlier
// request; the previous dispositions come back at scope exit. A second stop signal ends the process
// at once (an output set stays whole: app/output_set.h).
class StopSignalHandlers {
 public:
  StopSignalHandlers();
  ~StopSignalHandlers();
  StopSignalHandlers(const StopSignalHandlers&) = delete;
  StopSignalHandlers& operator=(const StopSignalHandlers&) = delete;

 private:
  static constexpr int kSignals = 3;
  bool ignored_[kSignals] = {};
  void (*previous_[kSignals])(int) = {};
};

// The stop signal that arrived since the handlers were installed, or 0.
int stop_signal();

}  // namespace pxf
