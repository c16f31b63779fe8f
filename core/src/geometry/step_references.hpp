#pragma once
// The instance references of a STEP file (ISO 10303-21 exchange structure), checked before
// OCCT's reader sees the file. OCCT follows some references by recursion while it reads
// (an ORIENTED_EDGE asks its edge element for its start, which may be another oriented
// edge): a file whose references run in a circle, or nest deeper than a thread's stack
// holds, overflows the stack, and no signal handler survives that (fuzz_step found two
// such files). Written by hand: no library here reads Part 21 but OCCT, whose reader is
// what this protects; only what the check needs is parsed (entity names, the type of each,
// its references), in one pass.
#include <cstddef>
#include <string>
#include <string_view>

namespace hg::geometry {

// Far deeper than any real model's chain of references (35 files from elsewhere: the AS1
// assembly, three NIST test cases, FreeCAD's IDF library and OCCT's samples, 16 at most),
// yet far inside a thread's 8 MiB stack at OCCT's frame sizes.
inline constexpr std::size_t kMaxStepReferenceDepth = 2000;

// Why OCCT must not read this STEP text, in words ("entity #20 (ORIENTED_EDGE) refers back
// to itself"), or "" when its references form no cycle and nest at most `maxDepth` deep.
std::string stepReferenceProblem(std::string_view text, std::size_t maxDepth = kMaxStepReferenceDepth);

// The longest chain of references in the text, counted in entities (1: no references),
// 0 for a text without entities; for the corpus check of kMaxStepReferenceDepth.
std::size_t stepReferenceDepth(std::string_view text);

}  // namespace hg::geometry
