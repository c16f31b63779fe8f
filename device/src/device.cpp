// The Device interface is header-only; this file keeps the library non-empty until its
// back ends land, and anchors the vtable.
#include "hapticgrasp/device/device.hpp"
