// decimate/attribute_store.hpp: channels beside the half-edge buffer, seam vertices, and what
// collapses and writes do with them.
#include "decimate/attribute_store.hpp"

#include "decimate/collapse.hpp"
#include "decimate/halfedge_buffer.hpp"

#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <vector>

namespace {

using namespace meshstream;
using namespace meshstream::decimate;

io::Channels uv_and_material() {
    io::Channels c;
    c.uv_sets = 1;
    c.material = true;
    return c;
}

// A fan of four triangles round (0,0,0), corner values given per triangle (3 × 2 floats) and
// one material per triangle.
struct Fan {
    HalfEdgeBuffer buffer{64, 0};
    AttributeStore store{AttributeLayout(uv_and_material(), {}), 64};
    std::vector<uint32_t> faces;
    Fan() { buffer.set_attributes(&store); }
    void add(const std::array<float, 9>& tri, const std::array<float, 6>& uv, uint32_t material) {
        const auto added = buffer.add_triangle(tri.data());
        ASSERT_NE(added.face, kNoIndex);
        store.add_face(buffer, added.face, uv.data(), material, nullptr);
        faces.push_back(added.face);
    }
    uint32_t centre() const { return buffer.corner_vertex(half_edge(faces[0], 0)); }
};

const std::array<std::array<float, 9>, 4> kFan = {{
    {0, 0, 0, 1, 0, 0, 0, 1, 0},
    {0, 0, 0, 0, 1, 0, -1, 0, 0},
    {0, 0, 0, -1, 0, 0, 0, -1, 0},
    {0, 0, 0, 0, -1, 0, 1, 0, 0},
}};

TEST(AttributeStore, CornersThatAgreeMakeNoSeam) {
    Fan fan;
    for (const auto& tri : kFan) {
        std::array<float, 6> uv;
        for (int k = 0; k < 3; ++k) uv[2 * k] = tri[3 * k], uv[2 * k + 1] = tri[3 * k + 1];  // uv = xy
        fan.add(tri, uv, 0);
    }
    EXPECT_EQ(fan.buffer.vertex(fan.centre()).flags & kSeam, 0);
    EXPECT_EQ(fan.store.seam_vertices(), 0u);
}

// The fan with triangles 2 and 3 (y ≤ 0) from another texture chart (u shifted by 10): the seam
// runs from (−1, 0) through the centre to (1, 0); (0, ±1) lie inside one chart each.
void add_two_charts(Fan& fan) {
    for (size_t t = 0; t < kFan.size(); ++t) {
        std::array<float, 6> uv;
        for (int k = 0; k < 3; ++k)
            uv[2 * k] = kFan[t][3 * k] + (t >= 2 ? 10.0f : 0.0f), uv[2 * k + 1] = kFan[t][3 * k + 1];
        fan.add(kFan[t], uv, 0);
    }
}

TEST(AttributeStore, ASeamVertexCollapsesOnlyAlongItsSeamAndNeverMoves) {
    Fan fan;
    add_two_charts(fan);
    const uint32_t c = fan.centre();
    EXPECT_NE(fan.buffer.vertex(c).flags & kSeam, 0);
    EXPECT_EQ(fan.store.seam_vertices(), 3u);
    fan.buffer.finalize_all();
    // From the centre: along the seam (to (±1, 0)) yes, across it (to (0, ±1)) no.
    int along = 0;
    for (uint32_t f : fan.faces)
        for (uint32_t k = 0; k < 3; ++k) {
            const uint32_t h = half_edge(f, k);
            if (fan.buffer.corner_vertex(h) != c) continue;
            const float to_y = fan.buffer.vertex(fan.buffer.corner_vertex(next_in_face(h))).pos[1];
            EXPECT_EQ(collapse_eligible(fan.buffer, h), to_y == 0) << "towards y = " << to_y;
            along += to_y == 0;
        }
    EXPECT_EQ(along, 2);
    EXPECT_FALSE(collapse_target_free(fan.buffer, half_edge(fan.faces[0], 2)));  // (0,1,0)→centre
}

TEST(AttributeStore, ASlideGivesEachSideTheValueItsNewVertexHasThere) {
    Fan fan;
    add_two_charts(fan);
    fan.buffer.finalize_all();
    const uint32_t h = half_edge(fan.faces[0], 0);  // centre → (1, 0), along the seam
    ASSERT_TRUE(fan.store.slides(fan.buffer, h));
    fan.store.merge(fan.buffer, h);
    // The centre's corners on triangle 1 (chart A) and triangle 2 (chart B) now show (1, 0)'s
    // values on their charts: (1, 0) and (11, 0).
    EXPECT_EQ(fan.store.corner_value(half_edge(fan.faces[1], 0))[0], 1.0f);
    EXPECT_EQ(fan.store.corner_value(half_edge(fan.faces[2], 0))[0], 11.0f);
    EXPECT_EQ(fan.store.corner_value(half_edge(fan.faces[2], 0))[1], 0.0f);
}

TEST(AttributeStore, ASlideOffAStraightSeamCostsNothingAndOffABentOneCosts) {
    Fan fan;
    add_two_charts(fan);
    fan.buffer.finalize_all();
    double geometric = 0, attribute = 0;
    fan.store.slide_error(fan.buffer, half_edge(fan.faces[0], 0), geometric, attribute);
    EXPECT_NEAR(geometric, 0, 1e-12);  // the centre lies on the line from (−1, 0) to (1, 0)
    EXPECT_NEAR(attribute, 0, 1e-12);  // and its values halfway between theirs on each chart
    // The same seam bent: the centre lifted off the line by 0.5.
    Fan bent;
    for (size_t t = 0; t < kFan.size(); ++t) {
        std::array<float, 9> tri = kFan[t];
        for (int k = 0; k < 3; ++k)
            if (tri[3 * k] == 0 && tri[3 * k + 1] == 0) tri[3 * k + 2] = 0.5f;
        std::array<float, 6> uv;
        for (int k = 0; k < 3; ++k)
            uv[2 * k] = kFan[t][3 * k] + (t >= 2 ? 10.0f : 0.0f), uv[2 * k + 1] = kFan[t][3 * k + 1];
        bent.add(tri, uv, 0);
    }
    bent.buffer.finalize_all();
    geometric = attribute = 0;
    bent.store.slide_error(bent.buffer, half_edge(bent.faces[0], 0), geometric, attribute);
    EXPECT_NEAR(geometric, 0.25 * 2, 1e-9);  // 0.5² off, weighted by |(−1,0) − (1,0)| = 2
}

TEST(AttributeStore, DifferentMaterialsMakeASeam) {
    Fan fan;
    for (size_t t = 0; t < kFan.size(); ++t) {
        std::array<float, 6> uv{};
        fan.add(kFan[t], uv, t == 0 ? 1 : 0);
    }
    EXPECT_NE(fan.buffer.vertex(fan.centre()).flags & kSeam, 0);
    EXPECT_EQ(fan.store.material(fan.faces[0]), 1u);
    EXPECT_EQ(fan.store.material(fan.faces[1]), 0u);
}

struct Strip {
    HalfEdgeBuffer buffer{64, 0};
    AttributeStore store{AttributeLayout(uv_only(), {}), 64};
    static io::Channels uv_only() {
        io::Channels c;
        c.uv_sets = 1;
        return c;
    }
    Strip() { buffer.set_attributes(&store); }
    HalfEdgeBuffer::Added add(const std::array<float, 9>& tri, const std::array<float, 6>& uv) {
        const auto a = buffer.add_triangle(tri.data());
        store.add_face(buffer, a.face, uv.data(), 0, nullptr);
        return a;
    }
};

TEST(AttributeStore, ACollapseIntoASeamVertexTakesItsValueOnThatSide) {
    // Two triangles with uv = xy; (1,1) also belongs to a third triangle of another chart.
    Strip s;
    const auto a = s.add({0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 1, 0, 1, 1});
    s.add({0, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 0, 1, 1, 0, 1});
    s.add({1, 1, 0, 2, 1, 0, 1, 2, 0}, {7, 7, 6, 6, 5, 5});
    const uint32_t corner = a.vertex[1], seam = a.vertex[2];  // (1,0) and (1,1)
    ASSERT_EQ(s.buffer.vertex(corner).flags & kSeam, 0);
    ASSERT_NE(s.buffer.vertex(seam).flags & kSeam, 0);
    const double area_before = s.store.quadric_area(seam);
    // (1,0) → (1,1) along the open edge of face a: one side only, allowed.
    const uint32_t h = half_edge(a.face, 1);
    EXPECT_TRUE(s.store.seam_allows(s.buffer, h));
    s.store.merge(s.buffer, h);
    const float* moved = s.store.corner_value(half_edge(a.face, 1));
    EXPECT_EQ(moved[0], 1.0f);  // (1,1)'s value on this chart, not (7,7)
    EXPECT_EQ(moved[1], 1.0f);
    EXPECT_NEAR(s.store.quadric_area(seam), area_before + s.store.quadric_area(corner), 1e-12);
}

TEST(AttributeStore, NoCollapseAlongASeamEdgeIntoASeamVertex) {
    // Faces b and c share the edge (0,0)–(0,1); (0,0) shows (0,0) on b and (9,9) on c, (0,1)
    // shows (0,1) on both: collapsing (0,1) into (0,0) would not know which value to take.
    Strip s;
    s.add({0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 1, 0, 1, 1});
    const auto b = s.add({0, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 0, 1, 1, 0, 1});
    s.add({0, 0, 0, 0, 1, 0, -1, 0.5f, 0}, {9, 9, 0, 1, 8, 8});
    const uint32_t h = half_edge(b.face, 2);  // (0,1) → (0,0)
    ASSERT_NE(s.buffer.vertex(s.buffer.corner_vertex(next_in_face(h))).flags & kSeam, 0);
    ASSERT_EQ(s.buffer.vertex(s.buffer.corner_vertex(h)).flags & kSeam, 0);
    EXPECT_FALSE(s.store.seam_allows(s.buffer, h));
    s.buffer.finalize_all();
    EXPECT_FALSE(collapse_eligible(s.buffer, h));
}

TEST(AttributeStore, AMergeIsRatedByTheReducedSumOfBothQuadrics) {
    // Triangles away from the buffer's origin, with a uv field that is not linear across them:
    // p = (11, 5, 0.2) and q = (10.5, 6, 0.1) share the edge of the first two; q has a third.
    Strip s;
    const auto a = s.add({10, 5, 0, 11, 5, 0.2f, 10.5f, 6, 0.1f}, {0, 0, 1, 0.3f, 0.2f, 1});
    s.add({11, 5, 0.2f, 11.5f, 6, 0, 10.5f, 6, 0.1f}, {1, 0.3f, 0.9f, 1.1f, 0.2f, 1});
    s.add({10.5f, 6, 0.1f, 11.5f, 6, 0, 10.8f, 7, 0.3f}, {0.2f, 1, 0.9f, 1.1f, 0.1f, 2.5f});  // q's only
    const uint32_t p = a.vertex[1], q = a.vertex[2];
    const uint32_t h = half_edge(a.face, 1);  // p→q
    ASSERT_EQ(s.buffer.corner_vertex(h), p);
    const Quadric merged = s.store.merged_reduced(s.buffer, p, q);
    const Quadric alone_p = s.store.reduced(s.buffer, p), alone_q = s.store.reduced(s.buffer, q);
    std::vector<std::array<double, 3>> at(3);
    s.buffer.position(p, at[0].data());
    s.buffer.position(q, at[1].data());
    for (int i = 0; i < 3; ++i) at[2][i] = 0.5 * (at[0][i] + at[1][i]) + 0.1;
    // One value for both vertices costs at least their own best values each, and more here.
    double excess = 0;
    for (const auto& x : at) {
        EXPECT_GE(merged.error(x.data()), alone_p.error(x.data()) + alone_q.error(x.data()) - 1e-9);
        excess += merged.error(x.data()) - alone_p.error(x.data()) - alone_q.error(x.data());
    }
    EXPECT_GT(excess, 1e-4);
    // The quadric q holds once p merged into it is the same, reduced by the one-vertex path.
    s.store.merge(s.buffer, h);
    const Quadric after = s.store.reduced(s.buffer, q);
    for (const auto& x : at) EXPECT_NEAR(after.error(x.data()), merged.error(x.data()), 1e-5);
}

TEST(AttributeStore, AVertexThatAbsorbedCollapsesSettlesAtItsQuadricsValuesWithinItsInputsRange) {
    // Face (0,0) (1,0) (1,1) with uv = xy; (0,0) merges into (1,0), which then stands for inputs
    // with u in [0, 1] and v = 0.
    Strip s;
    const auto a = s.add({0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 1, 0, 1, 1});
    const uint32_t v = a.vertex[1];
    s.store.merge(s.buffer, half_edge(a.face, 0));
    s.buffer.set_partner(v, s.buffer.vertex(a.vertex[0]).pos);
    const double to[3] = {0.25, 0, 0};
    s.buffer.set_position(v, to);
    s.store.settle(s.buffer, v);
    EXPECT_NEAR(s.store.vertex_value(v)[0], 0.25, 1e-6);  // the field's value where it is now
    EXPECT_NEAR(s.store.vertex_value(v)[1], 0.0, 1e-6);
    // Moved where the field says v = 0.5, beyond every input it stands for: kept at their 0.
    const double off[3] = {0.5, 0.5, 0};
    s.buffer.set_position(v, off);
    s.store.settle(s.buffer, v);
    EXPECT_NEAR(s.store.vertex_value(v)[0], 0.5, 1e-6);
    EXPECT_EQ(s.store.vertex_value(v)[1], 0.0f);
    // A vertex that absorbed nothing keeps its input value.
    s.store.settle(s.buffer, a.vertex[2]);
    EXPECT_EQ(s.store.vertex_value(a.vertex[2])[0], 1.0f);
}

TEST(AttributeStore, NonFiniteValuesBecomeZeroAndAreCounted) {
    Strip s;
    float v[4] = {1, std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity(), 2};
    s.store.sanitize(v, 4);
    EXPECT_EQ(v[0], 1);
    EXPECT_EQ(v[1], 0);
    EXPECT_EQ(v[2], 0);
    EXPECT_EQ(s.store.non_finite_values(), 2u);
}

}  // namespace
