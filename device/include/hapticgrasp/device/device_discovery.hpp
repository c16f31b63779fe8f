#pragma once
// Which HID devices are plugged in, and which back end would drive each: a layout whose
// match (path, or vendor/product ID) fits wins, then the SpaceMouse table, else none.
#include <memory>
#include <string>
#include <vector>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/device/hid_layout.hpp"
#include "hapticgrasp/device/hid_transport.hpp"

namespace hg::device {

enum class HidBackend { None, SpaceMouse, GenericLayout };
const char* hidBackendName(HidBackend backend) noexcept;  // "none", "spacemouse", "layout"

struct DiscoveredDevice {
  HidDeviceInfo info;
  HidBackend backend = HidBackend::None;
  std::string model;       // SpaceMouse model name, or the layout's name
  int layoutIndex = -1;    // into the layouts given, for GenericLayout
};

std::vector<DiscoveredDevice> discoverDevices(HidTransport& transport, const std::vector<HidLayout>& layouts);

// One line per device:
//   /dev/hidraw3  046d:c626  3Dconnexion SpaceNavigator  -> spacemouse (SpaceNavigator)
// and "no HID devices found" when the list is empty.
std::string formatDiscoveredDevices(const std::vector<DiscoveredDevice>& devices);

// Opens a discovered device with its back end. Throws HidError for HidBackend::None or
// when the device cannot be opened.
std::unique_ptr<Device> openDiscoveredDevice(HidTransport& transport, const DiscoveredDevice& device,
                                             const std::vector<HidLayout>& layouts);

}  // namespace hg::device
