#include "hapticgrasp/device/spacemouse.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

namespace hg::device {
namespace {

constexpr SpaceMouseModel kModels[] = {
    {0x046d, 0xc603, "SpaceMouse Plus XT"},
    {0x046d, 0xc605, "CadMan"},
    {0x046d, 0xc606, "SpaceMouse Classic"},
    {0x046d, 0xc621, "SpaceBall 5000"},
    {0x046d, 0xc623, "SpaceTraveler"},
    {0x046d, 0xc625, "SpacePilot"},
    {0x046d, 0xc626, "SpaceNavigator"},
    {0x046d, 0xc627, "SpaceExplorer"},
    {0x046d, 0xc628, "SpaceNavigator for Notebooks"},
    {0x046d, 0xc629, "SpacePilot Pro"},
    {0x046d, 0xc62b, "SpaceMouse Pro"},
    {0x256f, 0xc62e, "SpaceMouse Wireless (cabled)"},
    {0x256f, 0xc62f, "SpaceMouse Wireless (receiver)"},
    {0x256f, 0xc631, "SpaceMouse Pro Wireless (cabled)"},
    {0x256f, 0xc632, "SpaceMouse Pro Wireless (receiver)"},
    {0x256f, 0xc633, "SpaceMouse Enterprise"},
    {0x256f, 0xc635, "SpaceMouse Compact"},
    {0x256f, 0xc652, "3Dconnexion Universal Receiver"},
};

int int16le(const std::uint8_t* p) noexcept {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] | (p[1] << 8)));
}

bool plausible(const int* v, int n) noexcept {
  for (int i = 0; i < n; ++i)
    if (std::abs(v[i]) > SpaceMouseParser::kMaxRawMagnitude) return false;
  return true;
}

double monotonicSeconds() noexcept {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

}  // namespace

const char* spaceMouseModel(std::uint16_t vendor_id, std::uint16_t product_id) noexcept {
  for (const auto& m : kModels)
    if (m.vendor_id == vendor_id && m.product_id == product_id) return m.name;
  return nullptr;
}

std::span<const SpaceMouseModel> spaceMouseModels() noexcept { return kModels; }

bool SpaceMouseParser::parse(const std::uint8_t* data, std::size_t size) noexcept {
  if (!data || size == 0) {
    ++stats_.short_;
    return false;
  }
  switch (data[0]) {
    case 1:
    case 2: {
      if (size < 7) {
        ++stats_.short_;
        return false;
      }
      const bool combined = data[0] == 1 && size == 13;
      if (size != 7 && !combined) {
        ++stats_.oversized;
        return false;
      }
      int v[6];
      const int n = combined ? 6 : 3;
      for (int i = 0; i < n; ++i) v[i] = int16le(data + 1 + 2 * i);
      if (!plausible(v, n)) {
        ++stats_.garbage;
        return false;
      }
      if (data[0] == 1) {
        for (int i = 0; i < 3; ++i) translation_[i] = v[i];
        if (combined)
          for (int i = 0; i < 3; ++i) rotation_[i] = v[3 + i];
      } else {
        for (int i = 0; i < 3; ++i) rotation_[i] = v[i];
      }
      break;
    }
    case 3: {
      if (size < 2) {
        ++stats_.short_;
        return false;
      }
      if (size > 13) {
        ++stats_.oversized;
        return false;
      }
      std::uint32_t mask = 0;
      for (std::size_t i = 1; i < size && i <= 4; ++i) mask |= std::uint32_t(data[i]) << (8 * (i - 1));
      buttons_ = mask;
      break;
    }
    default:
      ++stats_.unknownId;
      return false;
  }
  ++stats_.accepted;
  return true;
}

// ---- the virtual hand ---------------------------------------------------------------

SpaceMouseHand::SpaceMouseHand(const SpaceMouseConfig& config) : config_(config) { reset(); }

void SpaceMouseHand::reset() noexcept {
  wrist_ = config_.initialWrist;
  rotation_ = Quat(config_.initialRotation).normalized();
  width_ = targetWidth_ = config_.openWidth_m;
  linear_ = angular_ = Vec3::Zero();
  buttons_ = 0;
}

double SpaceMouseHand::shaped(int raw) const noexcept {
  const double full = config_.fullScale > 0 ? config_.fullScale : 350.0;
  const double a = std::clamp(raw / full, -1.0, 1.0);
  const double db = std::clamp(config_.deadband, 0.0, 0.99);
  const double m = std::abs(a);
  if (m <= db) return 0;
  return std::copysign((m - db) / (1 - db), a);
}

void SpaceMouseHand::setInput(const std::array<int, 3>& translation, const std::array<int, 3>& rotation,
                              std::uint32_t buttons) noexcept {
  linear_ = config_.axisMap * Vec3(shaped(translation[0]), shaped(translation[1]), shaped(translation[2]));
  angular_ = config_.axisMap * Vec3(shaped(rotation[0]), shaped(rotation[1]), shaped(rotation[2]));
  const std::uint32_t pressed = buttons & ~buttons_;
  auto bit = [](int b) { return (b >= 0 && b < 32) ? (std::uint32_t(1) << b) : 0u; };
  if (pressed & bit(config_.pinchButton)) targetWidth_ = config_.closedWidth_m;
  if (pressed & bit(config_.openButton)) targetWidth_ = config_.openWidth_m;
  buttons_ = buttons;
}

void SpaceMouseHand::advance(double dt) noexcept {
  if (!(dt > 0)) return;
  dt = std::min(dt, config_.maxStep_s);
  wrist_ += config_.linearSpeed_m_per_s * dt * linear_;
  if (!config_.workspace.empty()) wrist_ = wrist_.cwiseMax(config_.workspace.min).cwiseMin(config_.workspace.max);

  const Vec3 turn = config_.angularSpeed_rad_per_s * dt * angular_;
  const double angle = turn.norm();
  if (angle > 0) {
    const Quat dq(Eigen::AngleAxisd(angle, turn / angle));
    rotation_ = config_.rotateInWristFrame ? rotation_ * dq : dq * rotation_;
    rotation_.normalize();
  }

  const double span = std::abs(config_.openWidth_m - config_.closedWidth_m);
  const double rate = config_.gripTime_s > 0 ? span / config_.gripTime_s : 1e9;
  const double step = rate * dt;
  if (width_ < targetWidth_) width_ = std::min(targetWidth_, width_ + step);
  else if (width_ > targetWidth_) width_ = std::max(targetWidth_, width_ - step);
}

void SpaceMouseHand::fill(grasp::HandSample& hand) const noexcept {
  const Mat3 R = rotation_.toRotationMatrix();
  const Vec3 centre = wrist_ + R * config_.gripCentre_wrist;
  const Vec3 half = R.col(1) * (0.5 * width_);
  hand.wrist = wrist_;
  hand.wristRotation = R;
  hand.index = centre + half;
  hand.thumb = centre - half;
}

// ---- the device ---------------------------------------------------------------------

SpaceMouseDevice::SpaceMouseDevice(std::unique_ptr<HidConnection> connection, const SpaceMouseConfig& config,
                                   std::string name)
    : connection_(std::move(connection)), hand_(config) {
  if (!connection_) throw HidError("SpaceMouseDevice: no connection");
  spec_.name = std::move(name);
  spec_.forceOutput = false;
  spec_.maxForce_N = 0;
  spec_.maxTorque_Nm = 0;
  spec_.timeout_s = config.timeout_s;
  spec_.workspace = config.workspace;
}

bool SpaceMouseDevice::read(DeviceSample& sample) noexcept { return readAt(sample, monotonicSeconds()); }

bool SpaceMouseDevice::readAt(DeviceSample& sample, double now_s) noexcept {
  if (!started_) {
    started_ = true;
    lastTime_s_ = now_s;
  }
  // The input held since the last call moves the hand over the interval.
  hand_.advance(now_s - lastTime_s_);
  lastTime_s_ = now_s;

  bool got = false;
  std::uint8_t buffer[64];
  for (int i = 0; i < kMaxReportsPerRead; ++i) {
    const int n = connection_->read(buffer, sizeof buffer, 0);
    if (n == 0) break;
    if (n < 0) {
      ++parser_.stats().readErrors;
      break;
    }
    got |= parser_.parse(buffer, static_cast<std::size_t>(n));
  }
  if (got) {
    hand_.setInput(parser_.translation(), parser_.rotation(), parser_.buttons());
    lastReport_s_ = now_s;
    everReported_ = true;
  } else if (everReported_ && now_s - lastReport_s_ > hand_.config().inputHold_s) {
    hand_.setInput({}, {}, parser_.buttons());  // stale deflection: stop, keep the buttons
  }

  hand_.fill(sample.hand);
  sample.hand.t = now_s;
  sample.buttons = parser_.buttons();
  sample.jointCount = 0;
  sample.deviceTime_s = lastReport_s_;
  return got;
}

}  // namespace hg::device
