#pragma once
// The workbench's HID devices (SpaceMouse, generic HID layouts) on top of hg_device: which
// are attached, opening one with a message that says what to do when it cannot be opened,
// and placing its hand in the document. No Python here: module.cpp binds it.
//
// The transport is hidapi, unless a test swapped in TestHidFeed (an in-process fake the
// GUI or test thread feeds while the servo thread reads it).
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "hapticgrasp/device/device.hpp"
#include "hapticgrasp/device/device_discovery.hpp"
#include "hapticgrasp/device/hid_layout.hpp"
#include "hapticgrasp/device/hid_transport.hpp"
#include "hapticgrasp/device/spacemouse.hpp"

namespace hg::freecad {

// The transport every workbench HID call uses (hidapi by default).
device::HidTransport& hidTransport();
// TEST ONLY: use `transport` instead of hidapi until useRealHidTransport().
void useTestHidTransport(std::shared_ptr<device::HidTransport> transport);
void useRealHidTransport();

// TEST ONLY: device::FakeHidTransport made safe to feed from one thread while the servo
// thread reads: the feeder locks a mutex; a read that finds it taken returns 0 (nothing
// yet) instead of waiting, so the servo thread never blocks on it.
class TestHidFeed final : public device::HidTransport {
 public:
  void addDevice(const device::HidDeviceInfo& info);
  void removeDevice(const std::string& path);
  void queueReport(const std::string& path, std::vector<std::uint8_t> bytes);
  std::size_t pending(const std::string& path);
  std::size_t writeCount(const std::string& path);

  std::vector<device::HidDeviceInfo> enumerate() override;
  std::unique_ptr<device::HidConnection> open(const std::string& path) override;

 private:
  std::shared_ptr<std::mutex> mutex_ = std::make_shared<std::mutex>();
  device::FakeHidTransport fake_;
};

// What is attached, with the back end that would drive each (layouts from `layoutDirs`;
// a layout file that does not load is reported in *layoutErrors, not fatal).
struct HidListing {
  std::vector<device::DiscoveredDevice> devices;
  std::vector<device::HidLayout> layouts;
  std::vector<std::string> layoutErrors;
};
HidListing listHidDevices(const std::vector<std::string>& layoutDirs);

// The message for a device that could not be opened: the transport's reason, and when
// the node exists but this user may not read and write it, the udev rule that fixes it.
// `accessible` < 0: check the path with access(2); 0/1: given (tests).
std::string hidOpenAdvice(const device::HidDeviceInfo& info, const std::string& reason, int accessible = -1);

// A device whose hand is moved by `offset_m` (the device's frame placed in the document),
// with its workspace moved too. For an input-only device, `quietIsRest` makes a read with
// no new report count as "the hand is where it was" (a SpaceMouse at rest sends nothing):
// only a read error (the device unplugged) makes it silent for the watchdog.
class PlacedDevice final : public device::Device {
 public:
  // restFromStart: the hand is valid before the first report (the SpaceMouse's starting
  // hand); otherwise the device is silent until its first report.
  PlacedDevice(std::unique_ptr<device::Device> inner, const Vec3& offset_m, const std::uint64_t* readErrors,
               bool quietIsRest, bool restFromStart, std::string name);
  const device::DeviceSpec& spec() const noexcept override { return spec_; }
  bool read(device::DeviceSample& sample) noexcept override;
  void write(const device::DeviceCommand& command) noexcept override { inner_->write(command); }
  void idle() noexcept override { inner_->idle(); }
  void setSilent(bool silent) noexcept { silent_.store(silent, std::memory_order_release); }

 private:
  std::unique_ptr<device::Device> inner_;
  Vec3 offset_;
  const std::uint64_t* readErrors_;
  bool quietIsRest_;
  device::DeviceSpec spec_;
  device::DeviceSample raw_;  // the inner device's latest hand, its own frame
  bool haveHand_ = false;
  std::uint64_t errorsSeen_ = 0;
  std::atomic<bool> silent_{false};
};

// Opens the SpaceMouse at `path` (empty: the first one attached). Throws device::HidError
// with hidOpenAdvice's message when none is attached or it cannot be opened.
std::unique_ptr<PlacedDevice> openSpaceMouse(const std::string& path, const device::SpaceMouseConfig& config,
                                             const Vec3& offset_m);
// Opens the device `layoutFile` describes at `path` (empty: the first attached device the
// layout matches). Throws HidLayoutError for a bad layout, HidError as above.
std::unique_ptr<PlacedDevice> openHidLayout(const std::string& layoutFile, const std::string& path,
                                            const Vec3& offset_m);

}  // namespace hg::freecad
