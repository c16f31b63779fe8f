// HID layout JSON (resources/devices/*.json, a user's own file): parseHidLayout. It may
// throw HidLayoutError only, naming the field; a layout it accepts must be safe to use,
// so the input report it describes is decoded and a force report encoded with it.
#include <vector>

#include "fuzz_support.hpp"
#include "hapticgrasp/device/hid_layout.hpp"

using namespace hg::device;

namespace {

// A layout that parsed is used as the device would: a zero report of its declared size
// decoded, a command encoded into its force report and decoded back.
void use(const HidLayout& layout) {
  std::vector<std::uint8_t> report(static_cast<std::size_t>(std::max(layout.report_size, 1)), 0);
  report[0] = static_cast<std::uint8_t>(layout.input_report_id);
  DeviceSample sample;
  decodeInputReport(layout, report.data(), report.size(), sample);
  DeviceCommand command;
  command.f_wrist = hg::Vec3(1, -2, 3);
  command.f_grasp = 0.5;
  std::uint8_t out[GenericHidDevice::kMaxReportSize];
  const std::size_t n = encodeForceReport(layout, saturateCommand(command, layout.spec), out, sizeof out);
  if (n > 0) decodeForceReport(layout, out, n);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    use(parseHidLayout(hg::fuzz::text(data, size), "fuzz"));
  } catch (const HidLayoutError&) {
  }
  return 0;
}
