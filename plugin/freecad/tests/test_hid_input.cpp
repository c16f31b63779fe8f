// The workbench's HID devices through the test feed (no hidapi device on this machine):
// a SpaceMouse found, opened, placed in the document and read like the servo thread does;
// the messages when none is attached or it may not be opened.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "haptic_session.hpp"
#include "hid_input.hpp"

namespace hg::freecad {
namespace {

std::vector<std::uint8_t> translation(int x, int y, int z) {
  auto le = [](int v) { return std::pair<std::uint8_t, std::uint8_t>(v & 0xff, (v >> 8) & 0xff); };
  std::vector<std::uint8_t> r{1};
  for (int v : {x, y, z}) {
    auto [lo, hi] = le(v);
    r.push_back(lo);
    r.push_back(hi);
  }
  return r;
}

struct FeedFixture : ::testing::Test {
  std::shared_ptr<TestHidFeed> feed = std::make_shared<TestHidFeed>();
  void SetUp() override { useTestHidTransport(feed); }
  void TearDown() override { useRealHidTransport(); }
  void addSpaceMouse(const std::string& path = "/dev/hidraw-test0") {
    device::HidDeviceInfo info;
    info.path = path;
    info.vendor_id = 0x046d;
    info.product_id = 0xc626;
    info.product = "SpaceNavigator";
    feed->addDevice(info);
  }
};

TEST_F(FeedFixture, ListsTheSpaceMouseAndTheLayoutsDevices) {
  addSpaceMouse();
  device::HidDeviceInfo stick;
  stick.path = "/dev/hidraw-test1";
  stick.vendor_id = 0x1209;
  stick.product_id = 0x0001;
  feed->addDevice(stick);
  const HidListing listing = listHidDevices({std::string(HG_RESOURCES_DIR) + "/devices", "/no/such/dir"});
  ASSERT_EQ(listing.devices.size(), 2u);
  EXPECT_EQ(listing.devices[0].backend, device::HidBackend::SpaceMouse);
  EXPECT_EQ(listing.devices[1].backend, device::HidBackend::GenericLayout);
  EXPECT_TRUE(listing.layoutErrors.empty());
}

TEST_F(FeedFixture, ASpaceMouseAtRestIsNotSilentAndMovesWhenPushed) {
  addSpaceMouse();
  device::SpaceMouseConfig config;
  config.initialWrist = -config.gripCentre_wrist;
  auto dev = openSpaceMouse("", config, Vec3(0.4, 0, 0.3));
  EXPECT_NE(dev->spec().name.find("SpaceNavigator"), std::string::npos) << dev->spec().name;
  EXPECT_FALSE(dev->spec().forceOutput);
  device::DeviceSample s;
  ASSERT_TRUE(dev->read(s));  // at rest before any report: the starting hand
  const Vec3 centre = 0.5 * (s.hand.index + s.hand.thumb);
  EXPECT_NEAR((centre - Vec3(0.4, 0, 0.3)).norm(), 0, 1e-12);
  feed->queueReport("/dev/hidraw-test0", translation(0, 0, -350));  // full deflection up
  ASSERT_TRUE(dev->read(s));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(dev->read(s));  // no new report: still deflected, still not silent
  const Vec3 moved = 0.5 * (s.hand.index + s.hand.thumb) - centre;
  EXPECT_GT(moved.z(), 0.005);
  EXPECT_NEAR(moved.x(), 0, 1e-9);
  feed->removeDevice("/dev/hidraw-test0");  // unplugged: read errors are silence
  EXPECT_FALSE(dev->read(s));
}

TEST_F(FeedFixture, NoSpaceMouseAttachedSaysSo) {
  try {
    openSpaceMouse("", {}, Vec3::Zero());
    FAIL() << "no throw";
  } catch (const device::HidError& e) {
    EXPECT_NE(std::string(e.what()).find("no SpaceMouse attached"), std::string::npos) << e.what();
  }
  // The session keeps the device it had.
  Session session;
  session.useHandInput(0.5);
  EXPECT_THROW(session.useSpaceMouse("", {0, 0, 0}, 80, 0), device::HidError);
  EXPECT_EQ(session.deviceName(), "hand input");
}

TEST(HidOpenAdvice, PermissionDeniedNamesTheNodeAndTheUdevRule) {
  device::HidDeviceInfo info;
  info.path = "/dev/hidraw7";
  info.vendor_id = 0x256f;
  const std::string text = hidOpenAdvice(info, "could not open", 0);
  EXPECT_NE(text.find("permission denied on /dev/hidraw7"), std::string::npos) << text;
  EXPECT_NE(text.find("ATTRS{idVendor}==\"256f\""), std::string::npos) << text;
  EXPECT_NE(text.find("udevadm"), std::string::npos) << text;
  EXPECT_EQ(hidOpenAdvice(info, "could not open", 1), "could not open");
}

}  // namespace
}  // namespace hg::freecad
