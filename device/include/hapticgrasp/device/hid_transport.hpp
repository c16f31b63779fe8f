#pragma once
// A thin transport under the HID back ends: enumerate devices, open one by path, read
// input reports and write output reports. The real implementation is hidapi (hidraw back
// end); FakeHidTransport replays queued reports in process, for tests (this kernel has no
// uhid/uinput, so no virtual HID device can be made).
//
// Report bytes are as hidapi gives them: for a device with numbered reports, byte 0 of
// an input report is the report ID; an output report always starts with the report ID
// (0 for a device without numbered reports).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hg::device {

struct HidDeviceInfo {
  std::string path;  // platform path (/dev/hidrawN on Linux); open() takes it
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string product;       // UTF-8, may be empty
  std::string manufacturer;  // UTF-8, may be empty
  std::string serial;        // UTF-8, may be empty
  int interface_number = -1;
};

// Opening or enumerating failed (the message says why: no such path, permission, ...).
class HidError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One open device. read() and write() are for the servo thread: they do not allocate
// and do not throw.
class HidConnection {
 public:
  virtual ~HidConnection() = default;
  // Copies one input report into `buffer` (truncated to `size`), waiting at most
  // `timeout_ms` (0: do not wait). Returns its length, 0 on timeout, -1 on error.
  virtual int read(std::uint8_t* buffer, std::size_t size, int timeout_ms) noexcept = 0;
  // Writes one output report (byte 0 = report ID). Returns bytes written or -1.
  virtual int write(const std::uint8_t* buffer, std::size_t size) noexcept = 0;
};

class HidTransport {
 public:
  virtual ~HidTransport() = default;
  virtual std::vector<HidDeviceInfo> enumerate() = 0;
  // Throws HidError when the device cannot be opened; never returns null.
  virtual std::unique_ptr<HidConnection> open(const std::string& path) = 0;
};

// hidapi over hidraw. hid_init() runs once per process, on first use.
class HidapiTransport : public HidTransport {
 public:
  std::vector<HidDeviceInfo> enumerate() override;
  std::unique_ptr<HidConnection> open(const std::string& path) override;
};

// In-process fake: devices added by the test, reports replayed in order, writes recorded.
// A device with nothing queued times out (read() returns 0), as a silent device does.
// Not thread-safe: the test drives it from one thread.
class FakeHidTransport : public HidTransport {
 public:
  void addDevice(const HidDeviceInfo& info);
  void removeDevice(const std::string& path);  // open connections then read errors
  void queueReport(const std::string& path, std::vector<std::uint8_t> bytes);
  void queueError(const std::string& path);  // the next read returns -1
  std::size_t pending(const std::string& path) const;
  // Every report written to the device, in order (only while recording, the default;
  // recording allocates, so a test of write() allocations turns it off).
  const std::vector<std::vector<std::uint8_t>>& writes(const std::string& path) const;
  std::size_t writeCount(const std::string& path) const;
  void setRecordWrites(const std::string& path, bool record);
  void setFailWrites(const std::string& path, bool fail);

  std::vector<HidDeviceInfo> enumerate() override;
  std::unique_ptr<HidConnection> open(const std::string& path) override;

  struct State;  // shared by the transport and the connections it opened

 private:
  State& state(const std::string& path) const;
  std::map<std::string, std::shared_ptr<State>> devices_;
  std::vector<std::string> order_;  // enumerate() lists devices in the order added
};

}  // namespace hg::device
