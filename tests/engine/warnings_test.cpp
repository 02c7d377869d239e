// engine::Warnings: counted kinds add up, one-off notes are kept once, merge() keeps both, and
// the order is stable (by text).
#include "engine/warnings.hpp"

#include <gtest/gtest.h>

namespace meshstream {
namespace {

TEST(EngineWarnings, CountsNotesAndMerges) {
    engine::Warnings a;
    a.add("degenerate_triangles", "degenerate triangles skipped", 3);
    a.add("degenerate_triangles", "degenerate triangles skipped", 2);
    a.note("channels_dropped", "colours dropped: stl output carries positions only");
    a.note("channels_dropped", "colours dropped: stl output carries positions only");
    engine::Warnings b;
    b.add("degenerate_triangles", "degenerate triangles skipped", 1);
    b.note("no_triangles", "the input holds no triangles");
    a.merge(b);
    const std::vector<engine::Warnings::Line> all = a.all();
    ASSERT_EQ(all.size(), 3u);
    EXPECT_EQ(all[0].text, "colours dropped: stl output carries positions only");
    EXPECT_EQ(all[0].count, 0u);
    EXPECT_EQ(all[1].code, "degenerate_triangles");
    EXPECT_EQ(all[1].count, 6u);
    EXPECT_EQ(all[2].code, "no_triangles");
    EXPECT_EQ(a.lines()[1], "degenerate triangles skipped (6)");
}

}  // namespace
}  // namespace meshstream
