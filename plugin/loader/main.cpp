// hapticgrasp-loader: the workbench's loader process (geometry/loader_process.hpp). It loads
// the parts FreeCAD hands over, one after another, on its standard input (a socket), so that
// a shape that crashes OpenCASCADE or loops costs this process, never FreeCAD. Started by the
// workbench, never by hand.
#include <unistd.h>

#include <chrono>
#include <thread>

#include "hapticgrasp/geometry/loader_process.hpp"
#include "hapticgrasp/geometry/occt_faults.hpp"

int main() {
  // First, from the only thread: OCCT's faults become errors the workbench is told of.
  hg::geometry::catchOcctFaults();
  // A workbench that goes away closes the socket, which ends the loop below; one that goes
  // while a part loops is seen here, as this process is handed to another parent.
  const pid_t parent = getppid();
  std::thread([parent] {
    for (;;) {
      if (getppid() != parent) _exit(0);
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }).detach();
  return hg::geometry::serveLoads(STDIN_FILENO);
}
