#pragma once
// A B-rep vertex and its angle-weighted pseudo-normal (Baerentzen & Aanaes): the normals
// of the faces meeting there, each weighted by the face's interior angle at the vertex.
// x - vertex has a positive dot product with it exactly when x is outside, for every x
// whose closest feature is the vertex; computed once here so that a query never needs
// the (slow, allocating) solid classifier.
#include <TopTools_IndexedMapOfShape.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <vector>

#include "face_model.hpp"

namespace hg::geometry::exact {

struct VertexModel {
  gp_Pnt point;
  gp_Vec pseudoNormal;
};

// One model per vertex of `vertices`, in order. `faces` is the part's face map (faces as
// oriented in the solid) and `faceModels` the models built from it.
std::vector<VertexModel> buildVertexModels(const TopTools_IndexedMapOfShape& vertices,
                                           const TopTools_IndexedMapOfShape& faces,
                                           const std::vector<FaceModel>& faceModels);

}  // namespace hg::geometry::exact
