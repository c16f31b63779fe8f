#include "hapticgrasp/device/device_discovery.hpp"

#include <algorithm>
#include <cstdio>

#include "hapticgrasp/device/spacemouse.hpp"

namespace hg::device {

const char* hidBackendName(HidBackend backend) noexcept {
  switch (backend) {
    case HidBackend::SpaceMouse: return "spacemouse";
    case HidBackend::GenericLayout: return "layout";
    default: return "none";
  }
}

std::vector<DiscoveredDevice> discoverDevices(HidTransport& transport, const std::vector<HidLayout>& layouts) {
  std::vector<DiscoveredDevice> out;
  for (auto& info : transport.enumerate()) {
    DiscoveredDevice d;
    d.info = std::move(info);
    // A layout matched by path is the most specific; then by vendor/product ID.
    for (int pass = 0; pass < 2 && d.layoutIndex < 0; ++pass) {
      for (std::size_t i = 0; i < layouts.size(); ++i) {
        const bool byPath = !layouts[i].path.empty();
        if ((pass == 0) == byPath && layouts[i].matches(d.info)) {
          d.layoutIndex = static_cast<int>(i);
          break;
        }
      }
    }
    if (d.layoutIndex >= 0) {
      d.backend = HidBackend::GenericLayout;
      d.model = layouts[d.layoutIndex].name;
    } else if (const char* model = spaceMouseModel(d.info.vendor_id, d.info.product_id)) {
      d.backend = HidBackend::SpaceMouse;
      d.model = model;
    }
    out.push_back(std::move(d));
  }
  return out;
}

std::string formatDiscoveredDevices(const std::vector<DiscoveredDevice>& devices) {
  if (devices.empty()) return "no HID devices found\n";
  std::size_t pathWidth = 4;
  for (const auto& d : devices) pathWidth = std::max(pathWidth, d.info.path.size());
  std::string text;
  for (const auto& d : devices) {
    char ids[16];
    std::snprintf(ids, sizeof ids, "%04x:%04x", d.info.vendor_id, d.info.product_id);
    std::string line = d.info.path;
    line.append(pathWidth - d.info.path.size() + 2, ' ');
    line += ids;
    std::string label = d.info.manufacturer;
    if (!d.info.product.empty()) label += (label.empty() ? "" : " ") + d.info.product;
    if (label.empty()) label = "(unnamed)";
    line += "  " + label + "  -> " + hidBackendName(d.backend);
    if (d.backend == HidBackend::GenericLayout) {
      line += " '" + d.model + "'";
    } else if (d.backend == HidBackend::SpaceMouse) {
      line += " (" + d.model + ")";
    } else {
      line += " (no layout matches)";
    }
    text += line + "\n";
  }
  return text;
}

std::unique_ptr<Device> openDiscoveredDevice(HidTransport& transport, const DiscoveredDevice& device,
                                             const std::vector<HidLayout>& layouts) {
  switch (device.backend) {
    case HidBackend::SpaceMouse:
      return std::make_unique<SpaceMouseDevice>(transport.open(device.info.path), SpaceMouseConfig{},
                                                "SpaceMouse " + device.model);
    case HidBackend::GenericLayout:
      if (device.layoutIndex < 0 || device.layoutIndex >= static_cast<int>(layouts.size()))
        throw HidError("no layout " + std::to_string(device.layoutIndex) + " for " + device.info.path);
      return std::make_unique<GenericHidDevice>(transport.open(device.info.path), layouts[device.layoutIndex]);
    default:
      throw HidError(device.info.path + ": no back end for this device (give a layout that matches it)");
  }
}

}  // namespace hg::device
