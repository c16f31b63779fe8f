#include "binary_stl.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

namespace hg::session::detail {
namespace {

constexpr std::size_t kHeaderSize = 80;
constexpr std::size_t kTriangleSize = 50;

// Byte by byte, so the file is little-endian whatever the machine.
void putU32(std::uint32_t v, std::string& out) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFFu));
}
void putFloat(float v, std::string& out) { putU32(std::bit_cast<std::uint32_t>(v), out); }

using Point = std::array<float, 3>;

// The unit normal by the right-hand rule, zero for a degenerate triangle.
Point normal(const Point& a, const Point& b, const Point& c) {
  const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
  const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(length > 0)) return {0, 0, 0};
  return {float(n[0] / length), float(n[1] / length), float(n[2] / length)};
}

std::string header(std::string_view text) {
  std::string h = "HapticGrasp ";  // never "solid...", which readers take for ASCII STL
  h.append(text.substr(0, kHeaderSize - h.size()));
  h.resize(kHeaderSize, '\0');
  return h;
}

}  // namespace

std::string binaryStl(std::span<const float> vertices, std::span<const std::uint32_t> triangles,
                      std::string_view text) {
  const std::size_t vertexCount = vertices.size() / 3;
  std::string out = header(text);
  out.reserve(kHeaderSize + 4 + kTriangleSize * (triangles.size() / 3));
  putU32(0, out);  // the count, filled in once the bad triangles are left out
  std::uint32_t count = 0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    if (std::max({triangles[t], triangles[t + 1], triangles[t + 2]}) >= vertexCount) continue;
    Point p[3];
    for (int k = 0; k < 3; ++k) std::copy_n(&vertices[3 * std::size_t(triangles[t + k])], 3, p[k].begin());
    for (float v : normal(p[0], p[1], p[2])) putFloat(v, out);
    for (const Point& q : p)
      for (float v : q) putFloat(v, out);
    out.append(2, '\0');  // attribute byte count: unused
    ++count;
  }
  std::string countBytes;
  putU32(count, countBytes);
  out.replace(kHeaderSize, 4, countBytes);
  return out;
}

}  // namespace hg::session::detail
