// Tests of decimate/collapse: the boundary rules of §4 (which half-edges may collapse), boundary
// loops that touch at a vertex, holes of three edges that close, the link condition, and that
// collapses keep the half-edge structure consistent.
#include "decimate/collapse.hpp"
#include "decimate/greedy.hpp"

#include "mesh_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace meshstream::decimate;
using namespace meshstream::decimate::test;

namespace {

std::set<uint32_t> neighbours(const HalfEdgeBuffer& buffer, uint32_t v) {
    std::set<uint32_t> n;
    for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c)) {
        n.insert(buffer.corner_vertex(next_in_face(c)));
        n.insert(buffer.corner_vertex(prev_in_face(c)));
    }
    return n;
}

// The triangles of an n×n vertex grid numbered row by row, two per cell, rows in reading order.
std::vector<std::array<int, 3>> grid_faces(int n) {
    std::vector<std::array<int, 3>> faces;
    for (int y = 0; y + 1 < n; ++y)
        for (int x = 0; x + 1 < n; ++x) {
            const int a = n * y + x;
            faces.push_back({a, a + 1, a + n + 1});
            faces.push_back({a, a + n + 1, a + n});
        }
    return faces;
}

// The points of an n×n vertex grid (unit spacing, row by row) on the surface
// z = a·dx² + b·dy² + c·dx·dy about its centre (dx, dy from the middle of the grid).
std::vector<std::array<float, 3>> curved_grid(int n, float a, float b, float c) {
    std::vector<std::array<float, 3>> points;
    const float mid = 0.5f * float(n - 1);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const float dx = float(x) - mid, dy = float(y) - mid;
            points.push_back({float(x), float(y), a * dx * dx + b * dy * dy + c * dx * dy});
        }
    return points;
}

// A 5×5 vertex grid (32 triangles) on the bowl z = bump·((x−2)² + (y−2)²) (0: flat).
void add_grid(HalfEdgeBuffer& buffer, float bump = 0.1f) {
    add_indexed(buffer, curved_grid(5, bump, bump, 0), grid_faces(5));
}

// Whether the placement puts the merged vertex elsewhere than q, the target of h = p→q.
bool moves_target(const HalfEdgeBuffer& buffer, uint32_t h, const CollapsePlacement& placement) {
    double q[3];
    buffer.position(buffer.corner_vertex(next_in_face(h)), q);
    return q[0] != placement.target[0] || q[1] != placement.target[1] || q[2] != placement.target[2];
}

}  // namespace

TEST(Collapse, OctahedronCollapseRemovesTwoFacesAndStaysClosed) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());
    const uint32_t top = vertex_at(buffer, {0, 0, 1}), east = vertex_at(buffer, {1, 0, 0});
    const uint32_t h = half_edge(buffer, top, east);
    ASSERT_TRUE(collapse_eligible(buffer, h));
    ASSERT_TRUE(collapse_valid(buffer, h));
    apply_collapse(buffer, h);
    EXPECT_EQ(buffer.face_count(), 6u);
    EXPECT_TRUE(buffer_consistent(buffer));
    for (const uint32_t e : live_half_edges(buffer)) EXPECT_TRUE(is_half_edge(buffer.twin(e)));
    EXPECT_EQ(buffer.vertex(east).face_count, 4u);  // 4 - 2 removed + 2 inherited from top
}

TEST(Collapse, LinkConditionRefusesPinches) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());
    apply_collapse(buffer, half_edge(buffer, vertex_at(buffer, {0, 0, 1}), vertex_at(buffer, {1, 0, 0})));
    // Now a bipyramid-like closed mesh: check every half-edge against a brute-force link test.
    int refused_by_link = 0;
    const std::vector<uint32_t> half_edges = live_half_edges(buffer);
    for (uint32_t h : half_edges) {
        const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
        const std::set<uint32_t> np = neighbours(buffer, p), nq = neighbours(buffer, q);
        size_t common = 0;
        for (uint32_t x : np) common += nq.count(x);
        const bool link_ok = common == 2;
        if (collapse_eligible(buffer, h) && collapse_valid(buffer, h)) {
            EXPECT_TRUE(link_ok);
        }
        if (!link_ok) ++refused_by_link;
    }
    EXPECT_GT(refused_by_link, 0);
}

TEST(Collapse, TetrahedronNeverCollapses) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
    for (const uint32_t h : live_half_edges(buffer)) EXPECT_FALSE(collapse_valid(buffer, h));
}

TEST(Collapse, BoundaryRulesForPinAndPout) {
    HalfEdgeBuffer buffer(64, 0);
    add_grid(buffer);
    const uint32_t centre = vertex_at(buffer, {2, 2, 0});
    const uint32_t inner = vertex_at(buffer, {1, 2, 0.1f});
    const uint32_t rim = vertex_at(buffer, {0, 2, 0.4f});
    ASSERT_NE(rim, kNoIndex);
    // Half-edges from a boundary vertex never collapse.
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, rim, inner)));
    // Interior to interior: allowed.
    EXPECT_TRUE(collapse_eligible(buffer, half_edge(buffer, centre, inner)));
    // Into a P_in vertex (rim, still open towards the input): refused...
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, inner, rim)));
    // ...also when it has been written (P_in and P_out at once)...
    buffer.freeze(rim, 0);
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, inner, rim)));
    // ...but into a P_out vertex whose quadric is complete: allowed (it does not move).
    buffer.finalize_vertex(rim);
    EXPECT_TRUE(collapse_eligible(buffer, half_edge(buffer, inner, rim)));
    // And a written vertex never moves.
    buffer.freeze(inner, 1);
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, inner, centre)));
    EXPECT_TRUE(collapse_eligible(buffer, half_edge(buffer, centre, inner)));
    ASSERT_TRUE(collapse_valid(buffer, half_edge(buffer, centre, inner)));
    apply_collapse(buffer, half_edge(buffer, centre, inner));
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_EQ(buffer.face_count(), 30u);
}

// Vertices that join two fans (a second triangle touching only at the vertex): the fan walks
// of collapse_valid cover the fan around the edge, and must still see the other one.
TEST(Collapse, SecondFanAtEitherEndIsSeen) {
    const float centre_at[3] = {2, 2, 0}, inner_at[3] = {1, 2, 0.1f}, east_at[3] = {3, 2, 0.1f};
    const float far_east_at[3] = {4, 2, 0.4f}, apex[3] = {2, 2, 3};
    // The extra triangle comes first: a vertex whose grid fan has closed has left P_in, and a
    // later triangle would get a new vertex at the same position.
    auto build = [&](HalfEdgeBuffer& buffer, const float* extra_a, const float* extra_b) {
        if (extra_a != nullptr) {
            const float tri[9] = {extra_a[0], extra_a[1], extra_a[2], extra_b[0], extra_b[1],
                                  extra_b[2], apex[0],    apex[1],    apex[2]};
            ASSERT_NE(buffer.add_triangle(tri).face, kNoIndex);
        }
        add_grid(buffer);
        buffer.finalize_all();
    };
    {
        // Control: on the plain grid, centre → inner is a valid collapse.
        HalfEdgeBuffer buffer(64, 0);
        build(buffer, nullptr, nullptr);
        const uint32_t centre = vertex_at(buffer, {2, 2, 0}), inner = vertex_at(buffer, {1, 2, 0.1f});
        EXPECT_TRUE(collapse_valid(buffer, half_edge(buffer, centre, inner)));
    }
    {
        // q = inner gets a second fan reaching east, a neighbour of p = centre but not of q in
        // the grid: merging them would pinch the surface at east (link condition).
        HalfEdgeBuffer buffer(64, 0);
        build(buffer, inner_at, east_at);
        const uint32_t centre = vertex_at(buffer, {2, 2, 0}), inner = vertex_at(buffer, {1, 2, 0.1f});
        const uint32_t h = half_edge(buffer, centre, inner);
        ASSERT_EQ(buffer.vertex(inner).face_count, 7u);
        ASSERT_TRUE(collapse_eligible(buffer, h));
        EXPECT_FALSE(collapse_valid(buffer, h));
    }
    {
        // p = centre gets the second fan, reaching the rim: it has two open edges, like a hole's
        // rim vertex, but is no manifold vertex and must not move. Found once, when it left
        // P_in (kManyFans, and one of its fans closed: no kOpenFans): none of its half-edges is
        // eligible.
        HalfEdgeBuffer buffer(64, 0);
        build(buffer, centre_at, far_east_at);
        const uint32_t centre = vertex_at(buffer, {2, 2, 0}), far_east = vertex_at(buffer, {4, 2, 0.4f});
        const uint32_t h = half_edge(buffer, centre, far_east);
        ASSERT_EQ(buffer.vertex(centre).face_count, 7u);
        ASSERT_EQ(buffer.twin(h), kOpenEdge);
        EXPECT_EQ(buffer.vertex(centre).flags & (kManyFans | kOpenFans), kManyFans);
        EXPECT_FALSE(collapse_eligible(buffer, h));
    }
}

// Boundary loops that touch at a vertex: a flat 5×3 vertex grid (x 0..4, y 0..2, z 0) and a
// diamond (2,2) (3,3) (2,4) (1,3) above it, sharing the grid's top-middle vertex (2,2) only.
// `diamond`: false leaves the grid alone.
void add_touching_loops(HalfEdgeBuffer& buffer, bool diamond) {
    std::vector<std::array<float, 3>> points;
    std::vector<std::array<int, 3>> faces;
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x) points.push_back({float(x), float(y), 0});
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            const int a = 5 * y + x;
            faces.push_back({a, a + 1, a + 6});
            faces.push_back({a, a + 6, a + 5});
        }
    if (diamond) {
        points.insert(points.end(), {{3, 3, 0}, {2, 4, 0}, {1, 3, 0}});
        faces.push_back({12, 15, 16});
        faces.push_back({12, 16, 17});
    }
    add_indexed(buffer, points, faces);
    buffer.finalize_all();
}

TEST(Collapse, BoundaryLoopsTouchingAtAVertexSlideAlongTheirEdges) {
    HalfEdgeBuffer buffer(64, 0);
    add_touching_loops(buffer, true);
    const uint32_t junction = vertex_at(buffer, {2, 2, 0}), west = vertex_at(buffer, {1, 2, 0});
    const uint32_t below = vertex_at(buffer, {2, 1, 0}), north_east = vertex_at(buffer, {3, 3, 0});
    // Two fans, both open: four open edges.
    EXPECT_EQ(buffer.vertex(junction).flags & (kManyFans | kOpenFans), kManyFans | kOpenFans);
    EXPECT_EQ(buffer.vertex(junction).open_edges, 4u);
    EXPECT_EQ(buffer.vertex(junction).face_count, 5u);
    // Along each loop's outgoing open edge, as a vertex of one loop; never across the grid.
    const uint32_t h = half_edge(buffer, junction, west);
    EXPECT_TRUE(collapse_eligible(buffer, h));
    EXPECT_TRUE(collapse_eligible(buffer, half_edge(buffer, junction, north_east)));
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, junction, below)));
    // The grid's top edge is straight: alone, sliding costs nothing; the diamond's boundary
    // planes price moving its corner.
    HalfEdgeBuffer alone(64, 0);
    add_touching_loops(alone, false);
    const double free_slide =
        collapse_placement(alone, half_edge(alone, vertex_at(alone, {2, 2, 0}), vertex_at(alone, {1, 2, 0}))).error;
    EXPECT_NEAR(free_slide, 0, 1e-12);
    EXPECT_GT(collapse_placement(buffer, h).error, 0.1);
    // The collapse keeps the half-edges consistent; the loops touch at the west vertex now.
    ASSERT_TRUE(collapse_valid(buffer, h));
    apply_collapse(buffer, h);
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_EQ(buffer.face_count(), 17u);
    EXPECT_EQ(buffer.vertex(west).open_edges, 4u);
    EXPECT_EQ(buffer.vertex(west).face_count, 6u);
    EXPECT_EQ(buffer.vertex(west).flags & (kManyFans | kOpenFans), kManyFans | kOpenFans);
    EXPECT_EQ(neighbours(buffer, west),
              (std::set<uint32_t>{vertex_at(buffer, {0, 2, 0}), vertex_at(buffer, {0, 1, 0}),
                                  vertex_at(buffer, {1, 1, 0}), below, vertex_at(buffer, {3, 2, 0}), north_east,
                                  vertex_at(buffer, {2, 4, 0}), vertex_at(buffer, {1, 3, 0})}));
}

// Collapse targets are float positions, exactly what set_position() will store, so that the
// fold checks and the rating see the position the vertex gets: on a bowl (optimal placement),
// a cylinder (singular: the fallback to p, q or the midpoint) and a plane (nothing gains by
// moving), away from the origin so that rounding to float matters. (g++ 12 at -O3 once dropped
// that rounding for two of the three coordinates: HalfEdgeBuffer::through_float.)
TEST(Collapse, PlacementTargetsAreStoredFloatPositions) {
    struct Shape {
        float x2, y2;  // curvatures along x and y
        bool some_move;
    };
    for (const Shape shape : {Shape{0.13f, 0.08f, true}, Shape{0.13f, 0.0f, true}, Shape{0.0f, 0.0f, false}}) {
        std::vector<std::array<float, 3>> points;
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 7; ++x) {
                const float dx = float(x) - 3.1f, dy = float(y) - 2.9f;
                points.push_back({1000.25f + 0.7f * float(x) + 0.05f * float(y), -20.5f + 0.9f * float(y),
                                  5.75f + shape.x2 * dx * dx + shape.y2 * dy * dy});
            }
        HalfEdgeBuffer buffer(256, 0);
        add_indexed(buffer, points, grid_faces(7));
        buffer.finalize_all();
        int moved = 0, kept = 0;
        for (const uint32_t h : live_half_edges(buffer)) {
            if (!collapse_eligible(buffer, h)) continue;
            const CollapsePlacement placement = collapse_placement(buffer, h);
            for (int axis = 0; axis < 3; ++axis) {
                const double o = buffer.origin(axis);
                EXPECT_EQ(placement.target[axis], double(float(placement.target[axis] + o)) - o)
                    << "not a float position: half-edge " << h << ", axis " << axis;
            }
            ++(moves_target(buffer, h, placement) ? moved : kept);
        }
        EXPECT_EQ(moved > 0, shape.some_move) << moved << " targets moved";
        EXPECT_GT(kept, 0);
    }
}

// A merge whose quadric has no minimum (a cylinder, a plane) goes to the best of q, p and their
// midpoint rounded to floats, a later one only when strictly better: singular_merge(), which
// the rating calls with the quadric it has summed, and collapse_placement() both place it so.
TEST(Collapse, SingularMergeTakesTheBestOfTheEndsAndTheMidpoint) {
    for (const float curvature : {0.13f, 0.0f}) {
        std::vector<std::array<float, 3>> points;
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 7; ++x) {
                const float dx = float(x) - 3.1f;
                points.push_back({1000.25f + 0.7f * float(x), -20.5f + 0.9f * float(y), 5.75f + curvature * dx * dx});
            }
        HalfEdgeBuffer buffer(256, 0);
        add_indexed(buffer, points, grid_faces(7));
        buffer.finalize_all();
        int singular = 0, midpoints = 0;
        for (const uint32_t h : live_half_edges(buffer)) {
            if (!collapse_eligible(buffer, h) || !collapse_target_free(buffer, h)) continue;
            const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
            const Quadric sum = merged_quadric(buffer, p, q);
            double x[3];
            if (sum.minimum(x)) continue;
            ++singular;
            double candidate[3][3];
            buffer.position(q, candidate[0]);
            buffer.position(p, candidate[1]);
            for (int axis = 0; axis < 3; ++axis)
                candidate[2][axis] = 0.5 * (candidate[0][axis] + candidate[1][axis]);
            buffer.round_position(candidate[2]);
            int best = 0;
            for (int i = 1; i < 3; ++i)
                if (sum.error(candidate[i]) < sum.error(candidate[best])) best = i;
            midpoints += best == 2;
            for (const CollapsePlacement& placed : {singular_merge(buffer, sum, p, q), collapse_placement(buffer, h)}) {
                EXPECT_EQ(placed.error, sum.error(candidate[best])) << "half-edge " << h;
                for (int axis = 0; axis < 3; ++axis)
                    EXPECT_EQ(placed.target[axis], candidate[best][axis]) << "half-edge " << h << ", axis " << axis;
            }
        }
        EXPECT_GT(singular, 0) << "curvature " << curvature;
        if (curvature > 0) {
            EXPECT_GT(midpoints, 0) << "the bent rows' merges land between their ends";
        }
    }
}

TEST(Collapse, FlipIsRefused) {
    HalfEdgeBuffer buffer(64, 0);
    // A fan around (0,0,0) on the plane z = 0 with one far outlier neighbour: collapsing the
    // centre onto the outlier would turn the faces on the other side over.
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0.2f, 1, 0}, {-1, 0.2f, 0}, {-0.2f, -1, 0}, {5, 5, 0}},
                {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}});
    buffer.finalize_all();
    const uint32_t centre = vertex_at(buffer, {0, 0, 0}), east = vertex_at(buffer, {1, 0, 0});
    ASSERT_TRUE(collapse_eligible(buffer, half_edge(buffer, centre, east)));
    // Move east far out to the other side: the collapse would flip the west faces.
    buffer.vertex(east).pos[0] = -3;
    EXPECT_FALSE(collapse_valid(buffer, half_edge(buffer, centre, east)));
}

TEST(Collapse, SmallFaceMovedFarIsJudgedByItsOwnShape) {
    // A small sound face (v, a, b) on z = 0; moving v far out across the edge ab turns it over.
    // Judged by the new, long edges the old face looked degenerate and the move was allowed.
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, {{0, 0, 0}, {1e-3f, 0, 0}, {0, 1e-3f, 0}}, {{0, 1, 2}});
    const uint32_t v = vertex_at(buffer, {0, 0, 0});
    const double from[3] = {0, 0, 0}, across[3] = {10, 10, 0}, near[3] = {-1e-3, -1e-3, 0};
    EXPECT_FALSE(moves_keep_faces_valid(buffer, v, from, across, kNoIndex, kNoIndex));
    EXPECT_TRUE(moves_keep_faces_valid(buffer, v, from, near, kNoIndex, kNoIndex));
}

TEST(Collapse, DegenerateFaceMayNotComeOutUpsideDown) {
    // v lies on the segment ab, so (v, a, b) has no area; its neighbours (v, b, c) and (v, c, a)
    // face +z. Moving v towards c makes (v, a, b) a sound face facing +z, as its neighbours;
    // moving it away from c makes it a sound face facing −z while the neighbours stay sound.
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {-1, 0, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}});
    const uint32_t v = vertex_at(buffer, {0, 0, 0});
    const double from[3] = {0, 0, 0}, towards_c[3] = {0, -0.2, 0}, away[3] = {0, 0.2, 0};
    EXPECT_TRUE(moves_keep_faces_valid(buffer, v, from, towards_c, kNoIndex, kNoIndex));
    EXPECT_FALSE(moves_keep_faces_valid(buffer, v, from, away, kNoIndex, kNoIndex));
}

TEST(Collapse, ACollapseThatDoesNotMoveTheTargetLeavesItsFloatsAlone) {
    // Positions are held relative to the first vertex read, here (10, 10.5, 10). A coordinate
    // of 4.8e-17 does not survive the trip through relative doubles (10.5 + 4.8e-17 is 10.5), so
    // storing the target's own position back turned it into 0: for a written target, its later
    // triangles no longer met its earlier ones.
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, {{10, 10.5f, 10}, {11, 10.5f, 10}, {10, 11.5f, 10}}, {{0, 1, 2}});
    std::vector<std::array<float, 3>> points = octahedron_points();
    const float tiny = 4.7696769e-17f;
    for (auto& p : points)
        if (p == std::array<float, 3>{1, 0, 0}) p[1] = tiny;
    add_indexed(buffer, points, octahedron_faces());
    const uint32_t top = vertex_at(buffer, {0, 0, 1}), east = vertex_at(buffer, {1, tiny, 0});
    const uint32_t h = half_edge(buffer, top, east);
    double target[3];
    buffer.position(east, target);
    ASSERT_TRUE(collapse_valid(buffer, h, target));
    apply_collapse(buffer, h, target);
    EXPECT_EQ(buffer.vertex(east).pos[1], tiny);
}

TEST(Collapse, AMovedFaceMustStillRoughlyFaceItsFansWay) {
    // v's fan: four flat faces facing +z and one steep face. Moving v to `far` turns every face
    // by less than 84°, but leaves the steep face 147° from the fan's normal: turns add up that
    // way over successive collapses, so it is refused (the bound is 143°). Moving it to `near`
    // leaves the steep face 135° from the fan's normal, which thin tubes need.
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer,
                {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0.1f, 0.2f, 0.2f}, {-0.1f, -0.9f, -0.5f}},
                {{0, 5, 6}, {0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}});  // steep face first: v stays open
    const uint32_t v = vertex_at(buffer, {0, 0, 0});
    ASSERT_EQ(buffer.vertex(v).face_count, 5u);
    const double from[3] = {0, 0, 0}, far[3] = {-0.5, -0.2, -0.1}, near[3] = {-0.3, 0.1, 0.4},
                 gentle[3] = {0.05, 0.05, 0};
    EXPECT_FALSE(moves_keep_faces_valid(buffer, v, from, far, kNoIndex, kNoIndex));
    EXPECT_TRUE(moves_keep_faces_valid(buffer, v, from, near, kNoIndex, kNoIndex));
    EXPECT_TRUE(moves_keep_faces_valid(buffer, v, from, gentle, kNoIndex, kNoIndex));
}

TEST(Collapse, CheapestFirstReducesAClosedMesh) {
    HalfEdgeBuffer buffer(256, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());
    CollapseQueue queue(256);
    rate_pending(buffer, queue);  // the six vertices left P_in as the octahedron closed
    EXPECT_TRUE(collapse_cheapest(buffer, queue));
    EXPECT_EQ(buffer.face_count(), 6u);
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_TRUE(collapse_cheapest(buffer, queue));
    EXPECT_EQ(buffer.face_count(), 4u);
    // A tetrahedron is left, which no collapse may reduce.
    EXPECT_FALSE(collapse_cheapest(buffer, queue));
    EXPECT_EQ(buffer.face_count(), 4u);
}

// An edge with an end on P_in is never queued (rate_edges_around passes such edges over rather
// than rating them only to forget them): true while a grid streams in row by row, with ratings
// as fans close and collapses between the rows.
TEST(Collapse, NoEdgeWithAnEndOnPInIsQueued) {
    constexpr int n = 12;
    const std::vector<std::array<float, 3>> points = curved_grid(n, 0.05f, 0.03f, 0);
    const std::vector<std::array<int, 3>> faces = grid_faces(n);
    HalfEdgeBuffer buffer(512, 0);
    CollapseQueue queue(512);
    size_t open_checked = 0, queued = 0, collapses = 0;
    const size_t per_row = 2 * (n - 1);
    for (size_t row = 0; row * per_row < faces.size(); ++row) {
        const std::vector<std::array<int, 3>> band(faces.begin() + long(row * per_row),
                                                   faces.begin() + long((row + 1) * per_row));
        add_indexed(buffer, points, band);
        rate_pending(buffer, queue);
        for (int i = 0; i < 4 && collapse_cheapest(buffer, queue); ++i) ++collapses;
        for (const uint32_t h : live_half_edges(buffer)) {
            const uint32_t a = buffer.corner_vertex(h), b = buffer.corner_vertex(next_in_face(h));
            if (buffer.queue_key(h) != kNotQueued) ++queued;
            if (((buffer.vertex(a).flags | buffer.vertex(b).flags) & kInHash) == 0) continue;
            ++open_checked;
            EXPECT_EQ(buffer.queue_key(h), kNotQueued) << "row " << row << ", half-edge " << h;
        }
    }
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_GT(open_checked, 100u);
    EXPECT_GT(queued, 100u);
    EXPECT_GT(collapses, 20u);
}

// After a collapse, the queued edges between free ends round the merged vertex keep their
// entries as lower bounds (kStale) instead of being rated again: each is rated when it comes up,
// which keeps the cheapest-first order only if its rating can only have risen. Checked after
// every collapse of a curved grid decimated as far as it goes: every kept key is at most the
// edge's rating now.
TEST(Collapse, EdgesKeptAfterACollapseAreRatedNoLowerThanTheirKeys) {
    constexpr int n = 14;
    const std::vector<std::array<float, 3>> points = curved_grid(n, 0.05f, -0.03f, 0.01f);
    HalfEdgeBuffer buffer(1024, 0);
    CollapseQueue queue(1024);
    add_indexed(buffer, points, grid_faces(n));
    buffer.finalize_all();
    rate_pending(buffer, queue);
    size_t kept = 0, collapses = 0;
    while (collapse_cheapest(buffer, queue)) {
        ++collapses;
        for (const uint32_t h : live_half_edges(buffer)) {
            const uint16_t key = buffer.queue_key(h);
            if (key == kNotQueued || (key & CollapseQueue::kStale) == 0) continue;
            ++kept;
            const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
            ASSERT_TRUE(collapse_target_free(buffer, h)) << "collapse " << collapses;
            const Quadric sum = buffer.quadric(p) + buffer.quadric(q);
            double x[3];
            const double now = sum.minimum(x) ? sum.error_at_minimum(x) : singular_merge(buffer, sum, p, q).error;
            EXPECT_LE(key & CollapseQueue::kBucketMask, CollapseQueue::bucket_of(now)) << "collapse " << collapses;
        }
    }
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_GT(collapses, 100u);
    EXPECT_GT(kept, 1000u);
}

TEST(Collapse, FreeInteriorCollapsePlacesTheVertexAtTheQuadricOptimum) {
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());  // closed: every vertex free
    const uint32_t top = vertex_at(buffer, {0, 0, 1}), east = vertex_at(buffer, {1, 0, 0});
    const uint32_t h = half_edge(buffer, top, east);
    ASSERT_TRUE(collapse_target_free(buffer, h));
    const Quadric sum = buffer.quadric(top) + buffer.quadric(east);
    double optimum[3];
    ASSERT_TRUE(sum.minimum(optimum));
    double at_east[3];
    buffer.position(east, at_east);
    const CollapsePlacement placement = collapse_placement(buffer, h);
    ASSERT_TRUE(moves_target(buffer, h, placement));
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(placement.target[i], optimum[i], 1e-6);
    // By symmetry the optimum lies on the plane y = 0 of the edge and on the plane bisecting
    // it (positions are relative to the buffer's origin), and is strictly cheaper than keeping
    // east where it is (the half-edge collapse).
    double at_top[3];
    buffer.position(top, at_top);
    EXPECT_NEAR(optimum[1], at_top[1], 1e-9);
    double along = 0;
    for (int i = 0; i < 3; ++i) along += (optimum[i] - 0.5 * (at_top[i] + at_east[i])) * (at_east[i] - at_top[i]);
    EXPECT_NEAR(along, 0, 1e-9);
    EXPECT_LT(placement.error, sum.error(at_east) * 0.9);
    ASSERT_TRUE(collapse_valid(buffer, h, placement.target));
    apply_collapse(buffer, h, placement.target);
    EXPECT_TRUE(buffer_consistent(buffer));
    double moved[3];
    buffer.position(east, moved);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(moved[i], placement.target[i]);
    EXPECT_NEAR(buffer.quadric(east).error(moved), placement.error, 1e-12);
}

TEST(Collapse, ConstrainedTargetKeepsTheHalfEdgeCollapse) {
    HalfEdgeBuffer buffer(64, 0);
    add_grid(buffer);
    const uint32_t inner = vertex_at(buffer, {1, 2, 0.1f});
    const uint32_t rim = vertex_at(buffer, {0, 2, 0.4f});
    const uint32_t centre = vertex_at(buffer, {2, 2, 0});
    // The rim is on P_in: never a moving target (and not a target at all).
    EXPECT_FALSE(collapse_target_free(buffer, half_edge(buffer, inner, rim)));
    buffer.finalize_all();
    // A hole's vertex (open edges) and a written vertex (P_out) do not move either.
    EXPECT_FALSE(collapse_target_free(buffer, half_edge(buffer, inner, rim)));
    const CollapsePlacement to_rim = collapse_placement(buffer, half_edge(buffer, inner, rim));
    EXPECT_FALSE(moves_target(buffer, half_edge(buffer, inner, rim), to_rim));
    double at_rim[3];
    buffer.position(rim, at_rim);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(to_rim.target[i], at_rim[i]);
    EXPECT_TRUE(collapse_target_free(buffer, half_edge(buffer, inner, centre)));
    buffer.freeze(centre, 0);
    EXPECT_FALSE(collapse_target_free(buffer, half_edge(buffer, inner, centre)));
    EXPECT_FALSE(moves_target(buffer, half_edge(buffer, inner, centre),
                              collapse_placement(buffer, half_edge(buffer, inner, centre))));
}

TEST(Collapse, HoleBoundaryCollapsesAlongItsEdgeAndBoundaryPlanesPriceCorners) {
    // A flat 5×5 grid: face quadrics vanish on the plane, so every error comes from the
    // boundary planes added when the rim left P_in.
    HalfEdgeBuffer buffer(64, 0);
    add_grid(buffer, 0.0f);
    const uint32_t mid = vertex_at(buffer, {2, 0, 0}), right = vertex_at(buffer, {3, 0, 0});
    const uint32_t corner = vertex_at(buffer, {0, 0, 0}), next = vertex_at(buffer, {1, 0, 0});
    // On P_in, the rim never collapses.
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, mid, right)));
    buffer.finalize_all();
    // A true hole: along its outgoing boundary edge only.
    EXPECT_TRUE(collapse_eligible(buffer, half_edge(buffer, mid, right)));
    EXPECT_FALSE(collapse_eligible(buffer, half_edge(buffer, mid, vertex_at(buffer, {2, 1, 0}))));
    // Along a straight stretch the outline does not change: free. At the corner it does.
    EXPECT_NEAR(collapse_placement(buffer, half_edge(buffer, mid, right)).error, 0, 1e-12);
    EXPECT_GT(collapse_placement(buffer, half_edge(buffer, corner, next)).error, 0.5);
    ASSERT_TRUE(collapse_valid(buffer, half_edge(buffer, mid, right)));
    apply_collapse(buffer, half_edge(buffer, mid, right));
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_EQ(buffer.face_count(), 31u);
    EXPECT_EQ(buffer.vertex(right).open_edges, 2u);
}

TEST(Collapse, BestOfAllScansUntilNoCollapseIsValid) {
    // An octahedron comes down two faces a scan to the tetrahedron, which no collapse may
    // reduce: then the scan says so.
    HalfEdgeBuffer buffer(64, 0);
    add_indexed(buffer, octahedron_points(), octahedron_faces());
    EXPECT_TRUE(collapse_best_of_all(buffer));
    EXPECT_EQ(buffer.face_count(), 6u);
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_TRUE(collapse_best_of_all(buffer));
    EXPECT_EQ(buffer.face_count(), 4u);
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_FALSE(collapse_best_of_all(buffer));
    EXPECT_EQ(buffer.face_count(), 4u);
}

TEST(Collapse, BestOfAllTakesTheCheapestValidCollapse) {
    // On the bowl, the scan does what taking the cheapest valid candidate by hand does (the
    // first of equals in buffer order).
    HalfEdgeBuffer scanned(256, 0), brute(256, 0);
    add_grid(scanned);
    add_grid(brute);
    double cheapest = INFINITY;
    uint32_t best = kNoIndex;
    CollapsePlacement best_placement{};
    for (const uint32_t h : live_half_edges(brute)) {
        if (!collapse_eligible(brute, h)) continue;
        const CollapsePlacement c = collapse_placement(brute, h);
        if (c.error < cheapest && collapse_valid(brute, h, c.target)) {
            cheapest = c.error;
            best = h;
            best_placement = c;
        }
    }
    ASSERT_NE(best, kNoIndex);
    apply_collapse(brute, best, best_placement.target);
    ASSERT_TRUE(collapse_best_of_all(scanned));
    EXPECT_EQ(scanned.face_count(), 30u);
    EXPECT_TRUE(buffer_consistent(scanned));
    for (uint32_t v = 0; v < 25; ++v) {
        EXPECT_EQ(scanned.vertex(v).flags & kAlive, brute.vertex(v).flags & kAlive) << v;
        EXPECT_EQ(scanned.vertex(v).face_count, brute.vertex(v).face_count) << v;
        double a[3], b[3];
        scanned.position(v, a);
        brute.position(v, b);
        EXPECT_EQ(std::vector<double>(a, a + 3), std::vector<double>(b, b + 3)) << v;
    }
}

// One test per veto of collapse_valid, each called directly on a case that trips it and one
// that does not.

TEST(CollapseVeto, SharesApexFindsTwoFacesBackToBack) {
    HalfEdgeBuffer pillow(64, 0);
    add_indexed(pillow, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {1, 0, 2}});
    ASSERT_EQ(pillow.face_count(), 2u);
    for (const uint32_t h : live_half_edges(pillow)) EXPECT_TRUE(shares_apex(pillow, h));
    HalfEdgeBuffer octahedron(64, 0);
    add_indexed(octahedron, octahedron_points(), octahedron_faces());
    for (const uint32_t h : live_half_edges(octahedron)) EXPECT_FALSE(shares_apex(octahedron, h));
}

TEST(CollapseVeto, CollapsesTetrahedronOnlyForAVertexOfThreeFacesClosingOne) {
    HalfEdgeBuffer tetrahedron(64, 0);
    add_indexed(tetrahedron, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
    const std::vector<uint32_t> edges = live_half_edges(tetrahedron);
    ASSERT_EQ(edges.size(), 12u);
    for (const uint32_t h : edges) EXPECT_TRUE(collapses_tetrahedron(tetrahedron, h));
    // The octahedron's vertices are in four faces each: nothing to close.
    HalfEdgeBuffer octahedron(64, 0);
    add_indexed(octahedron, octahedron_points(), octahedron_faces());
    for (const uint32_t h : live_half_edges(octahedron)) EXPECT_FALSE(collapses_tetrahedron(octahedron, h));
}

// A closed cone over a 40-gon whose base is a fan from ring vertex 0: the apex is in 40 faces
// (more than the link test's small-fan limit, so collapses into it take the hub path), and ring
// vertex 0 is a neighbour of every ring vertex, so many collapses pinch. pinches_link must agree
// with the brute-force link condition on every half-edge, hub or not.
TEST(CollapseVeto, PinchesLinkAgreesWithTheLinkConditionOnHubsAndSmallFans) {
    constexpr int n = 40;
    static_assert(n > kMaxMovedFaces);
    std::vector<std::array<float, 3>> points;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * 3.141592653589793 * i / n;
        points.push_back({float(std::cos(a)), float(std::sin(a)), 0});
    }
    points.push_back({0, 0, 1});
    std::vector<std::array<int, 3>> faces;
    for (int i = 0; i < n; ++i) faces.push_back({i, (i + 1) % n, n});
    for (int i = 1; i + 1 < n; ++i) faces.push_back({0, i + 1, i});
    HalfEdgeBuffer buffer(256, 0);
    add_indexed(buffer, points, faces);
    ASSERT_EQ(buffer.face_count(), size_t{2 * n - 2});
    int pinched = 0, clear = 0, hub_pinched = 0, hub_clear = 0;
    for (const uint32_t h : live_half_edges(buffer)) {
        const uint32_t p = buffer.corner_vertex(h), q = buffer.corner_vertex(next_in_face(h));
        if (shares_apex(buffer, h) || collapses_tetrahedron(buffer, h)) continue;
        const std::set<uint32_t> np = neighbours(buffer, p), nq = neighbours(buffer, q);
        size_t common = 0;
        for (const uint32_t x : np) common += nq.count(x);
        const bool pinch = common > 2;
        EXPECT_EQ(pinches_link(buffer, h), pinch) << "half-edge " << p << "->" << q;
        const bool hub = buffer.vertex(q).face_count > 32;
        (pinch ? (hub ? hub_pinched : pinched) : (hub ? hub_clear : clear))++;
    }
    // Both outcomes seen on both paths.
    EXPECT_GT(pinched, 0);
    EXPECT_GT(clear, 0);
    EXPECT_GT(hub_pinched, 0);
    EXPECT_GT(hub_clear, 0);
}

TEST(CollapseVeto, MayDoubleWrittenEdgeOnlyIntoAWrittenVertexWithAnotherWrittenNeighbour) {
    HalfEdgeBuffer buffer(64, 0);
    add_grid(buffer);
    const uint32_t centre = vertex_at(buffer, {2, 2, 0});
    const uint32_t west = vertex_at(buffer, {1, 2, 0.1f}), east = vertex_at(buffer, {3, 2, 0.1f});
    const uint32_t h = half_edge(buffer, centre, west);
    // Nothing written: no veto.
    EXPECT_FALSE(may_double_written_edge(buffer, h));
    // A written neighbour of p, but q is not written: the new edge is in core, no veto.
    buffer.freeze(east, 0);
    EXPECT_FALSE(may_double_written_edge(buffer, h));
    // q written and p's other neighbour written: west–east may already be in the output.
    buffer.freeze(west, 1);
    EXPECT_TRUE(may_double_written_edge(buffer, h));
    // The written neighbours r and s of the edge itself do not count.
    HalfEdgeBuffer other(64, 0);
    add_grid(other);
    const uint32_t c = vertex_at(other, {2, 2, 0}), w = vertex_at(other, {1, 2, 0.1f});
    const uint32_t g = half_edge(other, c, w);
    const uint32_t r = other.corner_vertex(prev_in_face(g));  // the third vertex of g's face
    other.freeze(w, 2);
    other.freeze(r, 3);
    EXPECT_FALSE(may_double_written_edge(other, g));
}

// A flat 5×5 vertex grid without the face (1,1) (2,1) (2,2), or also without (2,2) (3,2) (3,3)
// (`second`): holes of three edges, which touch at (2,2) when there are two.
void add_triangle_holes(HalfEdgeBuffer& buffer, bool second) {
    std::vector<std::array<int, 3>> faces;
    for (const auto& f : grid_faces(5))
        if (f != std::array<int, 3>{6, 7, 12} && (!second || f != std::array<int, 3>{12, 13, 18})) faces.push_back(f);
    add_indexed(buffer, curved_grid(5, 0, 0, 0), faces);
    buffer.finalize_all();
}

TEST(Collapse, HoleOfThreeEdgesClosesAndItsCornersBecomeInterior) {
    HalfEdgeBuffer buffer(64, 0);
    add_triangle_holes(buffer, false);
    const uint32_t p = vertex_at(buffer, {2, 1, 0}), q = vertex_at(buffer, {1, 1, 0}), a = vertex_at(buffer, {2, 2, 0});
    const uint32_t h = half_edge(buffer, p, q);  // the hole's loop runs p→q→a→p
    ASSERT_EQ(buffer.twin(h), kOpenEdge);
    ASSERT_TRUE(collapse_eligible(buffer, h));
    const ClosedHole hole = closed_hole(buffer, h);
    EXPECT_EQ(hole.a, a);
    EXPECT_EQ(hole.qa, half_edge(buffer, q, a));
    EXPECT_EQ(hole.ap, half_edge(buffer, a, p));
    // a is a common neighbour of p and q besides the face's apex: the link condition alone
    // refused this, and the hole stayed.
    EXPECT_FALSE(closes_hole_badly(buffer, h));
    EXPECT_FALSE(pinches_link(buffer, h));
    ASSERT_TRUE(collapse_valid(buffer, h));
    apply_collapse(buffer, h);
    EXPECT_TRUE(buffer_consistent(buffer));
    EXPECT_EQ(buffer.face_count(), 30u);
    for (const uint32_t v : {q, a}) {
        EXPECT_EQ(buffer.vertex(v).open_edges, 0u);
        EXPECT_EQ(buffer.vertex(v).flags & (kManyFans | kOpenFans), 0);
        for (uint32_t c = buffer.vertex(v).first_corner; c != kNoIndex; c = buffer.next_corner(c))
            EXPECT_TRUE(is_half_edge(buffer.twin(c)));
    }
    EXPECT_EQ(buffer.twin(hole.qa), hole.ap);
}

TEST(Collapse, HoleOfThreeEdgesWhereLoopsTouchClosesAndTheFansJoin) {
    HalfEdgeBuffer buffer(64, 0);
    add_triangle_holes(buffer, true);
    const uint32_t p = vertex_at(buffer, {2, 1, 0}), q = vertex_at(buffer, {1, 1, 0}), a = vertex_at(buffer, {2, 2, 0});
    ASSERT_EQ(buffer.vertex(a).flags & (kManyFans | kOpenFans), kManyFans | kOpenFans);
    const uint32_t h = half_edge(buffer, p, q);
    EXPECT_EQ(closed_hole(buffer, h).a, a);
    ASSERT_TRUE(collapse_valid(buffer, h));
    apply_collapse(buffer, h);
    EXPECT_TRUE(buffer_consistent(buffer));
    // a is on the other hole alone now: one open fan, a rim vertex that slides along it.
    EXPECT_EQ(buffer.vertex(a).flags & (kManyFans | kOpenFans), 0);
    EXPECT_EQ(buffer.vertex(a).open_edges, 2u);
    EXPECT_TRUE(collapse_eligible(buffer, half_edge(buffer, a, vertex_at(buffer, {3, 3, 0}))));
}

TEST(Collapse, HoleOfThreeEdgesStaysWhenItsFacesWouldEndBackToBack) {
    // Three faces of a tetrahedron round the apex 3: the open base 0→1→2 is a hole of three
    // edges whose faces on 1→2 and 2→0 share the apex; closing it would fold them together.
    HalfEdgeBuffer buffer(16, 0);
    add_indexed(buffer, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3f, 0.3f, 1}}, {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}});
    buffer.finalize_all();
    const uint32_t h = half_edge(buffer, vertex_at(buffer, {0, 0, 0}), vertex_at(buffer, {1, 0, 0}));
    ASSERT_TRUE(collapse_eligible(buffer, h));
    EXPECT_EQ(closed_hole(buffer, h).a, vertex_at(buffer, {0, 1, 0}));
    EXPECT_TRUE(closes_hole_badly(buffer, h));
    EXPECT_FALSE(collapse_valid(buffer, h));
    // A lone triangle's edge is on no hole.
    HalfEdgeBuffer lone(16, 0);
    add_indexed(lone, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
    lone.finalize_all();
    EXPECT_EQ(closed_hole(lone, half_edge(lone, vertex_at(lone, {0, 0, 0}), vertex_at(lone, {1, 0, 0}))).a, kNoIndex);
}
