// Tests of decimate/quadric: plane quadrics are √area × squared distance, and the 3×3 minimum
// solve finds plane intersections and refuses singular systems.
#include "decimate/quadric.hpp"

#include <gtest/gtest.h>

#include <cmath>

using meshstream::decimate::Quadric;

TEST(Quadric, ErrorIsSquareRootOfAreaTimesSquaredDistance) {
    const double a[3] = {0, 0, 0}, b[3] = {2, 0, 0}, c[3] = {0, 2, 0};  // area 2, plane z = 0
    const Quadric q = Quadric::from_triangle(a, b, c);
    const double on[3] = {5, -3, 0}, above[3] = {1, 1, 3};
    EXPECT_NEAR(q.error(on), 0.0, 1e-12);
    EXPECT_NEAR(q.error(above), std::sqrt(2.0) * 9.0, 1e-12);
}

TEST(Quadric, DegenerateTriangleGivesZeroQuadric) {
    const double a[3] = {0, 0, 0}, b[3] = {1, 1, 1}, c[3] = {2, 2, 2};
    const Quadric q = Quadric::from_triangle(a, b, c);
    const double x[3] = {4, 5, 6};
    EXPECT_EQ(q.error(x), 0.0);
}

TEST(Quadric, MinimumOfThreePlanesIsTheirIntersection) {
    // Planes x = 1, y = 2, z = 3 (each from a triangle lying in it).
    const double x0[3] = {1, 0, 0}, x1[3] = {1, 1, 0}, x2[3] = {1, 0, 1};
    const double y0[3] = {0, 2, 0}, y1[3] = {0, 2, 1}, y2[3] = {1, 2, 0};
    const double z0[3] = {0, 0, 3}, z1[3] = {1, 0, 3}, z2[3] = {0, 1, 3};
    const Quadric q =
        Quadric::from_triangle(x0, x1, x2) + Quadric::from_triangle(y0, y1, y2) + Quadric::from_triangle(z0, z1, z2);
    double m[3] = {0, 0, 0};
    ASSERT_TRUE(q.minimum(m));
    EXPECT_NEAR(m[0], 1, 1e-12);
    EXPECT_NEAR(m[1], 2, 1e-12);
    EXPECT_NEAR(m[2], 3, 1e-12);
    EXPECT_NEAR(q.error(m), 0, 1e-12);
}

TEST(Quadric, SingularSystemIsRefusedAndLeavesOutputUntouched) {
    // Two parallel-normal triangles in the same plane: the minimum is a whole plane.
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {1, 1, 0};
    const Quadric q = Quadric::from_triangle(a, b, c) + Quadric::from_triangle(b, d, c);
    double m[3] = {7, 8, 9};
    EXPECT_FALSE(q.minimum(m));
    EXPECT_EQ(m[0], 7);
    EXPECT_EQ(m[2], 9);
    // Two planes (a crease): a line of minima, also singular.
    const double e[3] = {0, 0, 1}, f[3] = {0, 1, 1};
    const Quadric crease = q + Quadric::from_triangle(a, f, e);
    EXPECT_FALSE(crease.minimum(m));
}
