#include "hapticgrasp/geometry/occt_faults.hpp"

#include <OSD.hxx>
#include <atomic>
#include <csignal>
#include <iterator>

namespace hg::geometry {

namespace {

constexpr int kFaults[] = {SIGSEGV, SIGBUS, SIGILL, SIGFPE};
struct sigaction occtHandler[std::size(kFaults)];  // set before the counting handler goes in
std::atomic<unsigned long> faultsCaught{0};
static_assert(std::atomic<unsigned long>::is_always_lock_free, "counted inside a signal handler");

// Counts the fault, then hands it to OCCT's handler, which jumps back to OCC_CATCH_SIGNALS.
void countThenHandOn(int signal, siginfo_t* info, void* context) {
  faultsCaught.fetch_add(1, std::memory_order_relaxed);
  for (std::size_t i = 0; i < std::size(kFaults); ++i) {
    if (kFaults[i] != signal) continue;
    const struct sigaction& occt = occtHandler[i];
    if (occt.sa_flags & SA_SIGINFO) {
      occt.sa_sigaction(signal, info, context);
    } else if (occt.sa_handler != SIG_DFL && occt.sa_handler != SIG_IGN) {
      occt.sa_handler(signal);
    } else {  // no handler of OCCT's: the fault ends the process as it would have
      std::signal(signal, SIG_DFL);
      std::raise(signal);
    }
    return;
  }
}

// Puts countThenHandOn in front of the handler OCCT has just set for each fault, with its
// flags (SA_ONSTACK included) and mask.
void countFaults() {
  for (std::size_t i = 0; i < std::size(kFaults); ++i) {
    sigaction(kFaults[i], nullptr, &occtHandler[i]);
    struct sigaction counting = occtHandler[i];
    counting.sa_flags |= SA_SIGINFO;
    counting.sa_sigaction = &countThenHandOn;
    sigaction(kFaults[i], &counting, nullptr);
  }
}

}  // namespace

unsigned long occtFaultsCaught() noexcept { return faultsCaught.load(std::memory_order_relaxed); }

void catchOcctFaults() {
  // OSD::SetSignal sets every handler it knows; the ones not about faults are put back.
  constexpr int kKept[] = {SIGINT, SIGHUP, SIGQUIT};
  struct sigaction before[std::size(kKept)];
  for (std::size_t i = 0; i < std::size(kKept); ++i) sigaction(kKept[i], nullptr, &before[i]);
  OSD::SetSignal(OSD_SignalMode_Set, /*theFloatingSignal=*/false);
  for (std::size_t i = 0; i < std::size(kKept); ++i) sigaction(kKept[i], &before[i], nullptr);
  // A stack overflow is a SIGSEGV (or SIGBUS) with no stack left for its handler: on a
  // thread with a FaultStack, the handler runs there. Threads without one are unchanged.
  for (const int fault : {SIGSEGV, SIGBUS}) {
    struct sigaction action {};
    sigaction(fault, nullptr, &action);
    action.sa_flags |= SA_ONSTACK;
    sigaction(fault, &action, nullptr);
  }
  countFaults();
}

namespace {
// OCCT's handler makes its exception and jumps back to OCC_CATCH_SIGNALS: a few kB of stack.
constexpr std::size_t kFaultStackBytes = 256 * 1024;
}  // namespace

FaultStack::FaultStack() : memory_(new char[kFaultStackBytes]) {
  stack_t own{};
  own.ss_sp = memory_.get();
  own.ss_size = kFaultStackBytes;
  installed_ = sigaltstack(&own, &previous_) == 0;
}

FaultStack::~FaultStack() {
  if (installed_) sigaltstack(&previous_, nullptr);
}

}  // namespace hg::geometry
