#pragma once
// One servo tick as a recording's message: the `hapticgrasp.Tick` protobuf message
// (core/proto/hapticgrasp/tick.proto) holding every field of a TickRecord. Doubles stay
// doubles, so decode(encode(r)) is bit-identical to r (NaN payloads and -0.0 included):
// replay re-simulates from the recorded samples and must reproduce the session exactly.
// Slots a record does not use (joints past jointCount, moving parts past movingCount) are
// not written and decode to their defaults.
#include <string>
#include <string_view>

#include "hapticgrasp/servo/tick_record.hpp"

namespace hg::session {

// Overwrites `out` with the message. Runs on the recorder's writer thread at up to 8 kHz:
// it reuses a per-thread arena and `out`'s capacity, so a steady stream does not allocate.
void encodeTick(const servo::TickRecord& record, std::string& out);

// False, leaving `out` untouched, for bytes that are not a whole, consistent Tick (cut
// short, garbage, out-of-range enums or counts). Never throws, whatever the bytes.
bool decodeTick(std::string_view bytes, servo::TickRecord& out) noexcept;

// The schema name of an MCAP channel carrying Ticks (schema encoding "protobuf").
inline constexpr std::string_view kTickSchemaName = "hapticgrasp.Tick";
// A serialized google.protobuf.FileDescriptorSet: hapticgrasp/tick.proto and every file it
// imports, imports first. What viewers decode the channel with.
std::string tickSchema();

}  // namespace hg::session
