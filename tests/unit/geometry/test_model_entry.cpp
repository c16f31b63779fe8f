// A checked part as bytes: what the model cache stores and the loader process answers gives
// back the part it was made from, and no damaged copy is ever taken for a part.
#include "hapticgrasp/geometry/model_entry.hpp"

#include <gtest/gtest.h>

#include "geometry/part_answers.hpp"

namespace hg::geometry {
namespace {

using test::expectSameAnswers;

TEST(ModelEntry, APartComesBackAnsweringAsTheOneItWasMadeFrom) {
  for (const std::string name : {"block", "cylinder", "loft"}) {
    const PartModelPtr loaded = PartModel::fromBrepText(test::sample(name), LengthUnit::Millimetre, name);
    std::string why;
    const PartModelPtr restored = partFromEntry(entryBytes(*loaded), name, why);
    ASSERT_TRUE(restored) << name << ": " << why;
    EXPECT_EQ(restored->name(), name);
    expectSameAnswers(loaded, restored);
  }
}

TEST(ModelEntry, ADefectivePartKeepsItsVerdict) {
  const PartModelPtr loaded =
      PartModel::fromBrepText(test::corpus("defect_crossing_faces"), LengthUnit::Millimetre, "defect");
  ASSERT_NE(loaded->backendChoice().backend, Backend::Exact);
  std::string why;
  const PartModelPtr restored = partFromEntry(entryBytes(*loaded), "defect", why);
  ASSERT_TRUE(restored) << why;
  expectSameAnswers(loaded, restored);
}

TEST(ModelEntry, TheLoadsTimingIsReportedWhenGiven) {
  const PartModelPtr loaded = PartModel::fromBrepText(test::sample("cylinder"), LengthUnit::Millimetre, "c");
  std::string why;
  const PartLoadTiming timing{1.5, 2.5, 4.5};
  const PartModelPtr restored = partFromEntry(entryBytes(*loaded), "c", why, &timing);
  ASSERT_TRUE(restored) << why;
  EXPECT_EQ(restored->loadTiming().read_s, 1.5);
  EXPECT_EQ(restored->loadTiming().check_s, 2.5);
  EXPECT_GE(restored->loadTiming().total_s, 4.5);  // plus the restore's own
  const PartModelPtr untimed = partFromEntry(entryBytes(*loaded), "c", why);
  EXPECT_EQ(untimed->loadTiming().check_s, 0.0);
  EXPECT_LT(untimed->loadTiming().total_s, 1.0);
}

// Every cut and every 61st byte flipped: refused with the reason, never a part, never a crash.
TEST(ModelEntry, NoDamagedCopyIsTakenForAPart) {
  const std::string bytes =
      entryBytes(*PartModel::fromBrepText(test::sample("cylinder"), LengthUnit::Millimetre, "c"));
  std::string why;
  for (std::size_t cut = 0; cut < bytes.size(); cut += 53) {
    EXPECT_FALSE(partFromEntry(std::string_view(bytes).substr(0, cut), "c", why)) << cut;
    EXPECT_EQ(why, cut < 24 ? "not a model cache entry" : "checksum mismatch") << cut;
  }
  for (std::size_t at = 0; at < bytes.size(); at += 61) {
    std::string damaged = bytes;
    damaged[at] ^= 0x04;
    EXPECT_FALSE(partFromEntry(damaged, "c", why)) << at;
    EXPECT_FALSE(why.empty());
  }
  EXPECT_FALSE(partFromEntry("garbage", "c", why));
  EXPECT_EQ(why, "not a model cache entry");
}

}  // namespace
}  // namespace hg::geometry
