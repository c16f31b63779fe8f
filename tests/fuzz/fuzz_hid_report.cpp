// HID input reports, as a device sends them: a stream of reports read by GenericHidDevice
// with each example layout (resources/devices) and by the SpaceMouse, through an in-process
// connection. Nothing here throws; the devices must count what they reject and never read
// or write outside their buffers. The forces a report leads to are encoded back.
//
// Input: byte 0 picks the reader (a layout, or the SpaceMouse); then reports, each one
// length byte and that many bytes (the last one cut short by the input's end).
#include <memory>
#include <vector>

#include "fuzz_support.hpp"
#include "hapticgrasp/device/hid_layout.hpp"
#include "hapticgrasp/device/spacemouse.hpp"

using namespace hg::device;

namespace {

// Hands the reports out one by one, truncated to the reader's buffer as hidraw does.
class ReportStream : public HidConnection {
 public:
  ReportStream(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  int read(std::uint8_t* buffer, std::size_t capacity, int) noexcept override {
    if (pos_ >= size_) return 0;
    const std::size_t declared = data_[pos_++];
    const std::size_t length = std::min(declared, size_ - pos_);
    const std::size_t copied = std::min(length, capacity);
    std::copy_n(data_ + pos_, copied, buffer);
    pos_ += length;
    return static_cast<int>(copied);
  }
  int write(const std::uint8_t*, std::size_t size) noexcept override { return static_cast<int>(size); }
  bool drained() const noexcept { return pos_ >= size_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_, pos_ = 0;
};

const std::vector<HidLayout>& layouts() {
  static const std::vector<HidLayout> all = loadHidLayoutDirectory(HG_RESOURCES_DIR "/devices").layouts;
  return all;
}

void writeAt(GenericHidDevice& device, const DeviceCommand& command, double t) { device.writeAt(command, t); }
void writeAt(SpaceMouseDevice& device, const DeviceCommand& command, double) { device.write(command); }

// Reads until the stream is drained (one read takes at most kMaxReportsPerRead reports),
// answering each read with a force as the servo loop would, 1 ms apart.
template <class DeviceT>
void drain(DeviceT& device, const ReportStream& stream) {
  DeviceSample sample;
  DeviceCommand command;
  command.f_index = hg::Vec3(0.5, 0, -1);
  command.f_grasp = 2;
  for (double t = 0; !stream.drained(); t += 0.001) {
    device.readAt(sample, t);
    writeAt(device, command, t);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t pick = data[0] % (layouts().size() + 1);
  auto stream = std::make_unique<ReportStream>(data + 1, size - 1);
  const ReportStream& reports = *stream;
  if (pick < layouts().size()) {
    GenericHidDevice device(std::move(stream), layouts()[pick]);
    drain(device, reports);
  } else {
    SpaceMouseDevice device(std::move(stream));
    drain(device, reports);
  }
  return 0;
}
