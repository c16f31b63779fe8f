// URDF of the simulated master arm (resources/arms/master_arm.urdf, or the user's own via
// SimulatedArmOptions::urdfPath): urdfdom parses it, kdl_parser builds the tree, ArmModel
// checks the frames and joints. It may throw std::runtime_error only (urdfdom's own
// exceptions included, which derive from it). An arm it accepts must then simulate: a few
// steps of the simulated arm held by nobody, under gravity and a displayed force.
#include <console_bridge/console.h>

#include "fuzz_support.hpp"
#include "hapticgrasp/device/master_arm.hpp"
#include "hapticgrasp/device/simulated_operator.hpp"

using namespace hg::device;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // urdfdom's per-file errors
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static hg::fuzz::InputFile file(".urdf");
  SimulatedArmOptions options;
  options.urdfPath = file.write(data, size);
  try {
    SimulatedMasterArm arm(options);
    DeviceCommand command;
    command.f_index = hg::Vec3(0, 0, -2);
    DeviceSample sample;
    for (int i = 0; i < 10; ++i) {
      arm.read(sample);
      arm.write(command);
      arm.advance(0.001);
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
