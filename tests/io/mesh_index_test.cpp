// MeshIndexer tests: exact welding (-0 == +0), vertex-id mode, vertices keyed by their attribute
// record too (seams stay apart), degenerate triangles kept, non-finite ones dropped and counted
// (refused under strict, naming the triangle), parts by material, growth past the initial table,
// tables reserved for a known count, and unit-length area-weighted normals shared across seams.
#include "io/mesh_index.hpp"

#include "io/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

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
    io::MeshIndexer ix("out.glb", "glTF", {}, false);
    ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {-0.0f, 0, 0, 1, 1, 0, 0, 1, 0}}));
    EXPECT_EQ(ix.vertex_count(), 4u);
    io::IndexedMesh m = ix.take();
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(MeshIndexer, UsesVertexIdsWhenPresent) {
    io::MeshIndexer ix("out.glb", "glTF", io::Channels::ids_only(), false);
    io::TriangleChunk c =
        chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}}, io::Channels::ids_only());
    const uint64_t ids[6] = {7, 8, 9, 17, 9, 18};  // corner 1 of triangle 1 shares id 9
    for (int t = 0; t < 2; ++t)
        for (int k = 0; k < 3; ++k) c.id_at(t)[k] = ids[3 * t + k];
    ix.add(c);
    EXPECT_EQ(ix.vertex_count(), 5u);  // ids 7, 8, 9, 17, 18 (not welded by position)
    EXPECT_THROW(ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}})), io::Error);  // channel vanished
}

TEST(MeshIndexer, KeysVerticesOnTheirAttributesToo) {
    // A quad whose two triangles meet along a seam: the shared corners have one position but
    // different texture coordinates (and, in the second chunk, one uv but different normals).
    io::Channels ch;
    ch.uv_sets = 1;
    ch.normal = true;
    io::MeshIndexer ix("out.glb", "glTF", ch, false);
    io::TriangleChunk c = chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}}, ch);
    const float uv[2][6] = {{0, 0, 1, 0, 1, 1}, {0.5f, 0, 1, 1, 0, 1}};  // corner 0 differs, corner 1 (1,1,0) agrees
    for (int t = 0; t < 2; ++t) {
        std::copy(uv[t], uv[t] + 6, c.uv_at(t, 0));
        for (int k = 0; k < 3; ++k) c.normal_at(t)[3 * k + 2] = 1;
    }
    ix.add(c);
    EXPECT_EQ(ix.vertex_count(), 5u);  // (0,0,0) twice: its uv differs
    io::IndexedMesh m = ix.take();
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2, 3, 2, 4}));
    ASSERT_EQ(m.attributes.size(), 5 * io::CornerLayout(ch).bytes());
    io::VertexValues v = m.values(std::vector<uint32_t>{3});
    EXPECT_EQ(v.uvs[0], (std::vector<float>{0.5f, 0}));
    EXPECT_EQ(v.normals, (std::vector<float>{0, 0, 1}));
    // Smooth normals are summed per position, across the seam: both (0,0,0) get the same.
    const std::vector<float> n = m.smooth_normals();
    EXPECT_EQ(std::vector<float>(n.begin(), n.begin() + 3), std::vector<float>(n.begin() + 9, n.begin() + 12));
}

TEST(MeshIndexer, KeepsDegenerateTrianglesInOrder) {
    // glTF holds them; the Draco writer drops them itself (and says so).
    io::MeshIndexer ix("out.glb", "glTF", {}, false);
    ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 0, 0, 0}, {0, 0, 0, 1, 0, 0, 1, 1, 0}, {2, 2, 2, 2, 2, 2, 2, 2, 2}}));
    EXPECT_EQ(ix.input_triangle_count(), 3u);
    EXPECT_EQ(ix.triangle_count(), 3u);
    io::IndexedMesh m = ix.take();
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 0, 0, 1, 2, 3, 3, 3}));
}

TEST(MeshIndexer, DropsNonFiniteTrianglesOrRefusesThemUnderStrict) {
    io::MeshIndexer ix("out.glb", "glTF", {}, false);
    ix.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, NAN, 0, 0, 1, 1, 0}, {0, 0, 1, 1, 0, 1, 1, 1, 1}}));
    EXPECT_EQ(ix.input_triangle_count(), 3u);
    EXPECT_EQ(ix.non_finite_count(), 1u);
    EXPECT_EQ(ix.triangle_count(), 2u);
    ASSERT_EQ(ix.notes().size(), 1u);
    EXPECT_EQ(io::render(ix.notes()[0]),
              "1 of the 3 triangles have a NaN or infinite coordinate, which glTF cannot store: left "
              "out (strict mode makes this an error)");
    io::MeshIndexer strict("out.drc", "Draco", {}, true);
    strict.add(chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}}));
    try {
        strict.add(chunk_of({{0, 0, 0, INFINITY, 0, 0, 1, 1, 0}}));
        FAIL();
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), "out.drc");
        EXPECT_NE(std::string(e.what()).find("triangle 1 has a NaN or infinite coordinate, which Draco cannot store "
                                             "(strict mode)"),
                  std::string::npos)
            << e.what();
    }
}

TEST(MeshIndexer, NonFiniteAttributeValuesAreWrittenAsZeroAndCounted) {
    io::Channels ch;
    ch.uv_sets = 1;
    io::MeshIndexer ix("out.glb", "glTF", ch, false);
    io::TriangleChunk c = chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}}, ch);
    c.uv_at(0, 0)[3] = NAN;
    ix.add(c);
    io::IndexedMesh m = ix.take();
    EXPECT_EQ(ix.non_finite_attribute_count(), 1u);
    EXPECT_EQ(m.values(std::vector<uint32_t>{1}).uvs[0], (std::vector<float>{0, 0}));
}

TEST(MeshIndexer, PartsSplitTrianglesByMaterialWithTheirOwnVertices) {
    io::Channels ch;
    ch.material = true;
    io::MeshIndexer ix("out.glb", "glTF", ch, false);
    io::TriangleChunk c =
        chunk_of({{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, 0, 1, 0}, {5, 5, 5, 6, 5, 5, 6, 6, 5}}, ch);
    *c.material_at(0) = 2;
    *c.material_at(1) = 0;
    *c.material_at(2) = 2;
    ix.add(c);
    io::IndexedMesh m = ix.take();
    EXPECT_EQ(m.materials, (std::vector<uint32_t>{2, 0, 2}));
    const std::vector<io::MeshPart> parts = m.parts();
    ASSERT_EQ(parts.size(), 2u);  // material 1 has no triangles
    EXPECT_EQ(parts[0].material, 0u);
    EXPECT_EQ(parts[0].vertices, (std::vector<uint32_t>{0, 2, 3}));
    EXPECT_EQ(parts[0].indices, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(parts[1].material, 2u);
    EXPECT_EQ(parts[1].vertices, (std::vector<uint32_t>{0, 1, 2, 4, 5, 6}));
    EXPECT_EQ(parts[1].indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
}

TEST(MeshIndexer, GrowsPastTheInitialTable) {
    // A 100 x 100 grid: 10201 distinct vertices, each shared by up to six triangles.
    io::MeshIndexer ix("grid.drc", "Draco", {}, false);
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

TEST(MeshIndexer, ReservedTablesGiveTheSameMesh) {
    // The 60 x 60 grid (3721 vertices, 7200 triangles) in chunks of 64, indexed without a
    // reservation, with one for its count, with one too small (the tables grow past it) and with
    // one made once a vertex is in (ignored): the same indices and positions each time.
    std::vector<io::TriangleChunk> chunks;
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 60; ++x) {
            float a[9] = {float(x), float(y), 0, float(x + 1), float(y), 0, float(x + 1), float(y + 1), 0};
            float b[9] = {float(x), float(y), 0, float(x + 1), float(y + 1), 0, float(x), float(y + 1), 0};
            for (auto* t : {&a, &b}) {
                if (chunks.empty() || chunks.back().full()) chunks.emplace_back(64);
                chunks.back().push(*t);
            }
        }
    auto index = [&](std::optional<uint64_t> reserve, bool after_first) {
        io::MeshIndexer ix("grid.glb", "glTF", {}, false);
        if (reserve && !after_first) ix.reserve(*reserve);
        for (size_t i = 0; i < chunks.size(); ++i) {
            ix.add(chunks[i]);
            if (reserve && after_first && i == 0) ix.reserve(*reserve);
        }
        EXPECT_EQ(ix.vertex_count(), 61u * 61u);
        return ix.take();
    };
    const io::IndexedMesh plain = index(std::nullopt, false);
    for (const auto& [reserve, after_first] :
         {std::pair<uint64_t, bool>{7200, false}, {100, false}, {7200, true}, {uint64_t{1} << 40, true}}) {
        const io::IndexedMesh m = index(reserve, after_first);
        EXPECT_EQ(m.indices, plain.indices) << reserve;
        EXPECT_EQ(m.positions, plain.positions) << reserve;
    }
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
        EXPECT_NE(what.find("give the memory budget 130023424M or more"), std::string::npos) << what;
    }
}

}  // namespace
