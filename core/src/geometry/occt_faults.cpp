#include "hapticgrasp/geometry/occt_faults.hpp"

#include <OSD.hxx>
#include <csignal>
#include <iterator>

namespace hg::geometry {

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
