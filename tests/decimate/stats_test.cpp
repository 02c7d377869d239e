// Tests of decimate/stats: every field of Stats has one rule, combine_ranges applies each field's
// rule, and the seam pass's buffer follows the ranges' buffer.
#include "decimate/stats.hpp"

#include "decimate/field_count.hpp"
#include "decimate/stream_decimator.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <stdexcept>
#include <type_traits>
#include <vector>

using namespace meshstream::decimate;

namespace {

// Field k of the result gets base + k (bool: true); combine_ranges' output then tells which
// inputs each field came from.
Stats numbered(uint64_t base) {
    Stats s;
    uint64_t k = 0;
    for_each_stats_field([&](auto field, auto) {
        using T = std::remove_reference_t<decltype(s.*field)>;
        s.*field = std::is_same_v<T, bool> ? T(true) : T(base + k);
        ++k;
    });
    return s;
}

template <typename T>
size_t offset_of(T Stats::*field) {
    static const Stats s;
    return size_t(reinterpret_cast<const char*>(&(s.*field)) - reinterpret_cast<const char*>(&s));
}

}  // namespace

TEST(Stats, EveryFieldHasExactlyOneRule) {
    // A field added to Stats without a rule: the counts differ (stats.cpp also refuses to build).
    EXPECT_EQ(field_count<Stats>(), stats_rule_count());
    // The rules name distinct fields, in declaration order: with the counts equal, each field once.
    std::vector<size_t> offsets;
    for_each_stats_field([&](auto field, auto) { offsets.push_back(offset_of(field)); });
    ASSERT_EQ(offsets.size(), stats_rule_count());
    for (size_t i = 1; i < offsets.size(); ++i) EXPECT_LT(offsets[i - 1], offsets[i]) << "rule " << i;
}

TEST(Stats, FieldCountSeesEachScalar) {
    struct Three {
        int a;
        bool b;
        double c;
    };
    struct None {};
    EXPECT_EQ(field_count<Three>(), 3u);
    EXPECT_EQ(field_count<None>(), 0u);
}

TEST(Stats, CombineRangesAppliesEachFieldsRule) {
    Stats seams = numbered(100);
    // Three ranges: the first is neither the largest nor the last.
    std::vector<Stats> ranges = {numbered(200), numbered(400), numbered(300)};
    for (Stats& r : ranges) r.no_valid_collapse_left = false;
    const Stats whole = combine_ranges(seams, ranges, 50000);
    // Every field, named here: one left out keeps 0 and the comparison fails. Field k of the seam
    // pass is 100 + k, of the ranges 200 + k, 400 + k and 300 + k.
    const Stats expected{
        .triangles_in = 900,                 // ranges' sum
        .triangles_out = 101,                // seam pass's
        .target_triangles = 102,             // seam pass's
        .buffer_capacity = 50000,            // the ranges' buffer
        .peak_buffer_triangles = 404,        // ranges' largest
        .peak_vertices = 405,                // ranges' largest
        .collapses = 1024,                   // seam pass's plus ranges'
        .forced_writes = 921,                // ranges' sum
        .premature_writes = 924,             // ranges' sum
        .degenerate_passed = 927,            // ranges' sum
        .weld_dropped = 1040,                // seam pass's plus ranges'
        .nonmanifold_edges = 933,            // ranges' sum
        .boundary_edges = 112,               // seam pass's
        .vertices_merged = 939,              // ranges' sum
        .vertices_finalized_by_sweep = 942,  // ranges' sum
        .sweep_direction = 215,              // first range's
        .sort_violations = 948,              // ranges' sum
        .orphans_evicted = 1068,             // seam pass's plus ranges'
        .vertices_moved = 1072,              // seam pass's plus ranges'
        .seam_vertices = 1076,               // seam pass's plus ranges'
        .attribute_values_zeroed = 1080,     // seam pass's plus ranges'
        .no_valid_collapse_left = true,      // seam pass's
    };
    EXPECT_TRUE(whole == expected);
    for_each_stats_field(
        [&](auto field, auto) { EXPECT_EQ(whole.*field, expected.*field) << "field at offset " << offset_of(field); });
    seams.no_valid_collapse_left = false;
    for (Stats& r : ranges) r.no_valid_collapse_left = true;
    EXPECT_FALSE(combine_ranges(seams, ranges, 50000).no_valid_collapse_left);
}

TEST(Stats, OneRangeCombinesWithTheSeamPass) {
    const Stats seams = numbered(10);
    const std::vector<Stats> one = {numbered(1000)};
    const Stats whole = combine_ranges(seams, one, 16);
    EXPECT_EQ(whole.triangles_in, 1000u);
    EXPECT_EQ(whole.triangles_out, 11u);
    EXPECT_EQ(whole.buffer_capacity, 16u);
    EXPECT_EQ(whole.peak_buffer_triangles, 1004u);
    EXPECT_EQ(whole.collapses, 10u + 6 + 1000 + 6);
    EXPECT_EQ(whole.sweep_direction, 1015);
}

TEST(Stats, CombineRangesNeedsARange) { EXPECT_THROW(combine_ranges(Stats{}, {}, 1000), std::invalid_argument); }

TEST(Stats, SeamPassBufferIsAQuarterButAllOfSmallBuffers) {
    EXPECT_EQ(seam_pass_buffer(kDefaultBufferTriangles), kDefaultBufferTriangles / 4);
    EXPECT_EQ(seam_pass_buffer(4 * kSeamBufferTriangles), kSeamBufferTriangles);
    EXPECT_EQ(seam_pass_buffer(4 * kSeamBufferTriangles - 4), kSeamBufferTriangles);  // not below
    EXPECT_EQ(seam_pass_buffer(100000), kSeamBufferTriangles);
    EXPECT_EQ(seam_pass_buffer(kSeamBufferTriangles), kSeamBufferTriangles);
    EXPECT_EQ(seam_pass_buffer(20000), 20000u);
    EXPECT_EQ(seam_pass_buffer(16), 16u);
}

TEST(Stats, OptionsDefaultToTheNamedBuffer) {
    EXPECT_EQ(Options{}.buffer_triangles, kDefaultBufferTriangles);
    EXPECT_EQ(kDefaultBufferTriangles, 400000u);
}
