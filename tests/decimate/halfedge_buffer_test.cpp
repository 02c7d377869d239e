// Tests of decimate/halfedge_buffer: READ (welding, twins, P_in bookkeeping) and the frozen
// treatment of non-manifold and degenerate input.
#include "decimate/halfedge_buffer.hpp"

#include "mesh_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

using namespace meshstream::decimate;
using namespace meshstream::decimate::test;

TEST(HalfEdgeBuffer, NextAndPrevInFaceCycleThroughTheThreeCorners) {
    for (uint32_t f : {0u, 1u, 12345u, (1u << 30) - 2}) {
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(f, k);
            EXPECT_EQ(next_in_face(h), half_edge(f, (k + 1) % 3));
            EXPECT_EQ(prev_in_face(h), half_edge(f, (k + 2) % 3));
            EXPECT_EQ(prev_in_face(next_in_face(h)), h);
        }
    }
}

TEST(HalfEdgeBuffer, TwoTrianglesShareAnEdge) {
    HalfEdgeBuffer buffer(64, 0);
    const size_t free_before = buffer.free_vertex_count();
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 1, 2}, {1, 3, 2}});
    EXPECT_EQ(buffer.face_count(), 2u);
    EXPECT_EQ(free_before - buffer.free_vertex_count(), 4u);
    const uint32_t b = vertex_at(buffer, {1, 0, 0}), c = vertex_at(buffer, {0, 1, 0});
    const uint32_t bc = half_edge(buffer, b, c), cb = half_edge(buffer, c, b);
    ASSERT_NE(bc, kNoIndex);
    ASSERT_NE(cb, kNoIndex);
    EXPECT_EQ(buffer.twin(bc), cb);
    EXPECT_EQ(buffer.twin(cb), bc);
    // The outer edges are still open towards the input: every vertex is on P_in.
    EXPECT_EQ(buffer.vertex(b).open_edges, 2u);
    EXPECT_TRUE(buffer.vertex(b).flags & kInHash);
    EXPECT_EQ(buffer.oldest_interior_face(), kNoIndex);
    EXPECT_TRUE(buffer_consistent(buffer));
}

TEST(HalfEdgeBuffer, ClosedMeshLeavesPin) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());
    EXPECT_EQ(buffer.face_count(), 8u);
    for (const auto& p : octahedron_points()) {
        const uint32_t v = vertex_at(buffer, p);
        ASSERT_NE(v, kNoIndex);
        EXPECT_EQ(buffer.vertex(v).open_edges, 0u);
        EXPECT_FALSE(buffer.vertex(v).flags & kInHash);
        EXPECT_EQ(buffer.vertex(v).face_count, 4u);
    }
    // Every face left P_in: the first to, the one whose last corner closed first, is listed.
    EXPECT_NE(buffer.oldest_interior_face(), kNoIndex);
    EXPECT_TRUE(buffer_consistent(buffer));
}

TEST(HalfEdgeBuffer, NegativeZeroWeldsWithPositiveZero) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-0.0f, 0, 0}, {0, -1, 0}}, {{0, 1, 2}, {3, 4, 1}});
    EXPECT_EQ(buffer.free_vertex_count(), 3 * 64 + 3 - 4u);
}

TEST(HalfEdgeBuffer, ThirdFaceOnAnEdgeIsFrozenAsNonManifold) {
    HalfEdgeBuffer buffer(64, 0);
    const auto faces = add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}},
                                   {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
    EXPECT_EQ(buffer.nonmanifold_edges(), 1u);
    const uint32_t a = vertex_at(buffer, {0, 0, 0}), b = vertex_at(buffer, {1, 0, 0});
    EXPECT_TRUE(buffer.vertex(a).flags & kNonManifold);
    EXPECT_TRUE(buffer.vertex(b).flags & kNonManifold);
    EXPECT_EQ(buffer.twin(half_edge(faces[2], 0)), kNonManifoldEdge);
    EXPECT_TRUE(buffer_consistent(buffer));
}

TEST(HalfEdgeBuffer, DuplicateAndMisorientedFacesAreFrozen) {
    HalfEdgeBuffer buffer(64, 0);
    // The same triangle twice: every edge of the second conflicts with the first.
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 1, 2}});
    EXPECT_EQ(buffer.nonmanifold_edges(), 3u);
}

// A triangle's edges are found from the lists of its two corners in the fewest faces (a hub of
// thousands of faces made reading quadratic when its list was walked). A closed double cone with two
// hubs of 300 faces each, the hub at every corner position in turn, connects like any mesh;
// a third face on a spoke and a duplicate face at a hub are non-manifold as elsewhere.
TEST(HalfEdgeBuffer, EdgesAtVerticesInHundredsOfFacesConnectAsElsewhere) {
    constexpr uint32_t n = 300;
    std::vector<std::array<float, 3>> points = {{0, 0, 1}, {0, 0, -1}};
    for (uint32_t i = 0; i < n; ++i)
        points.push_back({std::cos(6.2831853f * float(i) / n), std::sin(6.2831853f * float(i) / n), 0});
    std::vector<std::array<int, 3>> faces;
    for (uint32_t i = 0; i < n; ++i) {
        const int a = int(2 + i), b = int(2 + (i + 1) % n);
        std::array<int, 3> top = {0, a, b}, bottom = {1, b, a};
        std::rotate(top.begin(), top.begin() + i % 3, top.end());
        std::rotate(bottom.begin(), bottom.begin() + (i + 1) % 3, bottom.end());
        faces.push_back(top);
        faces.push_back(bottom);
    }
    HalfEdgeBuffer buffer(4 * n, 0);
    add_indexed(buffer, points, faces);
    EXPECT_EQ(buffer.face_count(), 2 * n);
    EXPECT_EQ(buffer.nonmanifold_edges(), 0u);
    for (const auto& p : points) {
        const uint32_t v = vertex_at(buffer, p);
        EXPECT_EQ(buffer.vertex(v).open_edges, 0u);
        EXPECT_FALSE(buffer.vertex(v).flags & kInHash);  // closed: off P_in
    }
    EXPECT_EQ(buffer.vertex(vertex_at(buffer, points[0])).face_count, n);
    EXPECT_TRUE(buffer_consistent(buffer));

    // The top half less one face is an open fan: its rim and the two spokes at the gap stay
    // open (the hub stays on P_in), the other spokes connect; a duplicate face at the hub and
    // a third face on a spoke are then non-manifold.
    HalfEdgeBuffer disk(4 * n, 0);
    std::vector<std::array<int, 3>> fan;
    for (size_t i = 0; i + 2 < faces.size(); i += 2) fan.push_back(faces[i]);
    add_indexed(disk, points, fan);
    EXPECT_EQ(disk.nonmanifold_edges(), 0u);
    EXPECT_EQ(disk.vertex(vertex_at(disk, points[0])).open_edges, 2u);
    EXPECT_EQ(disk.vertex(vertex_at(disk, points[9])).open_edges, 2u);
    add_indexed(disk, points, {fan[20], {9, 0, 1}});
    EXPECT_EQ(disk.nonmanifold_edges(), 3u + 1u);
    EXPECT_TRUE(disk.vertex(vertex_at(disk, points[0])).flags & kNonManifold);
    EXPECT_TRUE(buffer_consistent(disk));
}

TEST(HalfEdgeBuffer, DegenerateTriangleIsNotInserted) {
    HalfEdgeBuffer buffer(64, 0);
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 0, 0};
    const HalfEdgeBuffer::Added added = buffer.add_triangle(tri);
    EXPECT_EQ(added.face, kNoIndex);
    EXPECT_EQ(added.vertex[0], added.vertex[2]);
    EXPECT_EQ(buffer.face_count(), 0u);
}

TEST(HalfEdgeBuffer, WeldGridMergesNearbyPositionsAndCounts) {
    HalfEdgeBuffer buffer(64, 0.01);
    // (0.1234, 0, 0) and (0.1236, 0, 0) share a 0.01 cell: the two triangles share an edge.
    add_indexed(buffer,
                {{0.1234f, 0.005f, 0.005f},
                 {1.005f, 0.005f, 0.005f},
                 {0.005f, 1.005f, 0.005f},
                 {0.1236f, 0.005f, 0.005f},
                 {0.5f, -1, 0.005f}},
                {{0, 1, 2}, {1, 3, 4}});
    EXPECT_EQ(buffer.vertices_merged(), 1u);
    EXPECT_EQ(buffer.free_vertex_count(), 3 * 64 + 3 - 4u);
}

TEST(HalfEdgeBuffer, WeldGridRoundsToTheNearestPointSoRoundNumbersWeld) {
    // A floor at z = 0 with round-off on either side: with cells ⌊z/EPS⌋ the border at 0 split
    // it (cells −1 and 0); cells around the nearest grid point keep it together. Corners just
    // either side of a half step (0.00005 with EPS 0.0001) are split, as a grid must split
    // somewhere.
    HalfEdgeBuffer buffer(64, 1e-4);
    add_indexed(buffer, {{0, 0, 1e-9f}, {1, 0, -1e-9f}, {0, 1, 1e-9f}, {1, 0, 1e-9f}, {1, 1, -1e-9f}, {0, 1, -1e-9f}},
                {{0, 1, 2}, {3, 4, 5}});
    EXPECT_EQ(buffer.vertices_merged(), 2u);  // (1, 0) and (0, 1) each absorbed the other sign
    EXPECT_EQ(buffer.free_vertex_count(), 3 * 64 + 3 - 4u);
    HalfEdgeBuffer split(64, 1e-4);
    add_indexed(split, {{0, 0, 0.000051f}, {1, 0, 0.000049f}, {0, 1, 0}, {0, 0, 0.000049f}}, {{0, 1, 2}, {3, 1, 2}});
    EXPECT_EQ(split.free_vertex_count(), 3 * 64 + 3 - 4u);
}

TEST(HalfEdgeBuffer, LeavingPinAndFreezingListVerticesForRating) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());
    std::vector<uint32_t> taken;
    buffer.take_pending([&](uint32_t v) { taken.push_back(v); });
    EXPECT_EQ(taken.size(), 6u);  // each vertex once, when its fan closed
    taken.clear();
    buffer.take_pending([&](uint32_t v) { taken.push_back(v); });
    EXPECT_TRUE(taken.empty());
    const uint32_t top = vertex_at(buffer, {0, 0, 1});
    buffer.freeze(top, 0);
    buffer.take_pending([&](uint32_t v) { taken.push_back(v); });
    EXPECT_EQ(taken, std::vector<uint32_t>{top});
}

TEST(HalfEdgeBuffer, FinalizedOpenVertexLeavesPin) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
    EXPECT_EQ(buffer.oldest_interior_face(), kNoIndex);
    buffer.finalize_all();
    EXPECT_EQ(buffer.oldest_interior_face(), 0u);
}

TEST(HalfEdgeBuffer, ClassifyFansFollowsTheFansAsTheyAreNow) {
    // Two triangles sharing vertex 0 only: two open fans (boundary loops touching there).
    HalfEdgeBuffer buffer(64, 0);
    const std::vector<uint32_t> faces =
        add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 3, 4}});
    buffer.finalize_all();
    const uint32_t centre = buffer.corner_vertex(half_edge(faces[0], 0));
    EXPECT_EQ(buffer.vertex(centre).flags & (kManyFans | kOpenFans), kManyFans | kOpenFans);
    // One of them gone: one fan, walked again by classify_fans.
    buffer.detach_face(faces[1]);
    buffer.classify_fans(centre);
    EXPECT_EQ(buffer.vertex(centre).flags & (kManyFans | kOpenFans), 0);
}
