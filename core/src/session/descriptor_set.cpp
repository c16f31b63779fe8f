#include "descriptor_set.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>

#include <unordered_set>

namespace hg::session::detail {
namespace {

namespace pb = google::protobuf;

// Depth first, each file after its imports; a file imported twice is written once.
void addFile(const pb::FileDescriptor& file, std::unordered_set<const pb::FileDescriptor*>& done,
             pb::FileDescriptorSet& set) {
  if (!done.insert(&file).second) return;
  for (int k = 0; k < file.dependency_count(); ++k) addFile(*file.dependency(k), done, set);
  file.CopyTo(set.add_file());
}

}  // namespace

std::string fileDescriptorSet(const pb::Descriptor& message) {
  pb::FileDescriptorSet set;
  std::unordered_set<const pb::FileDescriptor*> done;
  addFile(*message.file(), done, set);
  return set.SerializeAsString();
}

}  // namespace hg::session::detail
