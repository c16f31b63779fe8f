#pragma once
// The device and servo verbs of the hapticgrasp command.
#include <string>

namespace hg::cli {

// hapticgrasp devices: the HID devices found and which back end or layout matches each.
int listDevices();
// hapticgrasp bench servo: the real servo thread grasping and lifting a part, held by the
// simulated master arm (device "arm") or a scripted hand ("scripted").
int benchServo(double rate_hz, double seconds, const std::string& part, const std::string& device,
               const std::string& backend, bool json);

}  // namespace hg::cli
