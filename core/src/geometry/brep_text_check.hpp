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
// The entries are followed as OCCT's reader consumes them (GeomTools_CurveSet, _Curve2dSet,
// _SurfaceSet, BRepTools_ShapeSet, TopTools_LocationSet), word by word and integer by
// integer, up to the shapes; where the text leaves that grammar the walk stops and OCCT's
// reader, which fails cleanly there, has the last word. Written by hand: only OCCT reads
// this format.
#include <string>
#include <string_view>

namespace hg::geometry {

inline constexpr int kMaxBrepNesting = 64;          // a trimmed curve of an offset curve of ...: real files nest 3
inline constexpr long kMaxLocationPower = 1000;     // OCCT writes powers of 1 and -1

// Throws GeometryError "<what> could not be read: <why>" for the damage above.
void checkBrepText(std::string_view text, const std::string& what);

// Whether the walk followed every entry of the text up to its shapes ("TShapes"): every
// text OCCT writes must (the tests hold real ones to it), a damaged one need not.
bool brepTextWalkedToShapes(std::string_view text);

}  // namespace hg::geometry
