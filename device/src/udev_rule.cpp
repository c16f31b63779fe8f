#include "hapticgrasp/device/udev_rule.hpp"

#include <cstdio>
#include <set>
#include <utility>

#include "hapticgrasp/device/spacemouse.hpp"

namespace hg::device {
namespace {

std::string hex4(std::uint16_t v) {
  char s[5];
  std::snprintf(s, sizeof s, "%04x", v);
  return s;
}

// hidraw nodes hang below the USB device that carries the IDs, hence ATTRS (any parent).
std::string accessLine(std::uint16_t vendor, const std::uint16_t* product, const std::string& what) {
  std::string line = "# " + what + "\nSUBSYSTEM==\"hidraw\", ATTRS{idVendor}==\"" + hex4(vendor) + "\"";
  if (product) line += ", ATTRS{idProduct}==\"" + hex4(*product) + "\"";
  return line + ", TAG+=\"uaccess\"\n";
}

}  // namespace

std::string udevRule(const std::vector<HidLayout>& layouts) {
  std::string rule =
      "# HapticGrasp: the logged-in user may read and write the HID devices it drives.\n"
      "# Made by `hapticgrasp devices --udev-rule` from the program's device tables; uaccess only\n"
      "# (no MODE or GROUP): nobody else gets the device.\n";
  std::set<std::pair<std::uint16_t, int>> done;  // product -1: any product of the vendor
  for (const SpaceMouseModel& m : spaceMouseModels()) {
    if (!done.insert({m.vendor_id, m.product_id}).second) continue;
    rule += accessLine(m.vendor_id, &m.product_id, m.name);
  }
  for (const HidLayout& L : layouts) {
    if (!L.vendor_id) {
      rule += "# " + L.name + ": matched by path " + L.path + " only; not granted here\n";
      continue;
    }
    const int product = L.product_id ? *L.product_id : -1;
    if (!done.insert({*L.vendor_id, product}).second) continue;
    rule += accessLine(*L.vendor_id, L.product_id ? &*L.product_id : nullptr, L.name + " (HID layout)");
  }
  return rule;
}

}  // namespace hg::device
