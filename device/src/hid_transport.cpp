#include "hapticgrasp/device/hid_transport.hpp"

#include <hidapi/hidapi.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <utility>

namespace hg::device {
namespace {

// hidapi's strings are wchar_t (UTF-32 on Linux); the project's are UTF-8.
std::string toUtf8(const wchar_t* w) {
  std::string out;
  if (!w) return out;
  for (; *w; ++w) {
    auto c = static_cast<std::uint32_t>(*w);
    if (c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) c = 0xFFFD;
    if (c < 0x80) {
      out += static_cast<char>(c);
    } else if (c < 0x800) {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
      out += static_cast<char>(0xE0 | (c >> 12));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (c >> 18));
      out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return out;
}

void initHidapi() {
  static std::once_flag once;
  static int result = 0;
  std::call_once(once, [] { result = hid_init(); });
  if (result != 0) throw HidError("hidapi: hid_init failed: " + toUtf8(hid_error(nullptr)));
}

class HidapiConnection : public HidConnection {
 public:
  explicit HidapiConnection(hid_device* device) : device_(device) {}
  ~HidapiConnection() override { hid_close(device_); }
  HidapiConnection(const HidapiConnection&) = delete;
  HidapiConnection& operator=(const HidapiConnection&) = delete;

  int read(std::uint8_t* buffer, std::size_t size, int timeout_ms) noexcept override {
    return hid_read_timeout(device_, buffer, size, timeout_ms);
  }
  int write(const std::uint8_t* buffer, std::size_t size) noexcept override {
    return hid_write(device_, buffer, size);
  }

 private:
  hid_device* device_;
};

}  // namespace

std::vector<HidDeviceInfo> HidapiTransport::enumerate() {
  initHidapi();
  std::vector<HidDeviceInfo> out;
  hid_device_info* list = hid_enumerate(0, 0);
  for (const hid_device_info* d = list; d; d = d->next) {
    HidDeviceInfo info;
    info.path = d->path ? d->path : "";
    info.vendor_id = d->vendor_id;
    info.product_id = d->product_id;
    info.product = toUtf8(d->product_string);
    info.manufacturer = toUtf8(d->manufacturer_string);
    info.serial = toUtf8(d->serial_number);
    info.interface_number = d->interface_number;
    out.push_back(std::move(info));
  }
  hid_free_enumeration(list);
  return out;
}

std::unique_ptr<HidConnection> HidapiTransport::open(const std::string& path) {
  initHidapi();
  hid_device* device = hid_open_path(path.c_str());
  if (!device) {
    std::string why = toUtf8(hid_error(nullptr));
    if (why.empty()) why = "unknown error";
    throw HidError("could not open HID device " + path + ": " + why +
                   " (is it plugged in, and readable by this user? see udev rules for hidraw)");
  }
  return std::make_unique<HidapiConnection>(device);
}

// ---- fake ---------------------------------------------------------------------------

struct FakeHidTransport::State {
  struct Item {
    std::vector<std::uint8_t> bytes;
    bool error = false;
  };
  HidDeviceInfo info;
  std::deque<Item> queue;
  std::vector<std::vector<std::uint8_t>> writes;
  std::size_t writeCount = 0;
  bool recordWrites = true;
  bool failWrites = false;
  bool removed = false;
};

namespace {

class FakeConnection : public HidConnection {
 public:
  explicit FakeConnection(std::shared_ptr<FakeHidTransport::State> state) : state_(std::move(state)) {}

  int read(std::uint8_t* buffer, std::size_t size, int /*timeout_ms*/) noexcept override {
    auto& s = *state_;
    if (s.removed) return -1;
    if (s.queue.empty()) return 0;  // a silent device: timeout
    const bool error = s.queue.front().error;
    int n = -1;
    if (!error) {
      const auto& bytes = s.queue.front().bytes;
      const std::size_t count = std::min(size, bytes.size());  // hidraw truncates too
      if (count) std::memcpy(buffer, bytes.data(), count);
      n = static_cast<int>(count);
    }
    s.queue.pop_front();  // frees, never allocates
    return n;
  }

  int write(const std::uint8_t* buffer, std::size_t size) noexcept override {
    auto& s = *state_;
    if (s.removed || s.failWrites) return -1;
    ++s.writeCount;
    if (s.recordWrites) {
      try {
        s.writes.emplace_back(buffer, buffer + size);
      } catch (...) {
        return -1;
      }
    }
    return static_cast<int>(size);
  }

 private:
  std::shared_ptr<FakeHidTransport::State> state_;
};

}  // namespace

FakeHidTransport::State& FakeHidTransport::state(const std::string& path) const {
  auto it = devices_.find(path);
  if (it == devices_.end()) throw HidError("fake HID transport: no device at " + path);
  return *it->second;
}

void FakeHidTransport::addDevice(const HidDeviceInfo& info) {
  auto s = std::make_shared<State>();
  s->info = info;
  if (devices_.emplace(info.path, s).second) {
    order_.push_back(info.path);
  } else {
    devices_[info.path] = s;
  }
}

void FakeHidTransport::removeDevice(const std::string& path) {
  state(path).removed = true;
  devices_.erase(path);
  order_.erase(std::remove(order_.begin(), order_.end(), path), order_.end());
}

void FakeHidTransport::queueReport(const std::string& path, std::vector<std::uint8_t> bytes) {
  state(path).queue.push_back({std::move(bytes), false});
}

void FakeHidTransport::queueError(const std::string& path) { state(path).queue.push_back({{}, true}); }

std::size_t FakeHidTransport::pending(const std::string& path) const { return state(path).queue.size(); }

const std::vector<std::vector<std::uint8_t>>& FakeHidTransport::writes(const std::string& path) const {
  return state(path).writes;
}

std::size_t FakeHidTransport::writeCount(const std::string& path) const { return state(path).writeCount; }

void FakeHidTransport::setRecordWrites(const std::string& path, bool record) { state(path).recordWrites = record; }

void FakeHidTransport::setFailWrites(const std::string& path, bool fail) { state(path).failWrites = fail; }

std::vector<HidDeviceInfo> FakeHidTransport::enumerate() {
  std::vector<HidDeviceInfo> out;
  for (const auto& path : order_) out.push_back(devices_.at(path)->info);
  return out;
}

std::unique_ptr<HidConnection> FakeHidTransport::open(const std::string& path) {
  auto it = devices_.find(path);
  if (it == devices_.end()) throw HidError("could not open HID device " + path + ": no such device");
  return std::make_unique<FakeConnection>(it->second);
}

}  // namespace hg::device
