// Nothing built twice, nothing corrupt trusted: the cache gives back the part it was given,
// from memory and from disk, rebuilds a damaged entry, and keeps the disk within budget.
#include "hapticgrasp/geometry/model_cache.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "geometry/part_answers.hpp"

namespace hg::geometry {
namespace {

using test::corpus;
using test::expectSameAnswers;
using test::sample;
using test::text;

class ModelCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = std::filesystem::temp_directory_path() /
          ("hg-model-cache-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir);
  }
  void TearDown() override { std::filesystem::remove_all(dir); }
  std::filesystem::path dir;
};

TEST_F(ModelCacheTest, GivesBackThePartFromMemoryThenFromDisk) {
  ModelCache cache({dir});
  const std::string brep = sample("block");
  ModelCache::Outcome o;
  const PartModelPtr built = cache.load(brep, LengthUnit::Millimetre, "block", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Built);
  EXPECT_TRUE(std::filesystem::exists(cache.entryPath(cache.keyOf(brep, LengthUnit::Millimetre, {}))));
  EXPECT_EQ(cache.load(brep, LengthUnit::Millimetre, "block", {}, &o), built);
  EXPECT_EQ(o.source, ModelCache::Source::Memory);
  ModelCache another({dir});  // the next FreeCAD session
  const PartModelPtr restored = another.load(brep, LengthUnit::Millimetre, "block", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Disk);
  expectSameAnswers(built, restored);
}

TEST_F(ModelCacheTest, ADefectivePartKeepsItsVerdict) {
  ModelCache cache({dir});
  const std::string brep = corpus("defect_crossing_faces");
  const PartModelPtr built = cache.load(brep, LengthUnit::Millimetre, "crossing");
  ASSERT_TRUE(built->backendChoice().surfaceMayCross);
  ModelCache::Outcome o;
  const PartModelPtr restored = ModelCache({dir}).load(brep, LengthUnit::Millimetre, "crossing", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Disk);
  expectSameAnswers(built, restored);
}

TEST_F(ModelCacheTest, TheKeyIsTheContentUnitAndSettings) {
  const ModelCache cache({dir});
  const std::string a = sample("block"), b = sample("cylinder");
  PartModel::LoadOptions noCrossings;
  noCrossings.checkSelfIntersection = false;
  const std::string k = cache.keyOf(a, LengthUnit::Millimetre, {});
  EXPECT_EQ(k, cache.keyOf(std::string(a), LengthUnit::Millimetre, {}));
  EXPECT_NE(k, cache.keyOf(b, LengthUnit::Millimetre, {}));
  EXPECT_NE(k, cache.keyOf(a, LengthUnit::Metre, {}));
  EXPECT_NE(k, cache.keyOf(a, LengthUnit::Millimetre, noCrossings));
  std::string changed = a;
  changed[changed.size() / 2] = changed[changed.size() / 2] == '1' ? '2' : '1';
  EXPECT_NE(k, cache.keyOf(changed, LengthUnit::Millimetre, {}));
}

// Every kind of damage: a flipped bit, a truncated file, garbage, an empty file. Each is
// rebuilt (never trusted), said why, and the entry rewritten whole.
TEST_F(ModelCacheTest, ACorruptEntryIsRebuiltNeverTrusted) {
  const std::string brep = sample("cylinder");
  const std::filesystem::path path = ModelCache({dir}).entryPath(ModelCache({dir}).keyOf(brep, LengthUnit::Millimetre, {}));
  const auto damage = [&](const std::function<void(std::string&)>& how) {
    ModelCache({dir}).load(brep, LengthUnit::Millimetre, "cylinder");
    std::string bytes = text(path.string());
    how(bytes);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  };
  const std::vector<std::pair<std::string, std::function<void(std::string&)>>> damages{
      {"checksum mismatch", [](std::string& b) { b[b.size() / 2] ^= 0x10; }},
      {"checksum mismatch", [](std::string& b) { b.resize(b.size() * 2 / 3); }},
      {"not a model cache entry", [](std::string& b) { b = "garbage"; }},
      {"not a model cache entry", [](std::string& b) { b.clear(); }},
  };
  for (const auto& [why, how] : damages) {
    damage(how);
    ModelCache::Outcome o;
    const PartModelPtr part = ModelCache({dir}).load(brep, LengthUnit::Millimetre, "cylinder", {}, &o);
    EXPECT_EQ(o.source, ModelCache::Source::Rebuilt) << why;
    EXPECT_EQ(o.note, why);
    EXPECT_EQ(part->faces().Extent(), 3);
    ModelCache::Outcome again;
    ModelCache({dir}).load(brep, LengthUnit::Millimetre, "cylinder", {}, &again);
    EXPECT_EQ(again.source, ModelCache::Source::Disk) << "rewritten whole after " << why;
  }
}

TEST_F(ModelCacheTest, TheDiskStaysWithinItsBudgetDroppingTheLeastRecentlyUsed) {
  const auto entryBytes = [&](const std::string& name) {
    const std::filesystem::path probe = dir / ("probe-" + name);
    ModelCache cache({probe});
    cache.load(sample(name), LengthUnit::Millimetre, name);
    const std::uintmax_t bytes = cache.diskBytes();
    std::filesystem::remove_all(probe);
    return bytes;
  };
  const std::uintmax_t block = entryBytes("block"), cylinder = entryBytes("cylinder"), loft = entryBytes("loft");
  ASSERT_GT(block, 0u);
  const std::uintmax_t budget = cylinder + loft + block / 2;  // room for the two most recent
  ModelCache cache({dir / "models", budget});
  cache.load(sample("block"), LengthUnit::Millimetre, "block");
  cache.load(sample("cylinder"), LengthUnit::Millimetre, "cylinder");
  cache.load(sample("loft"), LengthUnit::Millimetre, "loft");
  EXPECT_LE(cache.diskBytes(), budget);
  ModelCache::Outcome o;
  ModelCache({dir / "models", budget}).load(sample("loft"), LengthUnit::Millimetre, "loft", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Disk);
  ModelCache({dir / "models", budget}).load(sample("cylinder"), LengthUnit::Millimetre, "cylinder", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Disk);
  ModelCache({dir / "models", budget}).load(sample("block"), LengthUnit::Millimetre, "block", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Built);  // the least recently used went
}

TEST_F(ModelCacheTest, WithoutADirectoryItKeepsToMemory) {
  ModelCache cache({});
  ModelCache::Outcome o;
  const PartModelPtr a = cache.load(sample("block"), LengthUnit::Millimetre, "block", {}, &o);
  EXPECT_EQ(o.source, ModelCache::Source::Built);
  EXPECT_EQ(cache.load(sample("block"), LengthUnit::Millimetre, "block", {}, &o), a);
  EXPECT_EQ(o.source, ModelCache::Source::Memory);
  EXPECT_THROW(cache.load("not a brep", LengthUnit::Millimetre, "junk"), GeometryError);
}

}  // namespace
}  // namespace hg::geometry
