#pragma once
// OpenCASCADE's faults as errors: with OCCT's signal handlers in place, a segmentation
// fault, bus error, illegal instruction or floating-point trap inside OCCT code under an
// OCC_CATCH_SIGNALS (the part readers, part_model.cpp) jumps back there and is thrown as a
// Standard_Failure, which the readers turn into a GeometryError. Without the handlers the
// process dies: in the workbench, FreeCAD and the user's unsaved work with it.
//
// Only a process that owns its signal handlers may call this: the command line and the
// tests. FreeCAD owns its own; the workbench never calls it.

namespace hg::geometry {

// Installs OCCT's handlers (OSD::SetSignal) for SIGSEGV, SIGBUS, SIGILL and SIGFPE, without
// enabling floating-point traps (NaN and infinity stay values, as the geometry code expects).
// SIGINT, SIGHUP and SIGQUIT keep the handlers they had: OCCT's would swallow Ctrl-C.
// Once per process, from its main thread, before any other thread is started.
void catchOcctFaults();

}  // namespace hg::geometry
