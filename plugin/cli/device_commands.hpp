#pragma once
// The device and servo verbs of the hapticgrasp command.
#include <string>

#include "hapticgrasp/servo/scene_bench.hpp"
#include "hapticgrasp/servo/servo_bench.hpp"
#include "hapticgrasp/servo/soak.hpp"

namespace hg::cli {

// hapticgrasp devices: the HID devices found and which back end or layout matches each.
int listDevices();
// The udev rule for the supported devices and the installed HID layouts (device/udev_rule.hpp).
int printUdevRule();
// hapticgrasp bench servo: the real servo thread grasping and lifting a part, held by the
// simulated master arm (device "arm") or a scripted hand ("scripted"), with the two-finger
// or the multi-finger method. The allocation counter is set here.
int benchServo(servo::ServoBenchOptions options, bool json);
// hapticgrasp bench scene: what a scene's size costs (scene_bench.hpp).
int benchScene(servo::SceneBenchOptions options, bool json);
// hapticgrasp soak: the servo thread under injected faults for minutes (soak.hpp); 1 unless it passed.
int soak(servo::SoakOptions options, bool json);
// Heap allocations made so far by the calling thread (the process's malloc counter, which
// lives in this command's one translation unit that interposes malloc).
long threadAllocations();

}  // namespace hg::cli
