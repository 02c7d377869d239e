// Helpers for the indexed-format tests (PLY, OBJ, welding): a per-test temp directory,
// reading a whole file into flat arrays through the registry, writing triangles through a
// format, and a generated grid surface.
#pragma once

#include "test_util.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/format.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

namespace meshstream::test {

inline std::string fixture(const std::string& name) { return std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name; }

// A fresh directory under the system temp dir, removed with its contents at scope exit.
struct Soup {
    std::vector<float> xyz;     // 9 per triangle
    std::vector<uint8_t> rgb;   // 9 per triangle: rgba as 8 bits, without alpha
    std::vector<float> rgba;    // 12 per triangle when the reader gives colour
    std::vector<uint64_t> ids;  // 3 per triangle when the reader gives vertex ids
    io::MeshHeader header;
    size_t triangles() const { return xyz.size() / 9; }
};

inline Soup read_soup(const std::string& path, size_t capacity = io::TriangleChunk::kDefaultCapacity,
                      io::ReadOptions options = {}, std::string_view from = {}) {
    io::Input in = io::open_input(path, from, options);
    Soup s;
    s.header = in.reader->header();
    io::TriangleChunk chunk(capacity, s.header.channels);
    while (in.reader->next(chunk)) {
        EXPECT_FALSE(chunk.empty());
        s.xyz.insert(s.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        s.rgba.insert(s.rgba.end(), chunk.colors().begin(), chunk.colors().end());
        for (size_t c = 0; c < chunk.colors().size(); ++c)  // RGB as 8 bits, alpha left out
            if (c % 4 != 3) s.rgb.push_back(uint8_t(std::lround(std::clamp(chunk.colors()[c], 0.0f, 1.0f) * 255.0f)));
        s.ids.insert(s.ids.end(), chunk.vertex_ids().begin(), chunk.vertex_ids().end());
    }
    EXPECT_TRUE(chunk.empty());
    EXPECT_FALSE(in.reader->next(chunk));  // stays exhausted
    return s;
}

// The io::Error that reading `path` throws; a test failure (and a placeholder error) if none.
inline io::Error read_error(const std::string& path) {
    try {
        read_soup(path);
    } catch (const io::Error& e) {
        return e;
    }
    ADD_FAILURE() << path << ": no io::Error";
    return io::Error(path, "no error");
}

// Writes `xyz` (9 floats a triangle), in chunks of `capacity`, as format `to` (empty: by name).
inline void write_soup(const std::string& path, const std::vector<float>& xyz, std::string_view to = {},
                       io::WriteOptions options = {}, size_t capacity = 1000) {
    io::Output out = io::open_output(path, to, options);
    io::TriangleChunk chunk(capacity);
    for (size_t t = 0; t < xyz.size() / 9; ++t) {
        if (chunk.full()) {
            out.write(chunk);
            chunk.clear();
        }
        float tri[9];
        std::copy(xyz.begin() + 9 * t, xyz.begin() + 9 * t + 9, tri);
        chunk.push(tri);
    }
    if (!chunk.empty()) out.write(chunk);
    out.finish();
}

// Converts `from` to `to` through the registry (like `meshstream convert`).
inline void convert(const std::string& from, const std::string& to, std::string_view to_format = {},
                    uint64_t budget = uint64_t{256} << 20, size_t capacity = io::TriangleChunk::kDefaultCapacity) {
    io::ReadOptions ro;
    ro.memory_budget_bytes = budget;
    io::Input in = io::open_input(from, {}, ro);
    io::WriteOptions wo;
    wo.memory_budget_bytes = budget;
    wo.sorted_axis = in.reader->header().sorted_axis;
    io::Output out = io::open_output(to, to_format, wo);
    io::TriangleChunk chunk(capacity, in.reader->header().channels);
    while (in.reader->next(chunk)) out.write(chunk);
    out.finish();
}

// A wavy n × n vertex grid: 2 (n-1)^2 triangles sharing vertices, with irregular floats.
inline std::vector<float> grid_soup(int n) {
    auto z = [](int i, int j) { return 0.001f * static_cast<float>((i * 7919 + j * 104729) % 1000) - 0.37f; };
    std::vector<float> out;
    out.reserve(size_t(2) * (n - 1) * (n - 1) * 9);
    auto put = [&](int i, int j) {
        out.push_back(static_cast<float>(i) * 0.1f + 1e-3f);
        out.push_back(static_cast<float>(j) * 0.3f - 7.0f);
        out.push_back(z(i, j));
    };
    for (int i = 0; i + 1 < n; ++i)
        for (int j = 0; j + 1 < n; ++j) {
            put(i, j), put(i + 1, j), put(i + 1, j + 1);
            put(i, j), put(i + 1, j + 1), put(i, j + 1);
        }
    return out;
}

// A polygon drawn in the plane and placed on a tilted plane away from the origin: its corners in
// space, its area (the shoelace formula, computed in the plane before placing) and the unit
// normal of its orientation.
struct PlacedPolygon {
    std::vector<float> xyz;  // 3 per corner
    double area = 0;
    std::array<double, 3> normal{};
    size_t corners() const { return xyz.size() / 3; }
};

inline PlacedPolygon place_polygon(const std::vector<std::array<double, 2>>& uv) {
    // e1 = (2, 1, 2) / 3 and e2 = (-1, 2, 0) / sqrt 5 are orthonormal; normal = e1 x e2.
    const double s5 = std::sqrt(5.0);
    const double e1[3] = {2.0 / 3, 1.0 / 3, 2.0 / 3}, e2[3] = {-1 / s5, 2 / s5, 0};
    const double origin[3] = {10, -3, 5};
    PlacedPolygon p;
    for (size_t i = 0; i < uv.size(); ++i) {
        for (int a = 0; a < 3; ++a)
            p.xyz.push_back(static_cast<float>(origin[a] + uv[i][0] * e1[a] + uv[i][1] * e2[a]));
        const auto& q = uv[(i + 1) % uv.size()];
        p.area += (uv[i][0] * q[1] - q[0] * uv[i][1]) / 2;
    }
    p.normal = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    if (p.area < 0) {  // clockwise in the plane: the polygon faces the other way
        p.area = -p.area;
        for (double& c : p.normal) c = -c;
    }
    return p;
}

// Twice the vector area of the triangle at t[0..8] (its normal scaled by twice its area).
inline std::array<double, 3> doubled_vector_area(const float* t) {
    double u[3], v[3];
    for (int a = 0; a < 3; ++a) {
        u[a] = double{t[3 + a]} - t[a];
        v[a] = double{t[6 + a]} - t[a];
    }
    return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}

// Expects the triangles `xyz` (9 floats each) to cover a polygon of `area` facing `normal`
// exactly once: each triangle faces the polygon's way (or is degenerate) and their unsigned
// areas add up to the polygon's (a fold or an overlap would add more).
inline void expect_covers_once(const std::vector<float>& xyz, double area, const std::array<double, 3>& normal,
                               double relative_tolerance = 1e-5) {
    double sum = 0;
    for (size_t t = 0; t < xyz.size() / 9; ++t) {
        std::array<double, 3> d = doubled_vector_area(&xyz[9 * t]);
        double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        sum += length / 2;
        EXPECT_GE(d[0] * normal[0] + d[1] * normal[1] + d[2] * normal[2], -1e-6 * length) << "triangle " << t;
    }
    EXPECT_NEAR(sum, area, relative_tolerance * area);
}

// Expects `s` to hold `polygons` in order, each as its n - 2 triangles covering it once, with
// vertex ids numbering the polygons' corners one after the other from 0 and each corner at
// the position of its id.
inline void expect_polygons(const Soup& s, const std::vector<PlacedPolygon>& polygons) {
    size_t t = 0;
    uint64_t first = 0;
    for (const PlacedPolygon& p : polygons) {
        const size_t n = p.corners();
        ASSERT_LE(9 * (t + n - 2), s.xyz.size());
        expect_covers_once({s.xyz.begin() + 9 * t, s.xyz.begin() + 9 * (t + n - 2)}, p.area, p.normal);
        for (size_t c = 3 * t; c < 3 * (t + n - 2); ++c) {
            ASSERT_GE(s.ids[c], first);
            ASSERT_LT(s.ids[c], first + n);
            for (int a = 0; a < 3; ++a) EXPECT_EQ(s.xyz[3 * c + a], p.xyz[3 * (s.ids[c] - first) + a]);
        }
        t += n - 2;
        first += n;
    }
    EXPECT_EQ(s.triangles(), t);
}

// Hand-made concave polygons: an E (12 corners, area 11) and a star with `points` tips whose
// corners alternate between radius 1 and `inner`.
inline std::vector<std::array<double, 2>> e_shape() {
    return {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 2}, {3, 2}, {3, 3}, {1, 3}, {1, 4}, {3, 4}, {3, 5}, {0, 5}};
}

inline std::vector<std::array<double, 2>> star_shape(size_t points, double inner) {
    std::vector<std::array<double, 2>> c;
    for (size_t k = 0; k < 2 * points; ++k) {
        double a = std::numbers::pi * static_cast<double>(k) / static_cast<double>(points);
        double r = k % 2 ? inner : 1;
        c.push_back({r * std::cos(a), r * std::sin(a)});
    }
    return c;
}

}  // namespace meshstream::test
