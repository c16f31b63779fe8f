#pragma once
// The udev rule that lets the logged-in user open the HID devices HapticGrasp drives, made
// from the code's own tables so that it cannot drift from them: every known SpaceMouse
// (spacemouse.hpp) and every HID layout matched by USB IDs (hid_layout.hpp). systemd-logind
// gives a device tagged "uaccess" to the user at the seat (an ACL, removed at logout); the rule
// sets no MODE or GROUP, so the node stays unreadable by anyone else. Its file name sorts
// before 73-seat-late.rules, which applies the tag.
#include <string>
#include <vector>

#include "hapticgrasp/device/hid_layout.hpp"

namespace hg::device {

inline constexpr const char* kUdevRuleFile = "70-hapticgrasp.rules";

// The rule's text; layouts matched by a device path only are listed in a comment (a path is
// the user's own machine, not a product).
std::string udevRule(const std::vector<HidLayout>& layouts);

}  // namespace hg::device
