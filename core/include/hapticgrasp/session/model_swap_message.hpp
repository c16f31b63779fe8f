#pragma once
// A part's models swapped during a recorded session as a recording's message: the
// `hapticgrasp.ModelSwap` protobuf message (core/proto/hapticgrasp/model_swap.proto), on the
// channel kModelTopic. The workbench starts its servo on stand-in boxes and publishes each
// part's own model as its build finishes; without these messages neither replay nor a
// review without the document would know the shapes the session ended with.
#include <cstdint>
#include <string>
#include <string_view>

#include "hapticgrasp/session/session_description.hpp"

namespace hg::session {

inline constexpr std::string_view kModelTopic = "/hapticgrasp/models";
inline constexpr std::string_view kModelSwapSchemaName = "hapticgrasp.ModelSwap";

struct ModelSwap {
  std::uint64_t publication = 0;  // Scene::publications() numbering, 0-based
  int part = 0;
  RecordedPart model;             // with its BREP in model.brep ("" for a stand-in)
};

void encodeModelSwap(const ModelSwap& swap, std::string& out);
// Throws SessionError for bytes that are not a whole ModelSwap with a readable part.
ModelSwap decodeModelSwap(std::string_view bytes);

// A serialized FileDescriptorSet of hapticgrasp/model_swap.proto (schema encoding "protobuf").
std::string modelSwapSchema();

}  // namespace hg::session
