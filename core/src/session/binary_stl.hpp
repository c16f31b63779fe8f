#pragma once
// A triangle mesh as a binary STL file, the form a SceneUpdate's ModelPrimitive embeds
// ("model/stl"): an 80-byte header, a little-endian u32 triangle count, then per triangle
// a normal and three vertices (12 float32) and a u16 attribute, 50 bytes in all. Readers
// tell binary from ASCII STL by that size, so the header never starts with "solid".
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace hg::session::detail {

// vertices: x, y, z per vertex; triangles: three indices each (a triangle naming a vertex
// that does not exist is left out).
std::string binaryStl(std::span<const float> vertices, std::span<const std::uint32_t> triangles,
                      std::string_view header);

}  // namespace hg::session::detail
