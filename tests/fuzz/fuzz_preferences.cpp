// Preferences: the workbench's preference page stores the force parameters in FreeCAD's
// parameter store and the Python side (prefs.py, session.py) hands them, as doubles, to
// Session::setParameters, the one C++ entry that judges them: any value a user can type
// or a damaged user.cfg can hold. It may throw std::invalid_argument only, and a set it
// accepts must read back finite.
//
// Input: records of one byte (the parameter: an index into parameterNames(), or an
// unknown name beyond it) and eight bytes (the value's bits, so NaN, infinities and
// denormals come up as often as ordinary numbers).
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "fuzz_support.hpp"
#include "haptic_session.hpp"

using hg::freecad::Session;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& names = Session::parameterNames();
  std::vector<std::pair<std::string, double>> values;
  for (std::size_t i = 0; i + 9 <= size; i += 9) {
    const std::size_t k = data[i] % (names.size() + 1);
    double value;
    std::memcpy(&value, data + i + 1, sizeof value);
    values.emplace_back(k < names.size() ? names[k] : std::string("K_unknown"), value);
  }
  Session session;
  try {
    session.setParameters(values);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  for (const std::string& name : names)
    if (!std::isfinite(session.parameter(name))) __builtin_trap();  // accepted, yet not finite
  return 0;
}
