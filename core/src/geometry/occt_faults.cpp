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
}

}  // namespace hg::geometry
