#include "hapticgrasp/device/udev_rule.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <sstream>
#include <string>

#include "hapticgrasp/device/spacemouse.hpp"

namespace hg::device {
namespace {

std::string ids(std::uint16_t vendor, std::uint16_t product) {
  char s[96];
  std::snprintf(s, sizeof s, "ATTRS{idVendor}==\"%04x\", ATTRS{idProduct}==\"%04x\"", vendor, product);
  return s;
}

HidLayout layoutMatching(std::optional<std::uint16_t> vendor, std::optional<std::uint16_t> product,
                         std::string path = "") {
  HidLayout L;
  L.name = "test layout";
  L.vendor_id = vendor;
  L.product_id = product;
  L.path = std::move(path);
  return L;
}

TEST(UdevRule, GrantsEveryKnownSpaceMouseToTheLoggedInUserOnly) {
  const std::string rule = udevRule({});
  ASSERT_GT(spaceMouseModels().size(), 10u);
  for (const SpaceMouseModel& m : spaceMouseModels())
    EXPECT_NE(rule.find(ids(m.vendor_id, m.product_id) + ", TAG+=\"uaccess\""), std::string::npos) << m.name;
  // Never world-writable, never a group of its own: uaccess is the whole grant.
  std::istringstream lines(rule);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line[0] == '#') continue;
    EXPECT_EQ(line.find("MODE"), std::string::npos) << line;
    EXPECT_EQ(line.find("GROUP"), std::string::npos) << line;
  }
}

TEST(UdevRule, EveryRuleLineIsAHidrawMatchWithUaccess) {
  std::istringstream lines(udevRule({layoutMatching(0x1209, 0x0003), layoutMatching(0x2341, std::nullopt)}));
  const std::regex rule(R"(SUBSYSTEM=="hidraw", ATTRS\{idVendor\}=="[0-9a-f]{4}"(, ATTRS\{idProduct\}=="[0-9a-f]{4}")?, TAG\+="uaccess")");
  int rules = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    EXPECT_TRUE(std::regex_match(line, rule)) << line;
    ++rules;
  }
  EXPECT_EQ(rules, static_cast<int>(spaceMouseModels().size()) + 2);
}

TEST(UdevRule, LayoutsByIdAreGrantedAndByPathOnlySaidInAComment) {
  const std::string rule =
      udevRule({layoutMatching(0x1209, 0x0003), layoutMatching(0x2341, std::nullopt),
                layoutMatching(std::nullopt, std::nullopt, "/dev/hidraw7")});
  EXPECT_NE(rule.find(ids(0x1209, 0x0003)), std::string::npos);
  // A layout for any product of a vendor grants the vendor.
  EXPECT_NE(rule.find("ATTRS{idVendor}==\"2341\", TAG+=\"uaccess\""), std::string::npos);
  EXPECT_NE(rule.find("# test layout: matched by path /dev/hidraw7 only"), std::string::npos);
  EXPECT_EQ(rule.find("hidraw7\""), std::string::npos);
}

TEST(UdevRule, ADeviceListedTwiceIsGrantedOnce) {
  const SpaceMouseModel& m = spaceMouseModels().front();
  const std::string rule = udevRule({layoutMatching(m.vendor_id, m.product_id)});
  const std::string line = ids(m.vendor_id, m.product_id);
  EXPECT_EQ(rule.find(line), rule.rfind(line));
}

}  // namespace
}  // namespace hg::device
