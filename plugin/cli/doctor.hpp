#pragma once
// hapticgrasp doctor: what this machine and user allow and lack for the product, each
// problem with its fix -- real-time scheduling and locked memory for the servo thread,
// access to HID devices (hidraw nodes and the package's udev rule), FreeCAD and whether its
// Python imports the workbench's module, an audio output for the grasp cues.
#include <nlohmann/json.hpp>

namespace hg::cli {

// The findings as JSON: {"realtime": {"granted", "why", "fix", ...}, "memory_lock": {...},
// "hidraw": {...}, "freecad": {...}, "addon": {...}, "audio": {...}, "problems": [...]}.
nlohmann::json doctorFindings();
// Prints the findings (JSON or one line per area); exit code 0 (a report, not a gate).
int doctor(bool json);

}  // namespace hg::cli
