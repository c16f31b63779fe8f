#pragma once
// A BREP text (OCCT's own format: FreeCAD's exportBrepToString, .brep files) checked before
// OCCT's reader sees it, for the damage that reader does not survive:
//   - a section count ("Curves 135") beyond the text's lines: the reader sizes its tables by
//     it, then spins through entries that are not there;
//   - a number that is not finite, as OCCT reads it (strtod on the word): NaN trimming loops
//     for minutes, an infinite plane axis loops for good;
//   - a word longer than OCCT's reader reads at once (255 characters);
//   - a count inside an entry (a B-spline's poles, a triangulation's nodes) larger than the
//     rest of the text could hold: the reader allocates for it first (1.6e9 poles asked
//     for 38 GB, found by fuzz_brep), so memory stays within a few times the text's size;
//   - curves or surfaces nested deeper than kMaxBrepNesting (the reader recurses), and a
//     location raised to a power beyond kMaxLocationPower (its product recurses as deep).
//   - a text whose entries cannot be followed, as OCCT writes them, up to its shapes.
// The entries are followed as OCCT's reader consumes them (GeomTools_CurveSet, _Curve2dSet,
// _SurfaceSet, BRepTools_ShapeSet, TopTools_LocationSet), word by word and integer by
// integer, up to the shapes. A text that leaves that grammar is refused rather than left to
// OCCT: its reader carries on past a damaged entry (a zero direction ends an entry early,
// an unknown header is skipped), and a walk that lost its place could miss a count the
// reader then allocates for. Every text OCCT writes is followed (tests: the corpus, OCCT's
// own samples, real STEP files meshed). Written by hand: only OCCT reads this format.
#include <string>
#include <string_view>

namespace hg::geometry {

inline constexpr int kMaxBrepNesting = 64;          // a trimmed curve of an offset curve of ...: real files nest 3
inline constexpr long kMaxLocationPower = 1000;     // OCCT writes powers of 1 and -1

// Throws GeometryError "<what> could not be read: <why>" for the damage above.
void checkBrepText(std::string_view text, const std::string& what);

// Whether the walk follows every entry of the text up to its shapes ("TShapes"), sizes
// aside: every text OCCT writes does (the tests hold real ones to it).
bool brepTextWalkedToShapes(std::string_view text);

}  // namespace hg::geometry
