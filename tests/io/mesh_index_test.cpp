// MeshIndexer tests: exact welding (-0 == +0), vertex-id mode, dropped index-degenerate
// triangles, non-finite refusal with the triangle's index, growth past the initial table, and
// unit-length area-weighted normals.
#include "io/mesh_index.hpp"

#include "io/error.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace io = meshstream::io;

namespace {

io::TriangleChunk chunk_of(std::initializer_list<std::array<float, 9>> tris, io::Channels ch = {}) {
    io::TriangleChunk c(tris.size() + 1, ch);
    for (const auto& t : tris) {
        float a[9];
        std::copy(t.begin(), t.end(), a);
        c.push(a);
    }
    return c;
}

TEST(MeshIndexer, WeldsExactPositionsTreatingMinusZeroAsZero) {
    io::MeshIndexer ix("out.glb");
    ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {-0.0f, 0, 0, 1, 1, 0, 0, 1, 0}}));
    EXPECT_EQ(ix.vertex_count(), 4u);
    io::IndexedMesh m = ix.take();
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(MeshIndexer, UsesVertexIdsWhenPresent) {
    io::MeshIndexer ix("out.glb");
    io::TriangleChunk c = chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}}, io::Channels::ids_only());
    const uint64_t ids[6] = {7, 8, 9, 17, 9, 18};  // corner 1 of triangle 1 shares id 9
    for (int t = 0; t < 2; ++t)
        for (int k = 0; k < 3; ++k) c.id_at(t)[k] = ids[3 * t + k];
    ix.add(c);
    EXPECT_EQ(ix.vertex_count(), 5u);  // ids 7, 8, 9, 17, 18 (not welded by position)
    EXPECT_THROW(ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}})), io::Error);  // channel vanished
}

TEST(MeshIndexer, DropsTrianglesThatWeldToAnEdge) {
    io::MeshIndexer ix("out.glb");
    ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 0, 0, 0}, {0, 0, 0, 1, 0, 0, 1, 1, 0}}));
    EXPECT_EQ(ix.input_triangle_count(), 2u);
    EXPECT_EQ(ix.dropped_triangle_count(), 1u);
    EXPECT_EQ(ix.triangle_count(), 1u);
}

TEST(MeshIndexer, RefusesNonFiniteNamingTheTriangle) {
    io::MeshIndexer ix("out.glb");
    ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}}));
    try {
        ix.add(chunk_of({{0, 0, 0, INFINITY, 0, 0, 1, 1, 0}}));
        FAIL();
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), "out.glb");
        EXPECT_NE(std::string(e.what()).find("triangle 1 has a non-finite coordinate"), std::string::npos) << e.what();
    }
}

TEST(MeshIndexer, GrowsPastTheInitialTable) {
    // A 100 x 100 grid: 10201 distinct vertices, each shared by up to six triangles.
    io::MeshIndexer ix("grid.drc");
    io::TriangleChunk c(64);
    for (int y = 0; y < 100; ++y)
        for (int x = 0; x < 100; ++x) {
            float a[9] = {float(x), float(y), 0, float(x + 1), float(y), 0, float(x + 1), float(y + 1), 0};
            float b[9] = {float(x), float(y), 0, float(x + 1), float(y + 1), 0, float(x), float(y + 1), 0};
            for (const float* t : {a, b}) {
                if (c.full()) {
                    ix.add(c);
                    c.clear();
                }
                float tri[9];
                std::copy(t, t + 9, tri);
                c.push(tri);
            }
        }
    ix.add(c);
    EXPECT_EQ(ix.vertex_count(), 101u * 101u);
    EXPECT_EQ(ix.triangle_count(), 20000u);
    io::IndexedMesh m = ix.take();
    std::vector<float> n = m.smooth_normals();
    ASSERT_EQ(n.size(), m.positions.size());
    for (size_t i = 0; i < n.size(); i += 3) {
        EXPECT_FLOAT_EQ(n[i + 2], 1.0f);  // flat, counter-clockwise seen from +z
        EXPECT_FLOAT_EQ(std::hypot(n[i], n[i + 1], n[i + 2]), 1.0f);
    }
    io::Bounds b = m.bounds();
    EXPECT_EQ(b.max[0], 100.0f);
    EXPECT_EQ(b.min[1], 0.0f);
}

// A count near 2^64 (a broken header) made the estimate wrap: "need at least 16777216 TiB …
// give --memory 0M or more".
TEST(BudgetCheck, AnAbsurdCountIsRefusedWithALowerBoundThatDoesNotWrap) {
    io::WriteOptions options;
    options.memory_budget_bytes = uint64_t{256} << 20;
    options.triangle_count = uint64_t{1} << 62;
    auto need = [](uint64_t vertices, uint64_t triangles, const io::WriteOptions&) {
        return vertices * 96 + triangles * 76;
    };
    try {
        io::budget_check_up_front("big.glb", options, "why", need);
        ADD_FAILURE() << "accepted";
    } catch (const io::Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("the 4611686018427387904 triangles to be written need at least 124 TiB"), std::string::npos)
            << what;
        EXPECT_NE(what.find("give --memory 130023424M or more"), std::string::npos) << what;
    }
}

}  // namespace
