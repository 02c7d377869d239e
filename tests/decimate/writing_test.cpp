// Tests of decimate/writing: write-time placement at the quadric minimum (§4.4), freezing and
// ids, P_out bookkeeping, and the preference for triangles on P_out.
#include "decimate/writing.hpp"

#include "mesh_util.hpp"

#include <gtest/gtest.h>

#include <array>

using namespace meshstream::decimate;
using namespace meshstream::decimate::test;

namespace {

// The octahedron in a buffer, and its top vertex (0, 0, 1).
struct Octahedron {
    HalfEdgeBuffer buffer{64, 0};
    uint32_t top;
    Octahedron() {
        add_indexed(buffer, octahedron_points(), octahedron_faces());
        top = vertex_at(buffer, {0, 0, 1});
    }
    // The quadric of the plane through three points, in the coordinates the buffer keeps
    // quadrics in (relative to its origin, the first vertex read).
    Quadric plane(std::array<double, 3> a, std::array<double, 3> b, std::array<double, 3> c) const {
        double rel[3];
        buffer.position(top, rel);
        for (int i = 0; i < 3; ++i) {
            const double origin = double(buffer.vertex(top).pos[i]) - rel[i];
            a[i] -= origin;
            b[i] -= origin;
            c[i] -= origin;
        }
        return Quadric::from_triangle(a.data(), b.data(), c.data());
    }
};

}  // namespace

TEST(Writing, WriteFreezesVerticesAndOpensPout) {
    HalfEdgeBuffer buffer(64, 0);
    const auto faces = add_indexed(buffer, octahedron_points(), octahedron_faces());
    TriangleOutput output(4);
    std::vector<uint64_t> ids;
    const Emit emit = [&](const meshstream::io::TriangleChunk& chunk) {
        ids.insert(ids.end(), chunk.vertex_ids().begin(), chunk.vertex_ids().end());
    };
    uint64_t next_id = 0;
    write_face(buffer, faces[0], next_id, output, emit);
    output.flush(emit);
    ASSERT_EQ(ids.size(), 3u);
    EXPECT_EQ(ids, (std::vector<uint64_t>{0, 1, 2}));
    EXPECT_EQ(buffer.face_count(), 7u);
    // The three neighbours across the written face's edges now border P_out.
    int written_edges = 0;
    for (uint32_t g = 0; g < buffer.face_slots(); ++g)
        for (uint32_t k = 0; buffer.face_alive(g) && k < 3; ++k)
            written_edges += buffer.twin(half_edge(g, k)) == kWrittenEdge;
    EXPECT_EQ(written_edges, 3);
    // The next write reuses the frozen ids of shared vertices.
    const uint32_t f = pick_write(buffer);
    ASSERT_NE(f, kNoIndex);
    write_face(buffer, f, next_id, output, emit);
    output.flush(emit);
    EXPECT_LT(next_id, 6u);
    EXPECT_TRUE(buffer_consistent(buffer));
}

TEST(Writing, WritesTheFaceThatLeftPinFirst) {
    // A strip of four faces read left to right, then closed off: faces leave P_in as their
    // last corner does. finalize_vertex() on the left end first makes face 0 interior first,
    // and the writer takes faces in that order, skipping the removed ones.
    HalfEdgeBuffer buffer(64, 0);
    const auto faces = add_indexed(buffer, {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}},
                                   {{0, 2, 1}, {1, 2, 3}, {2, 4, 3}, {3, 4, 5}});
    EXPECT_EQ(pick_write(buffer), kNoIndex);  // every face touches P_in
    for (const std::array<float, 3>& p :
         std::vector<std::array<float, 3>>{{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {2, 1, 0}})
        buffer.finalize_vertex(vertex_at(buffer, p));
    TriangleOutput output(4);
    const Emit emit = [](const meshstream::io::TriangleChunk&) {};
    uint64_t next_id = 0;
    std::vector<uint32_t> order;
    for (uint32_t f = pick_write(buffer); f != kNoIndex; f = pick_write(buffer)) {
        order.push_back(f);
        write_face(buffer, f, next_id, output, emit);
    }
    EXPECT_EQ(order, (std::vector<uint32_t>{faces[0], faces[1], faces[2], faces[3]}));
}

TEST(Writing, VertexMovesToItsQuadricMinimumOnce) {
    Octahedron oct;
    HalfEdgeBuffer& buffer = oct.buffer;
    const uint32_t top = oct.top;
    // Give the top vertex a quadric whose minimum is (0.1, -0.1, 0.9): three planes.
    buffer.quadric(top) = oct.plane({0.1, 0, 0}, {0.1, 1, 0}, {0.1, 0, 1}) +
                          oct.plane({0, -0.1, 0}, {0, -0.1, 1}, {1, -0.1, 0}) +
                          oct.plane({0, 0, 0.9}, {1, 0, 0.9}, {0, 1, 0.9});
    // A vertex nothing was collapsed into is the minimum of its own planes: it stays put
    // (ratio 1 copies the input exactly).
    EXPECT_FALSE(place_vertex(buffer, top));
    EXPECT_EQ(buffer.vertex(top).pos[2], 1.0f);
    const float far_end[3] = {0.0f, 0.0f, 0.8f};  // as if a vertex there had been collapsed into it
    buffer.set_partner(top, far_end);
    ASSERT_TRUE(place_vertex(buffer, top));
    EXPECT_FLOAT_EQ(buffer.vertex(top).pos[0], 0.1f);
    EXPECT_FLOAT_EQ(buffer.vertex(top).pos[1], -0.1f);
    EXPECT_FLOAT_EQ(buffer.vertex(top).pos[2], 0.9f);
    buffer.freeze(top, 0);
    EXPECT_FALSE(place_vertex(buffer, top));  // frozen: never again
}

TEST(Writing, FarOrSingularOptimumKeepsThePosition) {
    Octahedron oct;
    HalfEdgeBuffer& buffer = oct.buffer;
    const uint32_t top = oct.top;
    const double a[3] = {0, 0, 9}, b[3] = {1, 0, 9}, c[3] = {0, 1, 9};  // only the plane z = 9
    buffer.quadric(top) = Quadric::from_triangle(a, b, c);
    EXPECT_FALSE(place_vertex(buffer, top));  // singular
    const double d[3] = {9, 0, 0}, e[3] = {9, 1, 0}, f[3] = {9, 0, 1};
    const double g[3] = {0, 9, 0}, h[3] = {0, 9, 1}, i[3] = {1, 9, 0};
    buffer.quadric(top) = buffer.quadric(top) + Quadric::from_triangle(d, e, f) + Quadric::from_triangle(g, h, i);
    EXPECT_FALSE(place_vertex(buffer, top));  // minimum (9, 9, 9) is beyond the longest edge
    EXPECT_EQ(buffer.vertex(top).pos[2], 1.0f);
}

TEST(Writing, SingularQuadricFallsBackToTheBestEndOfTheCollapsedEdge) {
    Octahedron oct;
    HalfEdgeBuffer& buffer = oct.buffer;
    const uint32_t top = oct.top;
    // Only the plane z = 0.9: singular (no unique minimum).
    buffer.quadric(top) = oct.plane({0, 0, 0.9}, {1, 0, 0.9}, {0, 1, 0.9});
    // Nothing collapsed into it: no fallback, it stays.
    EXPECT_FALSE(place_vertex(buffer, top));
    // As if p = (0.05, 0, 0.9) had been collapsed into it: p lies on the plane (error 0),
    // better than the midpoint (0.025, 0, 0.95) and the old position (0, 0, 1).
    const float far_end[3] = {0.05f, 0.0f, 0.9f};
    buffer.set_partner(top, far_end);
    ASSERT_TRUE(place_vertex(buffer, top));
    EXPECT_FLOAT_EQ(buffer.vertex(top).pos[0], 0.05f);
    EXPECT_FLOAT_EQ(buffer.vertex(top).pos[1], 0.0f);
    EXPECT_FLOAT_EQ(buffer.vertex(top).pos[2], 0.9f);
}

TEST(Writing, SingularFallbackNeverTakesAWorseEnd) {
    Octahedron oct;
    HalfEdgeBuffer& buffer = oct.buffer;
    const uint32_t top = oct.top;
    // The plane z = 1 through the vertex itself: its old position already has error 0.
    buffer.quadric(top) = oct.plane({0, 0, 1}, {1, 0, 1}, {0, 1, 1});
    const float far_end[3] = {0.0f, 0.0f, 0.8f};
    buffer.set_partner(top, far_end);
    EXPECT_FALSE(place_vertex(buffer, top));
    EXPECT_EQ(buffer.vertex(top).pos[2], 1.0f);
}

TEST(Writing, PassThroughFreezesInPlace) {
    HalfEdgeBuffer buffer(64, 0);
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 0, 0};
    const HalfEdgeBuffer::Added added = buffer.add_triangle(tri);
    TriangleOutput output(8);
    std::vector<float> xyz;
    std::vector<uint64_t> ids;
    const Emit emit = [&](const meshstream::io::TriangleChunk& chunk) {
        xyz.insert(xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        ids.insert(ids.end(), chunk.vertex_ids().begin(), chunk.vertex_ids().end());
    };
    uint64_t next_id = 0;
    pass_through(buffer, added.vertex, next_id, output, emit);
    output.flush(emit);
    EXPECT_EQ(xyz, std::vector<float>(tri, tri + 9));
    EXPECT_EQ(ids, (std::vector<uint64_t>{0, 1, 0}));
}
