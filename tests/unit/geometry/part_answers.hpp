#pragma once
// Parts as text, and the check that two part models answer alike: a part restored from the
// model cache or from the loader process against the same part loaded from its text.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/part_model.hpp"

namespace hg::test {

using namespace hg::geometry;

// A file's text; a sample part's BREP text (resources/parts); a corpus part's (tests/corpus/parts).
inline std::string text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
inline std::string sample(const std::string& name) { return text(std::string(HG_RESOURCES_DIR) + "/parts/" + name + ".brep"); }
inline std::string corpus(const std::string& name) {
  return text(std::string(HG_TEST_DATA_DIR) + "/../corpus/parts/" + name + ".brep");
}

// The restored part answers every query as the one loaded from its text.
inline void expectSameAnswers(const PartModelPtr& a, const PartModelPtr& b) {
  EXPECT_EQ(a->faces().Extent(), b->faces().Extent());
  EXPECT_EQ(a->edges().Extent(), b->edges().Extent());
  EXPECT_LT((a->bounds().min - b->bounds().min).norm(), 1e-15);
  EXPECT_LT((a->bounds().max - b->bounds().max).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(a->massProperties(MassSpec::density(1000)).mass_kg, b->massProperties(MassSpec::density(1000)).mass_kg);
  EXPECT_EQ(a->backendChoice().backend, b->backendChoice().backend);
  EXPECT_EQ(a->backendChoice().reason, b->backendChoice().reason);
  EXPECT_EQ(a->backendChoice().surfaceMayCross, b->backendChoice().surfaceMayCross);
  EXPECT_EQ(a->warnings(), b->warnings());
  EXPECT_EQ(a->primitive().kind, b->primitive().kind);
  const auto pa = makePenetration(a), pb = makePenetration(b);
  EXPECT_EQ(pa->name(), pb->name());
  std::mt19937 rng(1);
  const Aabb box = a->bounds().inflated(0.005);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 500; ++i) {
    const Vec3 x = box.min + box.size().cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
    QueryState sa, sb;
    const Penetration qa = pa->query(x, sa), qb = pb->query(x, sb);
    ASSERT_EQ(qa.inside, qb.inside) << x.transpose();
    ASSERT_EQ(qa.depth, qb.depth) << x.transpose();
  }
}

}  // namespace hg::test
