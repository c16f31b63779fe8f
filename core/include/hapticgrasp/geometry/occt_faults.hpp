#pragma once
// OpenCASCADE's faults as errors: with OCCT's signal handlers in place, a segmentation
// fault, bus error, illegal instruction or floating-point trap inside OCCT code under an
// OCC_CATCH_SIGNALS (the part readers, part_model.cpp) jumps back there and is thrown as a
// Standard_Failure, which the readers turn into a GeometryError. Without the handlers the
// process dies: in the workbench, FreeCAD and the user's unsaved work with it.
//
// Only a process that owns its signal handlers may call this: the command line and the
// tests. FreeCAD owns its own; the workbench never calls it.
#include <signal.h>

#include <memory>

namespace hg::geometry {

// Installs OCCT's handlers (OSD::SetSignal) for SIGSEGV, SIGBUS, SIGILL and SIGFPE, without
// enabling floating-point traps (NaN and infinity stay values, as the geometry code expects).
// SIGINT, SIGHUP and SIGQUIT keep the handlers they had: OCCT's would swallow Ctrl-C.
// Once per process, from its main thread, before any other thread is started.
// The handlers for SIGSEGV and SIGBUS run on a thread's FaultStack when it has one.
void catchOcctFaults();

// How many faults have reached OCCT's handlers in this process since catchOcctFaults(),
// counted by a handler of ours in front of OCCT's (0 in a process without them: FreeCAD's).
// A fault leaves by a jump that skips the destructors of every frame between the fault and
// the OCC_CATCH_SIGNALS that catches it, some of them inside OCCT: what they held (tens of
// kB per damaged part measured; any lock) is lost. This count includes faults OCCT's own
// algorithms catch and go on from, which no caller sees. The loader process uses it to end
// a helper after such a load rather than hand it the next part (loader_process.hpp).
unsigned long occtFaultsCaught() noexcept;

// While it lives, the calling thread has a stack of its own for signal handlers. A recursion
// inside OCCT that runs out of the thread's stack then still reaches OCCT's handler, and
// becomes a Standard_Failure under OCC_CATCH_SIGNALS like any other fault; without it, the
// handler itself cannot run and the process dies (fuzz_step found STEP files that send the
// reader's ORIENTED_EDGE into endless recursion). The part readers keep one. It changes
// nothing in a process without catchOcctFaults' handlers (FreeCAD's).
class FaultStack {
 public:
  FaultStack();
  ~FaultStack();
  FaultStack(const FaultStack&) = delete;
  FaultStack& operator=(const FaultStack&) = delete;

 private:
  std::unique_ptr<char[]> memory_;
  stack_t previous_{};
  bool installed_ = false;
};

}  // namespace hg::geometry
