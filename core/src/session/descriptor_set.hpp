#pragma once
// The schema an MCAP channel of encoding "protobuf" carries: a serialized FileDescriptorSet
// holding the message's .proto file and every file it imports, transitively, each import
// before the files that use it (what `protoc --include_imports --descriptor_set_out` writes).
// Built at run time from the descriptors compiled into the library, so it cannot drift
// from the code that writes the messages.
#include <string>

namespace google::protobuf {
class Descriptor;
}

namespace hg::session::detail {

std::string fileDescriptorSet(const google::protobuf::Descriptor& message);

}  // namespace hg::session::detail
