// Polygon triangulation: convex polygons keep the fan, concave ones (drawn in a tilted plane,
// both orientations, with a hole joined by a doubled edge) are covered exactly once, and
// degenerate or self-intersecting ones still give n - 2 triangles of distinct corners.
#include "io/triangulate.hpp"

#include "indexed_test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

using namespace meshstream;
using Corners2 = std::vector<std::array<double, 2>>;

namespace {

std::vector<uint32_t> triangulate(const std::vector<float>& xyz) {
    io::TriangulateScratch scratch;
    std::vector<uint32_t> triangles;
    io::triangulate_polygon(xyz, scratch, triangles);
    return triangles;
}

std::vector<uint32_t> fan(size_t n) {
    std::vector<uint32_t> out;
    for (uint32_t k = 1; k + 1 < n; ++k) out.insert(out.end(), {0, k, k + 1});
    return out;
}

// n - 2 triangles of three distinct corners < n, each corner used at least once.
void expect_valid(const std::vector<uint32_t>& triangles, size_t n) {
    ASSERT_EQ(triangles.size(), 3 * (n - 2));
    std::vector<bool> used(n);
    for (size_t t = 0; t < triangles.size(); t += 3) {
        const uint32_t a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
        ASSERT_LT(std::max({a, b, c}), n);
        ASSERT_TRUE(a != b && b != c && c != a) << "triangle " << t / 3;
        used[a] = used[b] = used[c] = true;
    }
    EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);
}

void expect_covers_polygon(const test::PlacedPolygon& p) {
    std::vector<uint32_t> triangles = triangulate(p.xyz);
    expect_valid(triangles, p.corners());
    std::vector<float> soup;
    for (uint32_t corner : triangles) soup.insert(soup.end(), &p.xyz[3 * corner], &p.xyz[3 * corner + 3]);
    test::expect_covers_once(soup, p.area, p.normal);
}

Corners2 reversed(Corners2 c) { return {c.rbegin(), c.rend()}; }

Corners2 regular(size_t n, double radius = 1) {
    Corners2 c;
    for (size_t k = 0; k < n; ++k) {
        double a = 2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
        c.push_back({radius * std::cos(a), radius * std::sin(a)});
    }
    return c;
}

}  // namespace

TEST(TriangulatePolygon, TriangleIsItself) {
    EXPECT_EQ(triangulate({0, 0, 0, 1, 0, 0, 0, 1, 0}), (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(triangulate({0, 0, 0, 0, 0, 0, 0, 0, 0}), (std::vector<uint32_t>{0, 1, 2}));
}

TEST(TriangulatePolygon, ConvexPolygonsGiveTheFanFromCorner0) {
    std::vector<Corners2> shapes = {
        {{0, 0}, {1, 0}, {1, 1}, {0, 1}},
        {{0, 0}, {2, 0}, {2, 0.001}, {0, 1}},                              // a near-triangle
        {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}},  // straight corners
        {{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}},                  // repeated corners
    };
    for (size_t n = 5; n <= 64; n += 3) shapes.push_back(regular(n));
    for (const Corners2& shape : shapes)
        for (const Corners2& c : {shape, reversed(shape)}) {
            SCOPED_TRACE(testing::Message() << c.size() << " corners, starting at " << c[0][0] << ", " << c[0][1]);
            test::PlacedPolygon p = test::place_polygon(c);
            EXPECT_EQ(triangulate(p.xyz), fan(p.corners()));
            // Straight on in a coordinate plane too (z = 0, normal along +z or -z).
            std::vector<float> flat;
            for (const auto& q : c) flat.insert(flat.end(), {static_cast<float>(q[0]), static_cast<float>(q[1]), 0});
            EXPECT_EQ(triangulate(flat), fan(c.size()));
        }
    // Non-planar quads as real files have them.
    EXPECT_EQ(triangulate({5, 5, 5, 0, 0, 0, 1, 0, 0, 1, 1, 0}), fan(4));
    EXPECT_EQ(triangulate({0, 0, 0, 1, 0, 0.1f, 1, 1, 0, 0, 1, 0.1f}), fan(4));
}

TEST(TriangulatePolygon, ConcavePolygonsAreCoveredOnce) {
    std::vector<std::pair<const char*, Corners2>> shapes = {
        {"dart", {{0, 0}, {2, 1}, {0, 2}, {0.5, 1}}},
        {"dart, reflex corner 0", {{0.5, 1}, {0, 0}, {2, 1}, {0, 2}}},
        {"L", {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 3}, {0, 3}}},
        {"E", test::e_shape()},
        {"star 5", test::star_shape(5, 0.4)},
        {"star 40", test::star_shape(40, 0.9)},
        {"star 2500", test::star_shape(2500, 0.5)},
    };
    // A comb whose teeth make most corners reflex.
    Corners2 comb = {{0, 0}};
    for (int k = 0; k < 100; ++k) {
        const double x = 2.0 * k;
        comb.insert(comb.end(), {{x + 1, 0}, {x + 1, -5}, {x + 2, -5}, {x + 2, 0}});
    }
    comb.insert(comb.end(), {{201, 0}, {201, 1}, {0, 1}});
    shapes.emplace_back("comb", comb);
    // A spiral band of 3 turns, 400 corners.
    Corners2 spiral, inner;
    for (int k = 0; k < 200; ++k) {
        double a = 0.1 * k, r = 1 + 0.15 * a;
        spiral.push_back({r * std::cos(a), r * std::sin(a)});
        inner.push_back({0.9 * r * std::cos(a), 0.9 * r * std::sin(a)});
    }
    spiral.insert(spiral.end(), inner.rbegin(), inner.rend());
    shapes.emplace_back("spiral", spiral);
    // A square with a square hole, joined to the outline by an edge walked both ways (as
    // LightWave's concave_polygon.obj is): 10 corners, two of them repeated.
    shapes.emplace_back("holed square",
                        Corners2{{0, 0}, {4, 0}, {4, 4}, {3, 3}, {3, 1}, {1, 1}, {1, 3}, {3, 3}, {4, 4}, {0, 4}});
    for (const auto& [name, shape] : shapes)
        for (const Corners2& c : {shape, reversed(shape)}) {
            SCOPED_TRACE(name);
            expect_covers_polygon(test::place_polygon(c));
        }
}

TEST(TriangulatePolygon, DegenerateAndSelfIntersectingPolygonsGiveNMinus2Triangles) {
    std::vector<std::pair<const char*, std::vector<float>>> cases = {
        {"collinear", {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 1.5f, 1.5f, 1.5f}},
        {"one point", {1, 2, 3, 1, 2, 3, 1, 2, 3, 1, 2, 3, 1, 2, 3}},
        {"repeated corners", {0, 0, 0, 0, 0, 0, 2, 0, 0, 2, 0, 0, 1, 1, 0, 1, 1, 0, 1, 3, 0, 0, 1, 0, 0, 1, 0}},
        {"bow-tie", {0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 0}},
        {"spike", {0, 0, 0, 2, 0, 0, 2, 2, 0, 1, 1, 0, 1, 5, 0, 1, 1, 0, 0, 2, 0}},
        {"not finite", {0, 0, 0, 2, 0, 0, NAN, 1, 0, 2, 2, 0, INFINITY, 1, 0, 1, 1, 0, 0, 2, 0}},
    };
    std::vector<float> pentagram;
    for (int k = 0; k < 5; ++k) {
        double a = 2 * std::numbers::pi * (2 * k % 5) / 5;
        pentagram.insert(pentagram.end(), {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0});
    }
    cases.emplace_back("pentagram", pentagram);
    std::mt19937 rng(42);
    std::uniform_real_distribution<float> coordinate(-1, 1);
    std::vector<float> random_flat, random_space;
    for (int k = 0; k < 5000; ++k) {
        random_flat.insert(random_flat.end(), {coordinate(rng), coordinate(rng), 0.5f});
        random_space.insert(random_space.end(), {coordinate(rng), coordinate(rng), coordinate(rng)});
    }
    cases.emplace_back("5000 random corners in a plane", random_flat);
    cases.emplace_back("5000 random corners in space", random_space);
    for (const auto& [name, xyz] : cases) {
        SCOPED_TRACE(name);
        expect_valid(triangulate(xyz), xyz.size() / 3);
    }
}

TEST(TriangulatePolygon, ScratchIsReusedAcrossPolygons) {
    io::TriangulateScratch scratch;
    std::vector<uint32_t> triangles;
    const test::PlacedPolygon big = test::place_polygon(test::star_shape(50, 0.5));
    const test::PlacedPolygon e = test::place_polygon(test::e_shape());
    io::triangulate_polygon(big.xyz, scratch, triangles);
    io::triangulate_polygon(e.xyz, scratch, triangles);  // appends
    ASSERT_EQ(triangles.size(), 3 * (98 + 10));
    EXPECT_EQ(std::vector<uint32_t>(triangles.begin() + 3 * 98, triangles.end()), triangulate(e.xyz));
}
