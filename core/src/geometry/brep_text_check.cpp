#include "brep_text_check.hpp"

#include <locale.h>
#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <optional>

#include "hapticgrasp/geometry/geometry_error.hpp"

namespace hg::geometry {
namespace {

// OCCT reads a number as a word of at most 255 characters (GeomTools::GetReal), and a
// section's name into a buffer of 255.
constexpr std::size_t kReadWidth = 255;

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; }

// --- Line by line -------------------------------------------------------------------------

// A section count larger than the text's lines: each entry takes at least one.
void checkSectionCount(std::string_view line, std::size_t lines, const std::string& what) {
  static constexpr std::string_view kSections[] = {
      "Locations", "Curve2ds",       "Curves", "Polygon3D", "Polygon2D", "PolygonOnTriangulations",
      "Surfaces",  "Triangulations", "TShapes"};
  const std::size_t space = line.find(' ');
  const std::string_view section = line.substr(0, space);
  if (space == std::string_view::npos ||
      std::find(std::begin(kSections), std::end(kSections), section) == std::end(kSections))
    return;
  std::string_view count = line.substr(space + 1);
  while (!count.empty() && std::isspace(static_cast<unsigned char>(count.back()))) count.remove_suffix(1);
  if (count.empty() || count.find_first_not_of("0123456789") != std::string_view::npos) return;  // not a header
  if (count.size() > 18 || std::stoull(std::string(count)) > lines)
    throw GeometryError(what + " could not be read: its " + std::string(section) + " section claims " +
                        std::string(count) + " entries in a text of " + std::to_string(lines) + " lines");
}

// Not finite as OCCT reads it: strtod on the word, in the C locale whatever the process's
// (FreeCAD's), so "nan", "inf" and "1e2915" alike.
bool notFinite(std::string_view word) {
  static const locale_t c = newlocale(LC_ALL_MASK, "C", locale_t{});
  char buffer[kReadWidth + 1];
  word.copy(buffer, word.size());
  buffer[word.size()] = '\0';
  return !std::isfinite(strtod_l(buffer, nullptr, c));
}

void checkWords(std::string_view line, const std::string& what) {
  for (std::size_t w = 0; w < line.size();) {
    while (w < line.size() && isSpace(line[w])) ++w;
    std::size_t end = w;
    while (end < line.size() && !isSpace(line[end])) ++end;
    if (end - w >= kReadWidth)
      throw GeometryError(what + " could not be read: it holds a word of " + std::to_string(end - w) +
                          " characters (at most " + std::to_string(kReadWidth - 1) + " are read)");
    if (end > w && notFinite(line.substr(w, end - w)))
      throw GeometryError(what + " could not be read: it holds a number that is not finite (" +
                          std::string(line.substr(w, end - w)) + ")");
    w = end;
  }
}

// --- Entry by entry, as OCCT's reader consumes the text ----------------------------------

// The reader's two ways of taking from its stream: a word (`>> buffer`, GetReal) and an
// integer (`>> int`: a sign and digits, ending at anything else). nullopt where the stream
// would fail, which ends the walk: OCCT's reader fails there too (our stream throws on
// failbit, part_model.cpp).
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}

  std::size_t left() const { return text_.size() - at_; }

  std::optional<std::string_view> word() {
    skipSpace();
    const std::size_t start = at_;
    while (at_ < text_.size() && !isSpace(text_[at_]) && at_ - start < kReadWidth) ++at_;
    if (at_ == start) return std::nullopt;
    return text_.substr(start, at_ - start);
  }

  std::optional<long> integer() {
    skipSpace();
    std::size_t i = at_;
    const bool negative = i < text_.size() && text_[i] == '-';
    if (i < text_.size() && (text_[i] == '-' || text_[i] == '+')) ++i;
    const std::size_t digits = i;
    long value = 0;
    for (; i < text_.size() && text_[i] >= '0' && text_[i] <= '9'; ++i) {
      value = value * 10 + (text_[i] - '0');
      if (value > static_cast<long>(INT_MAX) + 1) return std::nullopt;  // the stream fails on overflow
    }
    if (i == digits) return std::nullopt;
    value = negative ? -value : value;
    if (value > INT_MAX || value < INT_MIN) return std::nullopt;
    at_ = i;
    return value;
  }

  // `>> bool`: an integer that is 0 or 1.
  std::optional<bool> flag() {
    const std::optional<long> v = integer();
    if (!v || (*v != 0 && *v != 1)) return std::nullopt;
    return *v == 1;
  }

  // Past the banner line (TopTools_ShapeSet::Read looks for it line by line, as C strings
  // of at most 99 characters, trailing CRs dropped, compared whole); its version, or 0
  // where OCCT's reader finds none or fails first.
  int skipToVersion() {
    static constexpr std::string_view kBanners[] = {"CASCADE Topology V1, (c) Matra-Datavision",
                                                    "CASCADE Topology V2, (c) Matra-Datavision",
                                                    "CASCADE Topology V3, (c) Open Cascade"};
    while (at_ < text_.size()) {
      const std::size_t end = std::min(text_.find('\n', at_), text_.size());
      std::string_view line = text_.substr(at_, end - at_);
      at_ = std::min(end + 1, text_.size());
      if (line.size() >= 100) return 0;  // the reader's getline fails
      line = line.substr(0, line.find('\0'));
      while (line.size() > 1 && (line.back() == '\r' || line.back() == '\n')) line.remove_suffix(1);
      for (int v = 0; v < 3; ++v)
        if (line == kBanners[v]) return v + 1;
    }
    return 0;
  }

 private:
  void skipSpace() {
    while (at_ < text_.size() && isSpace(text_[at_])) ++at_;
  }

  std::string_view text_;
  std::size_t at_ = 0;
};

class Walk {
 public:
  Walk(std::string_view text, const std::string& what) : c_(text), what_(what) {}

  // True when every entry was followed and the shapes come next; where() says where not.
  bool run() {
    const int version = c_.skipToVersion();
    if (version == 0) return false;
    hasNormals_ = version >= 3;
    return section("Locations", [&](long i) { return location(i); }) &&
           section("Curve2ds", [&](long i) { return curve(2, at("2D curve", i)); }) &&
           section("Curves", [&](long i) { return curve(3, at("3D curve", i)); }) &&
           section("Polygon3D", [&](long i) { return polygon3d(at("3D polygon", i)); }) &&
           section("PolygonOnTriangulations", [&](long i) { return polygonOnTriangulation(at("polygon on triangulation", i)); }) &&
           section("Surfaces", [&](long i) { return surface(at("surface", i)); }) &&
           section("Triangulations", [&](long i) { return triangulation(at("triangulation", i)); }) && shapesNext();
  }

  const std::string& where() const { return where_; }

 private:
  // Names the entry being read, for where() and the refusals.
  const std::string& at(const char* kind, long i) { return where_ = std::string(kind) + " " + std::to_string(i); }

  bool shapesNext() {
    where_ = "TShapes header";
    return c_.word() == "TShapes";
  }

  template <typename Entry>
  bool section(std::string_view name, Entry entry) {
    where_ = std::string(name) + " header";
    const std::optional<std::string_view> header = c_.word();
    const std::optional<long> count = header == name ? c_.integer() : std::nullopt;
    if (!count) return false;
    for (long i = 1; i <= *count; ++i)
      if (!entry(i)) return false;
    return true;
  }

  // Items the reader allocates for before it reads them: more than the characters left
  // (each takes one at least) cannot be there.
  bool fits(long count, long wordsEach, const std::string& entry, const char* items) {
    if (count < 0) return false;  // OCCT's array refuses it
    if (count * wordsEach > static_cast<long>(c_.left()))
      throw GeometryError(what_ + " could not be read: its " + entry + " claims " + std::to_string(count) + " " +
                          items + ", more than the " + std::to_string(c_.left()) + " characters after it hold");
    return true;
  }

  bool words(long n) {
    for (long i = 0; i < n; ++i)
      if (!c_.word()) return false;
    return true;
  }

  // Reals and integers in turn: B-spline knots and their multiplicities.
  bool knots(long n) {
    for (long i = 0; i < n; ++i)
      if (!c_.word() || !c_.integer()) return false;
    return true;
  }

  struct Nested {
    explicit Nested(int& depth) : depth_(depth) { ++depth_; }
    ~Nested() { --depth_; }
    int& depth_;
  };

  void checkNesting(const std::string& entry) {
    if (depth_ > kMaxBrepNesting)
      throw GeometryError(what_ + " could not be read: its " + entry + " nests curves and surfaces more than " +
                          std::to_string(kMaxBrepNesting) + " deep");
  }

  // "1" and a 3x4 matrix, or "2" and pairs (location, power) ending in 0.
  bool location(long i) {
    at("location", i);
    const std::optional<long> type = c_.integer();
    if (type == 1) return words(12);
    if (type != 2) return false;
    for (std::optional<long> datum = c_.integer(); datum && *datum != 0; datum = c_.integer()) {
      const std::optional<long> power = c_.integer();
      if (!power) return false;
      if (std::abs(*power) > kMaxLocationPower)
        throw GeometryError(what_ + " could not be read: its location " + std::to_string(i) + " raises location " +
                            std::to_string(*datum) + " to the power " + std::to_string(*power));
    }
    return true;
  }

  // GeomTools_CurveSet::ReadCurve (dim 3) and GeomTools_Curve2dSet::ReadCurve2d (dim 2).
  bool curve(int dim, const std::string& entry) {
    const Nested nested(depth_);
    checkNesting(entry);
    const std::optional<long> type = c_.integer();
    if (!type) return false;
    // Point, then the axes: 3 + 9 in 3D (main, x and y directions), 2 + 4 in 2D (x and y).
    const long axes = dim == 3 ? 12 : 6;
    switch (*type) {
      case 1: return words(2 * dim);      // line: point, direction
      case 2: return words(axes + 1);     // circle: radius
      case 3: return words(axes + 2);     // ellipse: radii
      case 4: return words(axes + 1);     // parabola: focal length
      case 5: return words(axes + 2);     // hyperbola: radii
      case 6: {                           // Bezier
        const std::optional<bool> rational = c_.flag();
        const std::optional<long> degree = c_.integer();
        if (!rational || !degree) return false;
        const long perPole = dim + (*rational ? 1 : 0);
        return fits(*degree + 1, perPole, entry, "poles") && words((*degree + 1) * perPole);
      }
      case 7: {                           // B-spline
        const std::optional<bool> rational = c_.flag(), periodic = c_.flag();
        const std::optional<long> degree = c_.integer(), poles = c_.integer(), knotCount = c_.integer();
        if (!rational || !periodic || !degree || !poles || !knotCount) return false;
        const long perPole = dim + (*rational ? 1 : 0);
        return fits(*poles, perPole, entry, "poles") && fits(*knotCount, 2, entry, "knots") &&
               words(*poles * perPole) && knots(*knotCount);
      }
      case 8: return words(2) && curve(dim, entry);                         // trimmed: range, basis
      case 9: return words(dim == 3 ? 4 : 1) && curve(dim, entry);          // offset: distance [, direction], basis
      default: return false;                                                // no type OCCT writes
    }
  }

  // GeomTools_SurfaceSet::ReadSurface.
  bool surface(const std::string& entry) {
    const Nested nested(depth_);
    checkNesting(entry);
    const std::optional<long> type = c_.integer();
    if (!type) return false;
    constexpr long kAx3 = 12;  // point, main, x and y directions
    switch (*type) {
      case 1: return words(kAx3);                                 // plane
      case 2: return words(kAx3 + 1);                             // cylinder: radius
      case 3: return words(kAx3 + 2);                             // cone: radius, angle
      case 4: return words(kAx3 + 1);                             // sphere: radius
      case 5: return words(kAx3 + 2);                             // torus: radii
      case 6: return words(3) && curve(3, entry);                 // linear extrusion: direction, curve
      case 7: return words(6) && curve(3, entry);                 // revolution: axis, curve
      case 8: {                                                   // Bezier
        const std::optional<bool> uRational = c_.flag(), vRational = c_.flag();
        const std::optional<long> uDegree = c_.integer(), vDegree = c_.integer();
        if (!uRational || !vRational || !uDegree || !vDegree) return false;
        const long perPole = 3 + (*uRational || *vRational ? 1 : 0);
        if (!fits(*uDegree + 1, perPole, entry, "rows of poles") || !fits(*vDegree + 1, perPole, entry, "columns of poles"))
          return false;
        const long poles = (*uDegree + 1) * (*vDegree + 1);
        return fits(poles, perPole, entry, "poles") && words(poles * perPole);
      }
      case 9: {                                                   // B-spline
        std::optional<bool> flags[4];
        for (auto& f : flags) f = c_.flag();
        std::optional<long> n[6];  // u and v degree, poles, knots
        for (auto& k : n) k = c_.integer();
        if (!flags[0] || !flags[1] || !flags[2] || !flags[3] ||
            std::any_of(std::begin(n), std::end(n), [](const auto& k) { return !k; }))
          return false;
        const long perPole = 3 + (*flags[0] || *flags[1] ? 1 : 0);
        if (!fits(*n[2], perPole, entry, "rows of poles") || !fits(*n[3], perPole, entry, "columns of poles"))
          return false;
        const long poles = *n[2] * *n[3];
        return fits(poles, perPole, entry, "poles") && fits(*n[4], 2, entry, "u knots") &&
               fits(*n[5], 2, entry, "v knots") && words(poles * perPole) && knots(*n[4]) && knots(*n[5]);
      }
      case 10: return words(4) && surface(entry);                 // rectangular trim: ranges, basis
      case 11: return words(1) && surface(entry);                 // offset: distance, basis
      default: return false;
    }
  }

  // BRepTools_ShapeSet::ReadPolygon3D: nodes, a flag for parameters, the deflection.
  bool polygon3d(const std::string& entry) {
    const std::optional<long> nodes = c_.integer(), hasParameters = c_.integer();
    if (!nodes || !hasParameters || !fits(*nodes, *hasParameters ? 4 : 3, entry, "nodes")) return false;
    return words(1 + 3 * *nodes + (*hasParameters ? *nodes : 0));
  }

  // BRepTools_ShapeSet::ReadPolygonOnTriangulation: node indices, "p", the deflection, a
  // flag for parameters.
  bool polygonOnTriangulation(const std::string& entry) {
    const std::optional<long> nodes = c_.integer();
    if (!nodes || !fits(*nodes, 1, entry, "nodes")) return false;
    for (long k = 0; k < *nodes; ++k)
      if (!c_.integer()) return false;
    if (!words(2)) return false;
    const std::optional<long> hasParameters = c_.integer();
    if (!hasParameters) return false;
    return !*hasParameters || (fits(*nodes, 1, entry, "parameters") && words(*nodes));
  }

  // BRepTools_ShapeSet::ReadTriangulation: nodes, triangles, UV flag, normals flag (V3).
  bool triangulation(const std::string& entry) {
    const std::optional<long> nodes = c_.integer(), triangles = c_.integer();
    const std::optional<bool> hasUV = c_.flag();
    const std::optional<bool> normals = hasNormals_ ? c_.flag() : std::optional<bool>(false);
    if (!nodes || !triangles || !hasUV || !normals) return false;
    const long perNode = 3 + (*hasUV ? 2 : 0) + (*normals ? 3 : 0);
    if (!fits(*nodes, perNode, entry, "nodes") || !fits(*triangles, 3, entry, "triangles")) return false;
    if (!words(1 + *nodes * (3 + (*hasUV ? 2 : 0)))) return false;
    for (long k = 0; k < 3 * *triangles; ++k)
      if (!c_.integer()) return false;
    return words(*normals ? 3 * *nodes : 0);
  }

  Cursor c_;
  std::string what_;
  bool hasNormals_ = false;
  int depth_ = 0;
  std::string where_ = "banner line (\"CASCADE Topology V1, (c) Matra-Datavision\")";
};

}  // namespace

void checkBrepText(std::string_view text, const std::string& what) {
  const std::size_t lines = std::count(text.begin(), text.end(), '\n') + 1;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    checkSectionCount(text.substr(start, end - start), lines, what);
    checkWords(text.substr(start, end - start), what);
    start = end + 1;
  }
  Walk walk(text, what);
  if (!walk.run()) throw GeometryError(what + " could not be read: its " + walk.where() + " is not as OCCT writes it");
}

bool brepTextWalkedToShapes(std::string_view text) {
  try {
    return Walk(text, "").run();
  } catch (const GeometryError&) {
    return false;
  }
}

}  // namespace hg::geometry
