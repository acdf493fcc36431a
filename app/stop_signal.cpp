#include "app/stop_signal.h"

#include <atomic>
#include <csignal>

namespace pxf {

namespace {

// Set from the handler: a process-directed signal may reach any thread (TBB's, llvmpipe's), and
// the handler only sets this flag, so whichever thread runs it is fine.
std::atomic<int> g_stop_signal{0};
const int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void on_stop_signal(int signal_number) {
  g_stop_signal = signal_number;
  for (int s : kStopSignals) std::signal(s, SIG_DFL);
}

}  // namespace

StopSignalHandlers::StopSignalHandlers() {
  static_assert(sizeof(kStopSignals) / sizeof(kStopSignals[0]) == kSignals);
  g_stop_signal = 0;
  for (int i = 0; i < kSignals; ++i) {
    struct sigaction current {};
    sigaction(kStopSignals[i], nullptr, &current);
    ignored_[i] = current.sa_handler == SIG_IGN;
    if (!ignored_[i]) previous_[i] = std::signal(kStopSignals[i], on_stop_signal);
  }
}

StopSignalHandlers::~StopSignalHandlers() {
  for (int i = 0; i < kSignals; ++i)
    if (!ignored_[i]) std::signal(kStopSignals[i], previous_[i]);
}

int stop_signal() { return g_stop_signal; }

}  // namespace pxf
