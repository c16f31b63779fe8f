#include "hid_input.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <filesystem>

namespace hg::freecad {

// ---- the transport ------------------------------------------------------------------

namespace {

std::mutex& transportMutex() {
  static std::mutex m;
  return m;
}

std::shared_ptr<device::HidTransport>& transportSlot() {
  static std::shared_ptr<device::HidTransport> slot = std::make_shared<device::HidapiTransport>();
  return slot;
}

}  // namespace

device::HidTransport& hidTransport() {
  std::lock_guard<std::mutex> lock(transportMutex());
  return *transportSlot();
}

void useTestHidTransport(std::shared_ptr<device::HidTransport> transport) {
  if (!transport) throw std::invalid_argument("no transport");
  std::lock_guard<std::mutex> lock(transportMutex());
  transportSlot() = std::move(transport);
}

void useRealHidTransport() {
  std::lock_guard<std::mutex> lock(transportMutex());
  transportSlot() = std::make_shared<device::HidapiTransport>();
}

// ---- the test feed ------------------------------------------------------------------

namespace {

class FeedConnection final : public device::HidConnection {
 public:
  FeedConnection(std::unique_ptr<device::HidConnection> inner, std::shared_ptr<std::mutex> mutex)
      : inner_(std::move(inner)), mutex_(std::move(mutex)) {}
  int read(std::uint8_t* buffer, std::size_t size, int timeout_ms) noexcept override {
    std::unique_lock<std::mutex> lock(*mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return 0;  // the feeder is queueing: nothing yet, never wait
    return inner_->read(buffer, size, timeout_ms);
  }
  int write(const std::uint8_t* buffer, std::size_t size) noexcept override {
    std::unique_lock<std::mutex> lock(*mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return static_cast<int>(size);
    return inner_->write(buffer, size);
  }

 private:
  std::unique_ptr<device::HidConnection> inner_;
  std::shared_ptr<std::mutex> mutex_;
};

}  // namespace

void TestHidFeed::addDevice(const device::HidDeviceInfo& info) {
  std::lock_guard<std::mutex> lock(*mutex_);
  fake_.addDevice(info);
  fake_.setRecordWrites(info.path, false);  // a long session would grow the record
}

void TestHidFeed::removeDevice(const std::string& path) {
  std::lock_guard<std::mutex> lock(*mutex_);
  fake_.removeDevice(path);
}

void TestHidFeed::queueReport(const std::string& path, std::vector<std::uint8_t> bytes) {
  std::lock_guard<std::mutex> lock(*mutex_);
  fake_.queueReport(path, std::move(bytes));
}

std::size_t TestHidFeed::pending(const std::string& path) {
  std::lock_guard<std::mutex> lock(*mutex_);
  return fake_.pending(path);
}

std::size_t TestHidFeed::writeCount(const std::string& path) {
  std::lock_guard<std::mutex> lock(*mutex_);
  return fake_.writeCount(path);
}

std::vector<device::HidDeviceInfo> TestHidFeed::enumerate() {
  std::lock_guard<std::mutex> lock(*mutex_);
  return fake_.enumerate();
}

std::unique_ptr<device::HidConnection> TestHidFeed::open(const std::string& path) {
  std::lock_guard<std::mutex> lock(*mutex_);
  return std::make_unique<FeedConnection>(fake_.open(path), mutex_);
}

// ---- listing and opening ------------------------------------------------------------

HidListing listHidDevices(const std::vector<std::string>& layoutDirs) {
  HidListing out;
  for (const auto& dir : layoutDirs) {
    if (dir.empty() || !std::filesystem::is_directory(dir)) continue;
    device::HidLayoutSet set = device::loadHidLayoutDirectory(dir);
    for (auto& layout : set.layouts) out.layouts.push_back(std::move(layout));
    for (auto& error : set.errors) out.layoutErrors.push_back(std::move(error));
  }
  out.devices = device::discoverDevices(hidTransport(), out.layouts);
  return out;
}

std::string hidOpenAdvice(const device::HidDeviceInfo& info, const std::string& reason, int accessible) {
  std::string text = reason;
  bool denied = accessible == 0;
  if (accessible < 0 && !info.path.empty() && info.path.rfind("/dev/", 0) == 0) {
    denied = ::access(info.path.c_str(), R_OK | W_OK) != 0 && errno == EACCES;
  }
  if (denied) {
    std::string vendor;  // the rule names the vendor when it is known
    if (info.vendor_id != 0) {
      char id[8];
      std::snprintf(id, sizeof id, "%04x", info.vendor_id);
      vendor = std::string(", ATTRS{idVendor}==\"") + id + "\"";
    }
    text = "permission denied on " + info.path + " (this user may not read and write it). Fix: a udev rule, " +
           "e.g. as root: echo 'KERNEL==\"hidraw*\"" + vendor +
           ", MODE=\"0660\", TAG+=\"uaccess\"' > /etc/udev/rules.d/70-hapticgrasp.rules && "
           "udevadm control --reload && udevadm trigger; then unplug and replug the device. (" +
           reason + ")";
  }
  return text;
}

namespace {

device::HidDeviceInfo findAttached(const std::string& path, const char* what,
                                   bool (*accept)(const device::DiscoveredDevice&, const void*), const void* arg,
                                   const std::vector<device::HidLayout>& layouts) {
  const auto devices = device::discoverDevices(hidTransport(), layouts);
  for (const auto& d : devices) {
    if (!path.empty() ? d.info.path == path : accept(d, arg)) return d.info;
  }
  if (!path.empty()) {
    device::HidDeviceInfo info;
    info.path = path;  // not listed (hidapi may still open it by path)
    return info;
  }
  std::string text = std::string("no ") + what + " attached";
  text += devices.empty() ? " (no HID device found at all)" : " (" + std::to_string(devices.size()) +
                                                                  " other HID device(s) found; `hapticgrasp devices` lists them)";
  throw device::HidError(text);
}

std::unique_ptr<device::HidConnection> openConnection(const device::HidDeviceInfo& info) {
  try {
    return hidTransport().open(info.path);
  } catch (const device::HidError& e) {
    throw device::HidError(hidOpenAdvice(info, e.what()));
  }
}

}  // namespace

std::unique_ptr<PlacedDevice> openSpaceMouse(const std::string& path, const device::SpaceMouseConfig& config,
                                             const Vec3& offset_m) {
  const device::HidDeviceInfo info = findAttached(
      path, "SpaceMouse",
      [](const device::DiscoveredDevice& d, const void*) { return d.backend == device::HidBackend::SpaceMouse; },
      nullptr, {});
  const char* model = device::spaceMouseModel(info.vendor_id, info.product_id);
  const std::string name = std::string("SpaceMouse") + (model ? std::string(" ") + model : std::string()) +
                           " (" + info.path + ")";
  auto spaceMouse = std::make_unique<device::SpaceMouseDevice>(openConnection(info), config, name);
  const std::uint64_t* errors = &spaceMouse->parser().stats().readErrors;
  return std::make_unique<PlacedDevice>(std::move(spaceMouse), offset_m, errors, true, true, name);
}

std::unique_ptr<PlacedDevice> openHidLayout(const std::string& layoutFile, const std::string& path,
                                            const Vec3& offset_m) {
  device::HidLayout layout = device::loadHidLayout(layoutFile);
  const std::vector<device::HidLayout> layouts{layout};
  const device::HidDeviceInfo info = findAttached(
      path, ("device matching the layout '" + layout.name + "'").c_str(),
      [](const device::DiscoveredDevice& d, const void*) { return d.backend == device::HidBackend::GenericLayout; },
      nullptr, layouts);
  const std::string name = layout.name + " (" + info.path + ")";
  const bool inputOnly = !layout.spec.forceOutput;
  auto generic = std::make_unique<device::GenericHidDevice>(openConnection(info), std::move(layout));
  const std::uint64_t* errors = &generic->stats().readErrors;
  return std::make_unique<PlacedDevice>(std::move(generic), offset_m, errors, inputOnly, false, name);
}

// ---- the placed device --------------------------------------------------------------

PlacedDevice::PlacedDevice(std::unique_ptr<device::Device> inner, const Vec3& offset_m,
                           const std::uint64_t* readErrors, bool quietIsRest, bool restFromStart, std::string name)
    : inner_(std::move(inner)), offset_(offset_m), readErrors_(readErrors), quietIsRest_(quietIsRest),
      haveHand_(restFromStart) {
  if (!inner_) throw std::invalid_argument("PlacedDevice: no device");
  spec_ = inner_->spec();
  spec_.name = std::move(name);
  if (!spec_.workspace.empty()) {
    spec_.workspace.min += offset_;
    spec_.workspace.max += offset_;
  }
  if (readErrors_) errorsSeen_ = *readErrors_;
}

bool PlacedDevice::read(device::DeviceSample& sample) noexcept {
  if (silent_.load(std::memory_order_acquire)) return false;
  // raw_ keeps the last hand: a device that fills nothing without a report leaves it.
  bool got = inner_->read(raw_);
  if (got) haveHand_ = true;
  if (!got && quietIsRest_ && haveHand_) {
    const std::uint64_t errors = readErrors_ ? *readErrors_ : 0;
    got = errors == errorsSeen_;  // quiet is rest; a read error is silence
    errorsSeen_ = errors;
  }
  if (!got) return false;
  sample = raw_;
  sample.hand.index += offset_;
  sample.hand.thumb += offset_;
  sample.hand.wrist += offset_;
  return true;
}

}  // namespace hg::freecad
