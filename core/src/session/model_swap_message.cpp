#include "hapticgrasp/session/model_swap_message.hpp"

#include <climits>

#include "descriptor_set.hpp"
#include "hapticgrasp/model_swap.pb.h"

namespace hg::session {

void encodeModelSwap(const ModelSwap& swap, std::string& out) {
  hapticgrasp::ModelSwap m;
  m.set_publication(swap.publication);
  m.set_part(static_cast<std::uint32_t>(swap.part));
  m.set_part_json(partToJson(swap.model));
  m.set_brep(swap.model.brep);
  m.SerializeToString(&out);
}

ModelSwap decodeModelSwap(std::string_view bytes) {
  hapticgrasp::ModelSwap m;
  if (bytes.size() > static_cast<std::size_t>(INT_MAX) || !m.ParseFromArray(bytes.data(), static_cast<int>(bytes.size())))
    throw SessionError("model swap: not a hapticgrasp.ModelSwap message");
  ModelSwap swap;
  swap.publication = m.publication();
  if (m.part() > static_cast<std::uint32_t>(INT_MAX)) throw SessionError("model swap: part index out of range");
  swap.part = static_cast<int>(m.part());
  try {
    swap.model = partFromJson(m.part_json());
  } catch (const SessionError& e) {
    throw SessionError(std::string("model swap: ") + e.what());
  }
  swap.model.brep = m.brep();
  return swap;
}

std::string modelSwapSchema() {
  static const std::string schema = detail::fileDescriptorSet(*hapticgrasp::ModelSwap::descriptor());
  return schema;
}

}  // namespace hg::session
