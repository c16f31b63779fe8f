#pragma once
// Faces that truly cross: two faces of one solid passing through each other (a defect the
// exact back end would answer wrongly near), or the boundaries of two solids of a compound
// passing through each other (their volumes overlap).
//
// Touching is not crossing: faces that meet along the edges and vertices they share, solids
// that touch (a bolt in its nut, coincident faces), and everything within the tolerances
// the B-rep carries (STEP files carry large ones) are not reported.
//
// How: a coarse mesh of the curved faces (planar faces stay exact planes) is searched for
// triangles that cross one another or cross a planar face inside its boundary, and planar
// faces whose edges pierce one another; each such candidate is then confirmed on the exact
// surfaces: a point where both surfaces meet at an angle, inside both faces and away from
// their vertices and shared edges. A crossing smaller than the search mesh can resolve
// (about its deflection) may be missed; a candidate that is not confirmed is not reported.
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Pnt.hxx>

#include <vector>

namespace hg::geometry {

struct FaceCrossing {
  TopoDS_Face a, b;             // as located in the searched shape
  int solidA = 0, solidB = 0;   // 1-based, in TopExp::MapShapes order; equal within one solid
  gp_Pnt point;                 // where they cross, shape units
};

struct CrossingSearch {
  std::vector<FaceCrossing> crossings;  // at most one per pair of faces
  std::vector<TopoDS_Face> unmeshed;    // curved faces BRepMesh left without triangles: not searched
  double deflection = 0;                // of the search mesh, shape units
  bool truncated = false;               // more candidate pairs than are confirmed (kept bounded)
  bool meshingStopped = false;          // BRepMesh stopped at its budget: curved faces meshed in part
  bool pairsStopped = false;            // the overlapping boxes were more than its budget: compared in part
};

// Bounds on the search's work, so that a damaged part's search ends; each is said in
// CrossingSearch when reached.
struct CrossingBudgets {
  // BRepMesh's asks of its progress indicator (meshing_limits.hpp: MeshingBudget). Real
  // parts ask about six times a face (the 1,030-face sample plate 6,146, the corpus at most
  // 3,007 for 517 faces); a damaged B-spline face kept BRepMesh's Delaunay busy for 9.8 s
  // (48,195 asks; fuzz_brep), 0.5 s within 5,000.
  long meshingChecksAtLeast = 5'000;
  long meshingChecksPerFace = 50;
  // Pairs of primitives whose boxes overlap. Real parts have fewer than ten per primitive
  // (the corpus and the external files: at most 6.3); a surface folded on itself has
  // thousands (a damaged B-spline face: 112 million pairs among 40,000 triangles, 3 s in
  // Release, 30 s under ASan; fuzz_brep).
  long boxPairsPerPrimitive = 100;
  long boxPairsAtLeast = 100'000;
};

// `shape`: a solid or a compound of solids. Throws Standard_Failure only on OCCT bugs.
CrossingSearch findFaceCrossings(const TopoDS_Shape& shape, const CrossingBudgets& budgets = {});

}  // namespace hg::geometry
