// Tests of decimate/schedule: the closed-form §4.1 schedule reproduces the paper's loop counts.
#include "decimate/schedule.hpp"

#include "decimate/stream_decimator.hpp"

#include <gtest/gtest.h>

using namespace meshstream::decimate;

TEST(Schedule, InitializationDecimatesToHalfWithoutWriting) {
    // N_max = 1000, p = 0.1: after reading 1000 triangles the budget is 100 < 500.
    const RoomPlan plan = plan_full_buffer(1000, 0.1, 1000, 0);
    EXPECT_EQ(plan.decimate_to, 500u);
    EXPECT_EQ(plan.write_to, 500u);
}

TEST(Schedule, MainLoopMatchesPaperCounts) {
    // Steady state: the buffer held N_max/2 at resolution p, N_max/2 more were read.
    // The paper: DECIMATE((1-p) N_max/4) collapses, i.e. down to N_max/2 + p N_max/2, then
    // WRITE(p N_max/2).
    const size_t n_max = kDefaultBufferTriangles;
    const double p = 0.1;
    const uint64_t n_out = 123456;
    const uint64_t n_in_before = static_cast<uint64_t>((n_out + n_max / 2) / p);  // R = p
    const RoomPlan plan = plan_full_buffer(n_max, p, n_in_before + n_max / 2, n_out);
    const size_t collapses = (n_max - plan.decimate_to) / 2;
    EXPECT_NEAR(double(collapses), (1 - p) * n_max / 4, 1.0);
    EXPECT_NEAR(double(plan.decimate_to - plan.write_to), p * n_max / 2, 1.0);
    EXPECT_EQ(plan.write_to, n_max / 2);
}

TEST(Schedule, WritingKeepsTheResolutionLevel) {
    const double p = 0.25;
    const double r0 = resolution_level(p, 500, 2000, 0);  // 500 in core stand for 2000 read
    EXPECT_DOUBLE_EQ(r0, p);
    // Writing 100 keeps R = p.
    EXPECT_DOUBLE_EQ(resolution_level(p, 400, 2000, 100), p);
    EXPECT_DOUBLE_EQ(resolution_budget(p, 2000, 100), 400.0);
}

TEST(Schedule, FinalLoopLandsOnRoundedTarget) {
    EXPECT_EQ(final_triangle_count(0.1, 69451), 6945u);
    EXPECT_EQ(final_triangle_count(0.01, 69451), 695u);
    EXPECT_EQ(final_triangle_count(1.0, 7), 7u);
    EXPECT_EQ(final_budget(6945, 6000), 945u);
    EXPECT_EQ(final_budget(6945, 7000), 0u);  // over-written (forced writes): write the rest
}

TEST(Schedule, DecimateTargetNeverExceedsCapacity) {
    const RoomPlan plan = plan_full_buffer(1000, 1.0, 5000, 0);  // p = 1: nothing to decimate
    EXPECT_EQ(plan.decimate_to, 1000u);
    EXPECT_EQ(plan.write_to, 500u);
}

TEST(Schedule, ARangeEndsWithOneFaceForEachVertexOnPin) {
    // A range that read 100 000 triangles at 10 % and wrote 9 000 holds 3 000 faces on P_in
    // around 2 300 vertices on P_in (a seam strip: about one face a vertex on each side of it,
    // plus the faces reaching the decimated side). The seam pass removes one face with each
    // such vertex, so the range keeps 2 300 for them, not 0.9 · 3 000.
    EXPECT_DOUBLE_EQ(part_budget(0.1, 100000, 9000, 3000), 1000.0 + 2700.0);
    EXPECT_DOUBLE_EQ(range_end_budget(0.1, 100000, 9000, 3000, 2300), 1000.0 + 2300.0);
    // Never above part_budget: vertices on P_in with few faces (a strip one face wide).
    EXPECT_DOUBLE_EQ(range_end_budget(0.1, 100000, 9000, 3000, 3500), part_budget(0.1, 100000, 9000, 3000));
    // Nothing on P_in: the ratio.
    EXPECT_DOUBLE_EQ(range_end_budget(0.1, 100000, 9000, 0, 0), 1000.0);
}
