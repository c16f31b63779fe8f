#pragma once
// The device and servo verbs of the hapticgrasp command.
namespace hg::cli {

// hapticgrasp devices: the HID devices found and which back end or layout matches each.
int listDevices();
// hapticgrasp bench servo: the real servo thread grasping and lifting a part.
int benchServo(double rate_hz, double seconds, bool json);

}  // namespace hg::cli
