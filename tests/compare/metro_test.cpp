// Tests of tools/metro.{hpp,cpp} and the `compare` command: exact zero for a mesh against
// itself, the Hausdorff distance of a translated sphere, the closed-form RMS of a tilted square
// against a flat one, edge counts on tiny hand-made meshes (in memory and spilled), which mesh
// is held in memory, and the CLI's exit codes and messages.
#include "compare/metro.hpp"
#include "io/error.hpp"
#include "io/format.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace meshstream;
using namespace meshstream::compare;

using meshstream::test::slurp;
using meshstream::test::TempDir;

namespace {

void push_tri(std::vector<float>& out, const float* a, const float* b, const float* c) {
    out.insert(out.end(), a, a + 3);
    out.insert(out.end(), b, b + 3);
    out.insert(out.end(), c, c + 3);
}

// A closed unit sphere: an octahedron subdivided `levels` times, vertices pushed to radius 1.
// Midpoints are computed symmetrically, so shared vertices are bit-identical (a welded,
// closed manifold).
std::vector<float> sphere(int levels, float dx = 0) {
    std::vector<float> tris;
    const float p[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (const auto& f : faces) push_tri(tris, p[f[0]], p[f[1]], p[f[2]]);
    for (int l = 0; l < levels; ++l) {
        std::vector<float> next;
        auto mid = [](const float* a, const float* b, float* m) {
            float s[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
            float len = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            for (int k = 0; k < 3; ++k) m[k] = s[k] / len;
        };
        for (size_t t = 0; t < tris.size(); t += 9) {
            const float *a = &tris[t], *b = &tris[t + 3], *c = &tris[t + 6];
            float ab[3], bc[3], ca[3];
            mid(a, b, ab);
            mid(b, c, bc);
            mid(c, a, ca);
            push_tri(next, a, ab, ca);
            push_tri(next, ab, b, bc);
            push_tri(next, ca, bc, c);
            push_tri(next, ab, bc, ca);
        }
        tris.swap(next);
    }
    for (size_t i = 0; i < tris.size(); i += 3) tris[i] += dx;
    return tris;
}

void write_mesh(const fs::path& path, const std::vector<float>& xyz) {
    io::Output out = io::open_output(path.string(), "", {});
    io::TriangleChunk chunk(1000);
    for (size_t t = 0; t < xyz.size(); t += 9) {
        std::memcpy(chunk.push_slot(), &xyz[t], 9 * sizeof(float));
        if (chunk.full()) {
            out.write(chunk);
            chunk.clear();
        }
    }
    if (!chunk.empty()) out.write(chunk);
    out.finish();
}

EdgeCounts count_edges(const std::vector<float>& xyz, uint64_t budget = uint64_t{256} << 20, bool* spilled = nullptr) {
    EdgeCounter counter(budget);
    for (size_t t = 0; t < xyz.size(); t += 9) counter.add_triangle(&xyz[t]);
    if (spilled) *spilled = counter.spilled();
    return counter.finish();
}

}  // namespace

TEST(Metro, OneSidedHausdorffIsTheFarthestSampleOfOneSideOnly) {
    // A unit sphere against itself moved by 0.25 along x: 0.25. Against its half x >= 0: the
    // pole (-1, 0, 0) is sqrt 2 from the half's rim (the circle x = 0), while the half lies on
    // the whole (0, within float rounding).
    const std::vector<float> s = sphere(5);
    EXPECT_NEAR(one_sided_hausdorff(s, sphere(5, 0.25f), 200000, 1), 0.25, 0.01);
    std::vector<float> half;
    for (size_t t = 0; t < s.size(); t += 9)
        if (s[t] >= 0 && s[t + 3] >= 0 && s[t + 6] >= 0) half.insert(half.end(), &s[t], &s[t] + 9);
    EXPECT_NEAR(one_sided_hausdorff(s, half, 200000, 1), std::sqrt(2.0), 0.02);
    EXPECT_LT(one_sided_hausdorff(half, s, 200000, 1), 1e-6);
    // The same samples for the same seed; nothing to measure against: 0.
    EXPECT_EQ(one_sided_hausdorff(s, half, 5000, 7), one_sided_hausdorff(s, half, 5000, 7));
    EXPECT_EQ(one_sided_hausdorff(s, {}, 5000, 1), 0.0);
    EXPECT_EQ(one_sided_hausdorff({}, s, 5000, 1), 0.0);
}

TEST(Metro, MeshAgainstItselfIsZero) {
    // Samples on the held mesh are stored as floats, so a sample may sit off its own triangle by
    // float rounding of its coordinates: at most ~2^-24 · |coordinate| ≈ 6e-8 on a unit sphere.
    // Samples on the streamed mesh are doubles and land on their triangle to ~1e-16.
    std::vector<float> s = sphere(4);
    CompareOptions options;
    options.samples = 100'000;
    CompareResult r = compare_meshes(memory_source("a", s), memory_source("b", s), options);
    EXPECT_EQ(r.a.triangles, 8u * 256u);
    EXPECT_LT(r.hausdorff(), 1e-6);
    EXPECT_LT(r.rms(), 1e-7);
    EXPECT_NEAR(r.a_to_b.samples, 100'000, 2'000);
    EXPECT_NEAR(r.b_to_a.samples, 100'000, 2'000);
}

TEST(Metro, MeshFarFromTheOriginAgainstItselfIsStillZero) {
    // The same sphere at UTM-like coordinates: a 0.25 m float step in y there. Held samples
    // stored as absolute floats were off their own triangles by up to half a step.
    std::vector<float> s = sphere(4);
    for (size_t i = 0; i < s.size(); i += 3) {
        s[i] = float(500000 + 10 * double(s[i]));
        s[i + 1] = float(4000000 + 10 * double(s[i + 1]));
        s[i + 2] = float(100 + 10 * double(s[i + 2]));
    }
    CompareOptions options;
    options.samples = 50'000;
    CompareResult r = compare_meshes(memory_source("a", s), memory_source("b", s), options);
    EXPECT_LT(r.hausdorff(), 1e-5);  // 1e-6 of the size; 0.09 m before
    EXPECT_LT(r.rms(), 1e-6);
}

TEST(Metro, TranslatedSphereHausdorffIsTheOffset) {
    // A closed surface translated by d is within d of the original everywhere (p - d lies on
    // it), and at the facets facing the translation the distance is d·cos(angle between facet
    // normal and the direction). The subdivided octahedron has facets within ~3° of ±x, so
    // cos ≥ 0.998, and 200 000 samples put some on those facets: expect [0.99 d, d].
    const float d = 0.01f;
    CompareOptions options;
    options.samples = 200'000;
    CompareResult r = compare_meshes(memory_source("a", sphere(5)), memory_source("b", sphere(5, d)), options);
    EXPECT_LE(r.hausdorff(), d * (1 + 1e-5));
    EXPECT_GE(r.a_to_b.max, 0.99 * d);
    EXPECT_GE(r.b_to_a.max, 0.99 * d);
    // Mean of d·|cos| over a sphere is d/2; the polyhedron is close to that.
    EXPECT_NEAR(r.a_to_b.mean, d / 2, 0.02 * d);
    EXPECT_NEAR(r.diagonal, 2 * std::sqrt(3.0), 1e-6);
}

TEST(Metro, WithoutEdgesTheDistancesAreTheSameAndNoEdgeIsCounted) {
    CompareOptions options;
    options.samples = 20'000;
    const CompareResult with = compare_meshes(memory_source("a", sphere(3)), memory_source("b", sphere(3, 0.05f)), options);
    options.edges = false;
    const CompareResult without = compare_meshes(memory_source("a", sphere(3)), memory_source("b", sphere(3, 0.05f)), options);
    EXPECT_GT(with.a.edges.edges, 0u);
    EXPECT_EQ(without.a.edges.edges, 0u);
    EXPECT_EQ(without.b.edges.edges, 0u);
    EXPECT_EQ(without.a_to_b.max, with.a_to_b.max);
    EXPECT_EQ(without.b_to_a.max, with.b_to_a.max);
    EXPECT_EQ(without.a_to_b.rms, with.a_to_b.rms);
    EXPECT_EQ(without.b_to_a.mean, with.b_to_a.mean);
}

TEST(Metro, TiltedSquareAgainstFlatSquareHasClosedFormRms) {
    // A = z = s·x over the unit square, B = z = 0. From A, each point (x, y, s x) projects
    // inside B at distance s·x with x uniform on [0, 1] (area-uniform on the tilted square):
    // RMS = s/√3, mean = s/2, max = s. From B, (x, y, 0) projects inside A at s·x/√(1+s²).
    // The relative standard error of the RMS estimate is about 0.45/√N (var of x² = 4/45),
    // 0.1 % at N = 200 000, so 1 % is a 10-sigma bound.
    const float s = 0.2f;
    float a00[3] = {0, 0, 0}, a10[3] = {1, 0, s}, a11[3] = {1, 1, s}, a01[3] = {0, 1, 0};
    float b00[3] = {0, 0, 0}, b10[3] = {1, 0, 0}, b11[3] = {1, 1, 0}, b01[3] = {0, 1, 0};
    std::vector<float> a, b;
    push_tri(a, a00, a10, a11);
    push_tri(a, a00, a11, a01);
    push_tri(b, b00, b10, b11);
    push_tri(b, b00, b11, b01);
    CompareOptions options;
    options.samples = 200'000;
    CompareResult r = compare_meshes(memory_source("tilted", a), memory_source("flat", b), options);
    EXPECT_NEAR(r.a_to_b.rms, s / std::sqrt(3.0), 0.01 * s);
    EXPECT_NEAR(r.a_to_b.mean, s / 2, 0.01 * s);
    EXPECT_NEAR(r.a_to_b.max, s, 0.01 * s);
    EXPECT_LE(r.a_to_b.max, s * (1 + 1e-6));
    double k = 1 / std::sqrt(1 + double(s) * s);
    EXPECT_NEAR(r.b_to_a.rms, k * s / std::sqrt(3.0), 0.01 * s);
    EXPECT_NEAR(r.rms(), s / std::sqrt(3.0), 0.01 * s);
    EXPECT_EQ(r.a.edges.boundary_edges, 4u);
    EXPECT_EQ(r.b.edges.edges, 5u);
}

TEST(Metro, SameSeedSameFiguresOtherSeedOtherSamples) {
    CompareOptions options;
    options.samples = 20'000;
    auto run = [&](uint64_t seed) {
        options.seed = seed;
        return compare_meshes(memory_source("a", sphere(3)), memory_source("b", sphere(3, 0.05f)), options);
    };
    CompareResult r1 = run(7), r2 = run(7), r3 = run(8);
    EXPECT_EQ(r1.a_to_b.rms, r2.a_to_b.rms);
    EXPECT_EQ(r1.b_to_a.max, r2.b_to_a.max);
    EXPECT_NE(r1.a_to_b.rms, r3.a_to_b.rms);
}

TEST(EdgeCounter, OpenQuadHasFourBoundaryEdges) {
    float p0[3] = {0, 0, 0}, p1[3] = {1, 0, 0}, p2[3] = {1, 1, 0}, p3[3] = {0, 1, 0};
    std::vector<float> quad;
    push_tri(quad, p0, p1, p2);
    push_tri(quad, p0, p2, p3);
    EdgeCounts c = count_edges(quad);
    EXPECT_EQ(c.edges, 5u);
    EXPECT_EQ(c.boundary_edges, 4u);
    EXPECT_EQ(c.non_manifold_edges, 0u);
}

TEST(EdgeCounter, ThreeTrianglesOnOneEdgeIsOneNonManifoldEdge) {
    float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c1[3] = {0.5f, 1, 0}, c2[3] = {0.5f, -1, 0}, c3[3] = {0.5f, 0, 1};
    std::vector<float> fan;
    push_tri(fan, a, b, c1);
    push_tri(fan, b, a, c2);  // opposite winding: orientation does not matter for counting
    push_tri(fan, a, b, c3);
    EdgeCounts c = count_edges(fan);
    EXPECT_EQ(c.edges, 7u);
    EXPECT_EQ(c.boundary_edges, 6u);
    EXPECT_EQ(c.non_manifold_edges, 1u);
}

TEST(EdgeCounter, NegativeZeroWeldsWithZeroAndTrianglesWithARepeatedCornerAddNoEdges) {
    float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, nc[3] = {-0.0f, 1, -0.0f}, d[3] = {1, 1, 0};
    float e[3] = {5, 5, 5}, f[3] = {6, 5, 5};
    std::vector<float> tris;
    push_tri(tris, a, b, c);
    push_tri(tris, nc, b, d);  // shares b-c through -0 == +0
    push_tri(tris, e, e, f);   // no surface: adds nothing
    push_tri(tris, a, b, b);   // lies on a-b: counted, a-b would have three uses (non-manifold)
    EdgeCounts counts = count_edges(tris);
    EXPECT_EQ(counts.edges, 5u);           // ab, bc, ca, bd, dc
    EXPECT_EQ(counts.boundary_edges, 4u);  // ab, ca, bd, dc
    EXPECT_EQ(counts.non_manifold_edges, 0u);
}

TEST(EdgeCounter, SpilledCountsEqualInMemoryCounts) {
    // Budget 0 keeps 1024 edge records in memory, so 8·4^4 = 2048 triangles spill.
    std::vector<float> closed = sphere(4);
    closed.resize(closed.size() - 9 * 5);  // open it: 5 triangles fewer
    float a[3] = {2, 0, 0}, b[3] = {3, 0, 0}, c1[3] = {2, 1, 0}, c2[3] = {2, -1, 0}, c3[3] = {2, 0, 1};
    push_tri(closed, a, b, c1);
    push_tri(closed, a, b, c2);
    push_tri(closed, a, b, c3);
    bool spilled = false, in_memory_spilled = true;
    EdgeCounts in_memory = count_edges(closed, uint64_t{256} << 20, &in_memory_spilled);
    EdgeCounts spilled_counts = count_edges(closed, 0, &spilled);
    EXPECT_FALSE(in_memory_spilled);
    EXPECT_TRUE(spilled);
    EXPECT_EQ(spilled_counts.edges, in_memory.edges);
    EXPECT_EQ(spilled_counts.boundary_edges, in_memory.boundary_edges);
    EXPECT_EQ(spilled_counts.non_manifold_edges, 1u);
    EXPECT_GT(in_memory.boundary_edges, 6u);
}

TEST(Metro, ClosedSphereHasNoBoundary) {
    CompareOptions options;
    options.samples = 1000;
    CompareResult r = compare_meshes(memory_source("a", sphere(3)), memory_source("b", sphere(2)), options);
    EXPECT_EQ(r.a.edges.boundary_edges, 0u);
    EXPECT_EQ(r.a.edges.non_manifold_edges, 0u);
    EXPECT_EQ(r.a.edges.edges, 3u * 512u / 2u);
    EXPECT_EQ(r.b.triangles, 128u);
}

TEST(Metro, HoldsTheSmallerFileAndStreamsTheLarger) {
    TempDir tmp;
    write_mesh(tmp.path() / "big.stl", sphere(5));
    write_mesh(tmp.path() / "small.stl", sphere(2));
    CompareOptions options;
    options.samples = 20'000;
    CompareResult r1 = compare_meshes(file_source((tmp.path() / "big.stl").string()),
                                      file_source((tmp.path() / "small.stl").string()), options);
    EXPECT_FALSE(r1.a.in_memory);
    EXPECT_TRUE(r1.b.in_memory);
    CompareResult r2 = compare_meshes(file_source((tmp.path() / "small.stl").string()),
                                      file_source((tmp.path() / "big.stl").string()), options);
    EXPECT_TRUE(r2.a.in_memory);
    EXPECT_FALSE(r2.b.in_memory);
    EXPECT_EQ(r1.a.triangles, 8u * 1024u);
    EXPECT_EQ(r2.b.triangles, 8u * 1024u);
    // The coarse sphere lies inside the fine one; both directions see the same chord gap.
    EXPECT_NEAR(r1.hausdorff(), r2.hausdorff(), 0.1 * r1.hausdorff());
    EXPECT_GT(r1.hausdorff(), 0);
    // A PLY states no triangle count (a face may be a polygon), but its face count is a fair
    // estimate: a small PLY as A is held too (B, the 8 k-triangle STL, was).
    {
        const std::vector<float> small = sphere(2);
        std::ofstream ply(tmp.path() / "small.ply");
        ply << "ply\nformat ascii 1.0\nelement vertex " << small.size() / 3
            << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << small.size() / 9
            << "\nproperty list uchar int vertex_indices\nend_header\n";
        for (size_t i = 0; i < small.size(); i += 3)
            ply << small[i] << ' ' << small[i + 1] << ' ' << small[i + 2] << '\n';
        for (size_t t = 0; t < small.size() / 9; ++t)
            ply << "3 " << 3 * t << ' ' << 3 * t + 1 << ' ' << 3 * t + 2 << '\n';
    }
    CompareResult r3 = compare_meshes(file_source((tmp.path() / "small.ply").string()),
                                      file_source((tmp.path() / "big.stl").string()), options);
    EXPECT_TRUE(r3.a.in_memory);
    EXPECT_FALSE(r3.b.in_memory);
    EXPECT_EQ(r3.a.triangles, r2.a.triangles);
}

TEST(Metro, EmptyMeshIsAnErrorNamingTheFile) {
    TempDir tmp;
    write_mesh(tmp.path() / "empty.stl", {});
    write_mesh(tmp.path() / "s.stl", sphere(1));
    try {
        compare_meshes(file_source((tmp.path() / "s.stl").string()), file_source((tmp.path() / "empty.stl").string()));
        FAIL() << "expected io::Error";
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("empty.stl"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("no (finite) triangles"), std::string::npos) << e.what();
    }
}

// ---- Colour and normal error (CompareOptions::attributes) ----------------------------------

namespace {

// The square [0, size]² in z = 0 as an n × n grid (2 n² triangles) with per-corner colours
// colour(x, y, centroid_x, rgba): the corner's position, and the x of its cell's centre, which
// tells the cells on either side of a colour seam apart (rgba starts as opaque black).
struct Plane {
    std::vector<float> xyz, colors;
};
template <class Colour>
Plane plane(int n, Colour colour, float size = 1) {
    Plane m;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const float x0 = size * float(i) / float(n), x1 = size * float(i + 1) / float(n),
                        y0 = size * float(j) / float(n), y1 = size * float(j + 1) / float(n);
            const float a[3] = {x0, y0, 0}, b[3] = {x1, y0, 0}, c[3] = {x1, y1, 0}, d[3] = {x0, y1, 0};
            const float cx = 0.5f * (x0 + x1);
            const float* tris[2][3] = {{a, b, c}, {a, c, d}};
            for (const auto& t : tris) {
                push_tri(m.xyz, t[0], t[1], t[2]);
                for (const float* v : t) {
                    float rgba[4] = {0, 0, 0, 1};
                    colour(v[0], v[1], cx, rgba);
                    m.colors.insert(m.colors.end(), rgba, rgba + 4);
                }
            }
        }
    return m;
}

// The same triangles with each one's corners rotated by `by` (0..2): corner k becomes k + by.
Plane rotate_corners(const Plane& m, int by) {
    Plane out = m;
    for (size_t t = 0; t < m.xyz.size() / 9; ++t)
        for (int k = 0; k < 3; ++k) {
            const int to = (k + by) % 3;
            std::copy_n(&m.xyz[9 * t + 3 * k], 3, &out.xyz[9 * t + 3 * to]);
            std::copy_n(&m.colors[12 * t + 4 * k], 4, &out.colors[12 * t + 4 * to]);
        }
    return out;
}

// Per-corner colours of a sphere from its positions: RGB = (p + 1) / 2 · 0.8, smooth and below
// 0.9 so a shift by 0.1 stays in 0..1.
std::vector<float> sphere_colours(const std::vector<float>& xyz, float shift_red = 0) {
    std::vector<float> rgba;
    for (size_t i = 0; i < xyz.size(); i += 3)
        rgba.insert(rgba.end(), {0.4f * (xyz[i] + 1) + shift_red, 0.4f * (xyz[i + 1] + 1), 0.4f * (xyz[i + 2] + 1), 1});
    return rgba;
}

CompareOptions with_attributes(uint64_t samples) {
    CompareOptions options;
    options.samples = samples;
    options.attributes = true;
    return options;
}

}  // namespace

TEST(MetroAttributes, ColouredMeshAgainstItselfHasNoColourError) {
    const std::vector<float> s = sphere(3);
    const CompareResult r = compare_meshes(memory_source("a", s, {}, sphere_colours(s)),
                                           memory_source("b", s, {}, sphere_colours(s)), with_attributes(20'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_TRUE(r.attributes->color);
    EXPECT_FALSE(r.attributes->normal);
    // Held samples sit off their triangle by float rounding (~6e-8), so their nearest point's
    // colour differs by about that much.
    EXPECT_LT(r.attributes->color_a_to_b.max, 1e-5);
    EXPECT_LT(r.attributes->color_b_to_a.max, 1e-5);
    EXPECT_EQ(r.attributes->color_a_to_b.samples, r.a_to_b.samples);
    EXPECT_EQ(r.attributes->color_b_to_a.samples, r.b_to_a.samples);
    EXPECT_EQ(r.attributes->color_symmetric().samples, r.a_to_b.samples + r.b_to_a.samples);
    EXPECT_EQ(r.attributes->normal_a_to_b.samples, 0u);
    // Without the option nothing is measured and the figures are those of positions only.
    CompareOptions plain;
    plain.samples = 20'000;
    const CompareResult p = compare_meshes(memory_source("a", s, {}, sphere_colours(s)),
                                           memory_source("b", s, {}, sphere_colours(s)), plain);
    EXPECT_FALSE(p.attributes);
    EXPECT_EQ(p.a_to_b.rms, r.a_to_b.rms);
    EXPECT_EQ(p.b_to_a.max, r.b_to_a.max);
}

TEST(MetroAttributes, ColoursShiftedByAConstantHaveThatError) {
    // Every red + 0.1: each sample's colour differs from the other surface's by exactly 0.1,
    // both ways (held and streamed), in RMS and max.
    const std::vector<float> s = sphere(3);
    const CompareResult r = compare_meshes(memory_source("a", s, {}, sphere_colours(s)),
                                           memory_source("b", s, {}, sphere_colours(s, 0.1f)), with_attributes(20'000));
    ASSERT_TRUE(r.attributes);
    for (const AttributeStats& e : {r.attributes->color_a_to_b, r.attributes->color_b_to_a}) {
        EXPECT_NEAR(e.rms, 0.1, 1e-5);
        EXPECT_NEAR(e.max, 0.1, 1e-5);
        EXPECT_GT(e.samples, 19'000u);
        EXPECT_EQ(e.skipped, 0u);
    }
    EXPECT_NEAR(r.attributes->color_symmetric().rms, 0.1, 1e-5);
}

TEST(MetroAttributes, ColourIsInterpolatedAcrossTriangles) {
    // A linear ramp (r = x, g = y) on a 40 × 40 grid against the same ramp on a 2 × 2 grid: the
    // barycentric interpolation of a linear function is exact, so both directions are ~0. A
    // triangle's one colour (its first corner's, say) would be off by up to a cell (0.5 on the
    // coarse grid).
    auto ramp = [](float x, float y, float, float* rgba) { rgba[0] = x, rgba[1] = y, rgba[2] = 0.5f; };
    const Plane fine = plane(40, ramp), coarse = plane(2, ramp);
    const CompareResult r =
        compare_meshes(memory_source("fine", fine.xyz, {}, fine.colors),
                       memory_source("coarse", coarse.xyz, {}, coarse.colors), with_attributes(20'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_TRUE(r.b.in_memory);
    EXPECT_LT(r.attributes->color_a_to_b.max, 1e-5);
    EXPECT_LT(r.attributes->color_b_to_a.max, 1e-5);
    EXPECT_GT(r.attributes->color_a_to_b.samples, 19'000u);
    EXPECT_GT(r.attributes->color_b_to_a.samples, 19'000u);
}

TEST(MetroAttributes, NearestPointsOnEdgesAndCornersInterpolateThere) {
    // B = [0, 2]² coloured (min(x, 1), min(y, 1)), piecewise linear on its grid; A = the unit
    // square coloured (x, y). B's samples past x = 1 or y = 1 are nearest to A's edges (at
    // (1, y) or (x, 1)) or its corner (1, 1), whose colours there are B's own: 0 both ways, if
    // the closest point's barycentric coordinates are right in every region. A's corners are
    // rotated so that its outer edges are each triangle's ab, bc and ca in turn.
    const Plane b = plane(
        16, [](float x, float y, float, float* rgba) { rgba[0] = std::min(x, 1.0f), rgba[1] = std::min(y, 1.0f); }, 2);
    for (int by = 0; by < 3; ++by) {
        const Plane a =
            rotate_corners(plane(4, [](float x, float y, float, float* rgba) { rgba[0] = x, rgba[1] = y; }), by);
        const CompareResult r = compare_meshes(memory_source("a", a.xyz, {}, a.colors),
                                               memory_source("b", b.xyz, {}, b.colors), with_attributes(10'000));
        ASSERT_TRUE(r.attributes);
        EXPECT_GT(r.b_to_a.max, 1.3);  // samples near B's far corner, sqrt 2 from A's
        EXPECT_LE(r.b_to_a.max, std::sqrt(2.0) + 1e-6);
        EXPECT_LT(r.attributes->color_a_to_b.max, 1e-5) << by;
        EXPECT_LT(r.attributes->color_b_to_a.max, 1e-5) << by;
    }
}

TEST(MetroAttributes, NearestPointOnADegenerateTriangleInterpolatesAlongItsEdge) {
    // A is one triangle with two equal corners (no area, so no samples of its own; the
    // closest point falls back to its edges), red rising along it as x / 2; B is a triangle
    // beside it coloured the same way. Each of B's samples is nearest to A's edge at its own
    // x, where A's red is B's.
    const std::vector<float> line = {0, 0, 0, 0, 0, 0, 2, 0, 0};
    const std::vector<float> beside = {0, 0.1f, 0, 2, 0.1f, 0, 1, 0.5f, 0};
    auto red_by_x = [](const std::vector<float>& xyz) {
        std::vector<float> rgba;
        for (size_t i = 0; i < xyz.size(); i += 3) rgba.insert(rgba.end(), {xyz[i] / 2, 0, 0, 1});
        return rgba;
    };
    const CompareResult r =
        compare_meshes(memory_source("line", line, {}, red_by_x(line)),
                       memory_source("beside", beside, {}, red_by_x(beside)), with_attributes(5'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_EQ(r.a_to_b.samples, 0u);
    EXPECT_GT(r.attributes->color_b_to_a.samples, 4'900u);
    EXPECT_LT(r.attributes->color_b_to_a.max, 1e-6);
}

TEST(MetroAttributes, HeldSamplesNearestToTheirFirstBoundKeepThatVertexsValue) {
    // B (streamed) is three triangles shrunk to points, red, green and blue; A (held, fewer
    // triangles) has a green triangle above the green point and a blue one above the blue
    // point. Each held sample's first upper bound (from a reservoir vertex of B) is its true
    // distance, which no triangle then lowers: the value it keeps is that vertex's.
    const std::vector<float> points = {0, 0,  0, 0, 0,  0, 0, 0,  0, 10, 0,  0, 10, 0,
                                       0, 10, 0, 0, 20, 0, 0, 20, 0, 0,  20, 0, 0};
    const float rgb[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    std::vector<float> point_colours;
    for (const auto& c : rgb)
        for (int k = 0; k < 3; ++k) point_colours.insert(point_colours.end(), {c[0], c[1], c[2], 1});
    const std::vector<float> above = {9.9f,  -0.1f, 1, 10.1f, -0.1f, 1, 10, 0.1f, 1,
                                      19.9f, -0.1f, 1, 20.1f, -0.1f, 1, 20, 0.1f, 1};
    std::vector<float> above_colours;
    for (int k = 0; k < 3; ++k) above_colours.insert(above_colours.end(), {0, 1, 0, 1});
    for (int k = 0; k < 3; ++k) above_colours.insert(above_colours.end(), {0, 0, 1, 1});
    const CompareResult r = compare_meshes(memory_source("above", above, {}, above_colours),
                                           memory_source("points", points, {}, point_colours), with_attributes(2'000));
    ASSERT_TRUE(r.a.in_memory);
    EXPECT_GT(r.attributes->color_a_to_b.samples, 1'900u);
    EXPECT_EQ(r.attributes->color_a_to_b.max, 0.0);
}

TEST(MetroAttributes, MovedColourBorderShowsTheJump) {
    // Red left of x = 0.5, blue right of it (per-corner colours, a seam along the grid line);
    // B has the border one cell (1/16) further right. Samples in the strip between see red
    // against blue, |(1,0,0) - (0,0,1)| = sqrt 2; all others 0. RMS = sqrt(2 / 16).
    auto border = [](float at) {
        return [at](float, float, float centroid_x, float* rgba) {
            rgba[0] = centroid_x < at ? 1.0f : 0.0f;
            rgba[2] = centroid_x < at ? 0.0f : 1.0f;
        };
    };
    const Plane a = plane(16, border(0.5f)), b = plane(16, border(0.5625f));
    const CompareResult r = compare_meshes(memory_source("a", a.xyz, {}, a.colors),
                                           memory_source("b", b.xyz, {}, b.colors), with_attributes(40'000));
    ASSERT_TRUE(r.attributes);
    for (const AttributeStats& e : {r.attributes->color_a_to_b, r.attributes->color_b_to_a}) {
        EXPECT_NEAR(e.max, std::sqrt(2.0), 1e-6);
        EXPECT_NEAR(e.rms, std::sqrt(2.0 / 16), 0.02);
    }
}

TEST(MetroAttributes, RotatedNormalsHaveTheirAngle) {
    // Normals in the yz plane varying across the square, and the same rotated 30° about x: the
    // interpolated normals, rotated too (rotation is linear), are 30° apart everywhere.
    const Plane a = plane(8, [](float, float, float, float*) {});
    std::vector<float> normals, rotated;
    const double angle = 30 * 3.14159265358979323846 / 180;
    for (size_t i = 0; i < a.xyz.size(); i += 3) {
        const double phi = 0.8 * (a.xyz[i] - 0.5) + 0.3 * a.xyz[i + 1];  // tilt in yz, by position
        const double ny = std::sin(phi), nz = std::cos(phi);
        normals.insert(normals.end(), {0, float(ny), float(nz)});
        rotated.insert(rotated.end(), {0, float(ny * std::cos(angle) - nz * std::sin(angle)),
                                       float(ny * std::sin(angle) + nz * std::cos(angle))});
    }
    const CompareResult r =
        compare_meshes(memory_source("a", a.xyz, normals), memory_source("b", a.xyz, rotated), with_attributes(20'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_FALSE(r.attributes->color);
    EXPECT_TRUE(r.attributes->normal);
    for (const AttributeStats& e : {r.attributes->normal_a_to_b, r.attributes->normal_b_to_a}) {
        EXPECT_NEAR(e.rms, 30, 1e-3);
        EXPECT_NEAR(e.max, 30, 1e-3);
        EXPECT_GT(e.samples, 19'000u);
    }
    // And against themselves, 0.
    const CompareResult same =
        compare_meshes(memory_source("a", a.xyz, normals), memory_source("b", a.xyz, normals), with_attributes(20'000));
    EXPECT_LT(same.attributes->normal_symmetric().max, 1e-3);
}

TEST(MetroAttributes, ZeroNormalsAreSkippedAndCounted) {
    const std::vector<float> s = sphere(2);
    std::vector<float> zero(s.size(), 0.0f), outward = s;  // the unit sphere's normal is its position
    const CompareResult r =
        compare_meshes(memory_source("zero", s, zero), memory_source("outward", s, outward), with_attributes(10'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_EQ(r.attributes->normal_a_to_b.samples, 0u);
    EXPECT_EQ(r.attributes->normal_a_to_b.skipped, r.a_to_b.samples);
    EXPECT_EQ(r.attributes->normal_b_to_a.skipped, r.b_to_a.samples);
    EXPECT_EQ(r.attributes->normal_symmetric().skipped, r.a_to_b.samples + r.b_to_a.samples);
}

TEST(MetroAttributes, OnlyTheChannelsBothHaveAreMeasured) {
    const std::vector<float> s = sphere(2);
    const CompareResult r = compare_meshes(memory_source("both", s, s, sphere_colours(s)),
                                           memory_source("colours", s, {}, sphere_colours(s)), with_attributes(5'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_TRUE(r.attributes->color);
    EXPECT_FALSE(r.attributes->normal);
    EXPECT_TRUE(r.a.channels.normal);
    EXPECT_FALSE(r.b.channels.normal);
    try {
        compare_meshes(memory_source("a.ply", s, {}, sphere_colours(s)), memory_source("b.ply", s, s),
                       with_attributes(5'000));
        FAIL() << "expected NoSharedAttributes";
    } catch (const NoSharedAttributes& e) {
        EXPECT_STREQ(e.what(),
                     "no colours or normals in both meshes to compare: A (a.ply) has colours, B (b.ply) has "
                     "normals");
        // The library's option error: the setting that cannot work with these meshes.
        const io::OptionError& option = e;
        EXPECT_EQ(option.setting(), io::Setting::kAttributes);
    }
    try {
        compare_meshes(memory_source("a.stl", s), memory_source("b.ply", s, s, sphere_colours(s)),
                       with_attributes(5'000));
        FAIL() << "expected NoSharedAttributes";
    } catch (const NoSharedAttributes& e) {
        EXPECT_STREQ(e.what(),
                     "no colours or normals in both meshes to compare: A (a.stl) has neither colours nor "
                     "normals, B (b.ply) has colours and normals");
    }
}

TEST(MetroAttributes, HeldSamplesFarFromTheStreamedSurfaceTakeItsValuesToo) {
    // The tilted square over the grid of HeldSamplesFarFromTheStreamedSurfaceAreExactToo, both
    // coloured r = x: each held sample's nearest point is straight below it, at its own x, so
    // its colour error is 0, for near samples (a triangle at a time) and far ones (a chunk at a
    // time through its BVH) alike. A held sample left with the value of the vertex that first
    // bounded it would be off by up to the grid's cell and more.
    auto ramp = [](float x, float, float, float* rgba) { rgba[0] = x; };
    const Plane grid = plane(60, ramp);
    const std::vector<float> tilted = {0, 0, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0, 1, 1, 1, 0, 1, 0};
    std::vector<float> tilted_colours;
    for (size_t i = 0; i < tilted.size(); i += 3) tilted_colours.insert(tilted_colours.end(), {tilted[i], 0, 0, 1});
    const CompareResult r = compare_meshes(memory_source("tilted", tilted, {}, tilted_colours),
                                           memory_source("grid", grid.xyz, {}, grid.colors), with_attributes(40'000));
    ASSERT_TRUE(r.a.in_memory);
    EXPECT_GT(r.a_to_b.max, 0.99);  // far samples were there
    EXPECT_LT(r.attributes->color_a_to_b.max, 1e-5);
    EXPECT_GT(r.attributes->color_a_to_b.samples, 39'000u);
}

TEST(MetroAttributes, ColoursAndNormalsFromPlyFiles) {
    // Read through the PLY reader: uchar colours (value / 255) and float normals.
    TempDir tmp;
    const std::vector<float> s = sphere(2);
    auto write_ply = [&](const fs::path& path, int red_offset) {
        std::ofstream ply(path);
        ply << "ply\nformat ascii 1.0\nelement vertex " << s.size() / 3
            << "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
               "property float nz\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face "
            << s.size() / 9 << "\nproperty list uchar int vertex_indices\nend_header\n";
        for (size_t i = 0; i < s.size(); i += 3)
            ply << s[i] << ' ' << s[i + 1] << ' ' << s[i + 2] << ' ' << s[i] << ' ' << s[i + 1] << ' ' << s[i + 2]
                << ' ' << 100 + red_offset << " 50 200\n";
        for (size_t t = 0; t < s.size() / 9; ++t) ply << "3 " << 3 * t << ' ' << 3 * t + 1 << ' ' << 3 * t + 2 << '\n';
    };
    write_ply(tmp.path() / "a.ply", 0);
    write_ply(tmp.path() / "b.ply", 51);  // red + 0.2
    const CompareResult r = compare_meshes(file_source((tmp.path() / "a.ply").string()),
                                           file_source((tmp.path() / "b.ply").string()), with_attributes(5'000));
    ASSERT_TRUE(r.attributes);
    EXPECT_TRUE(r.attributes->color);
    EXPECT_TRUE(r.attributes->normal);
    EXPECT_NEAR(r.attributes->color_symmetric().rms, 0.2, 1e-6);
    EXPECT_NEAR(r.attributes->color_symmetric().max, 0.2, 1e-6);
    EXPECT_LT(r.attributes->normal_symmetric().max, 0.01);  // the ascii text's 6 digits
}

// ---- The CLI --------------------------------------------------------------------------------

namespace {

struct RunResult {
    int exit_code;
    std::string out, err;
};

RunResult run_cli(const fs::path& dir, const std::string& args) {
    std::string cmd = std::string(MESHSTREAM_BINARY) + " -q " + args + " > " + (dir / "stdout.txt").string() + " 2> " +
                      (dir / "stderr.txt").string();
    int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(dir / "stdout.txt"), slurp(dir / "stderr.txt")};
}

}  // namespace

TEST(CompareCli, MissingFileExitsOneNamingTheFile) {
    TempDir tmp;
    write_mesh(tmp.path() / "s.stl", sphere(1));
    RunResult r =
        run_cli(tmp.path(), "compare " + (tmp.path() / "s.stl").string() + " " + (tmp.path() / "nope.stl").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("nope.stl"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.rfind("meshstream: error: ", 0), 0u) << r.err;
}

TEST(CompareCli, GarbageFileExitsOneNamingTheFile) {
    TempDir tmp;
    write_mesh(tmp.path() / "s.stl", sphere(1));
    std::ofstream(tmp.path() / "bad.stl") << "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\n";
    RunResult r =
        run_cli(tmp.path(), "compare " + (tmp.path() / "bad.stl").string() + " " + (tmp.path() / "s.stl").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("bad.stl"), std::string::npos) << r.err;
}

TEST(CompareCli, BadOptionExitsTwo) {
    TempDir tmp;
    RunResult r = run_cli(tmp.path(), "compare a.stl b.stl --samples zero");
    EXPECT_EQ(r.exit_code, 2);
    r = run_cli(tmp.path(), "compare a.stl");
    EXPECT_EQ(r.exit_code, 2);
    // More samples than memory can hold: refused before any work (it used to fail after a
    // minute and 12 GB as a bare "out of memory"). 2^32 samples take 258 GB.
    if (double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGESIZE)) < 2.5e11) {
        r = run_cli(tmp.path(), "compare a.stl b.stl --samples 4294967296");
        EXPECT_EQ(r.exit_code, 2);
        EXPECT_NE(
            r.err.find("--samples 4294967296: the held mesh's samples alone take about 257.70 GB (60 bytes each), "
                       "more than this machine's memory"),
            std::string::npos)
            << r.err;
    }
}

TEST(CompareCli, JsonReportsBothDirectionsAndCounts) {
    TempDir tmp;
    write_mesh(tmp.path() / "a.stl", sphere(3));
    write_mesh(tmp.path() / "b.stl", sphere(3));
    RunResult r = run_cli(tmp.path(), "compare --samples 5000 --json " + (tmp.path() / "a.stl").string() + " " +
                                          (tmp.path() / "b.stl").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* key : {"\"a_to_b\"", "\"b_to_a\"", "\"symmetric\"", "\"rms_pct\"", "\"boundary_edges\": 0",
                            "\"non_manifold_edges\": 0", "\"triangles\": 512", "\"held_in_memory\": true"})
        EXPECT_NE(r.out.find(key), std::string::npos) << key << "\n" << r.out;
    r = run_cli(tmp.path(),
                "compare --samples 5000 " + (tmp.path() / "a.stl").string() + " " + (tmp.path() / "b.stl").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("symmetric"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("boundary edges 0"), std::string::npos) << r.out;
}

TEST(Metro, BoundsCountEveryCornerOfTheFirstTriangle) {
    // A rhombus whose first triangle holds the extremes x = -1 and y = -1 in its first two
    // corners: each corner of the first triangle used to restart the box, so only the third
    // counted (box from x = 0, diagonal 2.236 instead of 2.828, every percentage 26 % high).
    const std::vector<float> rhombus = {-1, 0, 0, 0, -1, 0, 0, 1, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0};
    std::vector<float> raised = rhombus;
    for (size_t i = 2; i < raised.size(); i += 3) raised[i] = 0.1f;
    CompareOptions options;
    options.samples = 10'000;
    const CompareResult r = compare_meshes(memory_source("a", rhombus), memory_source("b", raised), options);
    EXPECT_EQ(r.a.bounds.min, (std::array<float, 3>{-1, -1, 0}));
    EXPECT_EQ(r.a.bounds.max, (std::array<float, 3>{1, 1, 0}));
    EXPECT_EQ(r.b.bounds.min, (std::array<float, 3>{-1, -1, 0.1f}));
    EXPECT_NEAR(r.diagonal, 2 * std::sqrt(2.0), 1e-6);
    EXPECT_NEAR(r.hausdorff(), 0.1, 1e-6);
}

TEST(CompareCli, ADirectionWithoutSamplesIsNotMeasuredNotZero) {
    // A's triangles have no area, so nothing on A is sampled: A -> B used to print max 0, mean 0,
    // though every point of A is 99 or more away from B.
    TempDir tmp;
    write_mesh(tmp.path() / "sphere.stl", sphere(1));
    write_mesh(tmp.path() / "flat.stl", {100, 0, 0, 101, 0, 0, 102, 0, 0, 100, 1, 0, 100, 2, 0, 100, 3, 0});
    const std::string args = (tmp.path() / "flat.stl").string() + " " + (tmp.path() / "sphere.stl").string();
    RunResult r = run_cli(tmp.path(), "compare " + args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("A -> B     no samples: not measured"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("warning: no samples on " + (tmp.path() / "flat.stl").string() +
                         " (its triangles have no area): A -> B is not measured"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("A -> B is not measured, and the symmetric figures are the other direction's alone"),
              std::string::npos)
        << r.err;
    r = run_cli(tmp.path(), "compare --json " + args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\"samples\": 0,\n    \"max\": null"), std::string::npos) << r.out;
    // Neither measured: no "other direction" to speak of.
    r = run_cli(tmp.path(), "compare " + (tmp.path() / "flat.stl").string() + " " + (tmp.path() / "flat.stl").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("symmetric  no samples: not measured"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("B -> A is not measured\n"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("other direction"), std::string::npos) << r.err;
    // decimate --report used to print "Hausdorff 0 (0.0000 %)" for the same meshes, and to
    // fail (exit 1, after writing) when the output had no triangles.
    r = run_cli(tmp.path(), "decimate -r 0.5 --report " + (tmp.path() / "flat.stl").string() + " " +
                                (tmp.path() / "flat_out.stl").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("error vs input: not measured (no samples: the triangles have no area)"), std::string::npos)
        << r.err;
    write_mesh(tmp.path() / "one.stl", {0, 0, 0, 1, 0, 0, 0, 1, 0});
    r = run_cli(tmp.path(), "decimate -r 0.1 --report " + (tmp.path() / "one.stl").string() + " " +
                                (tmp.path() / "none.stl").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("error vs input: not measured (the output has no triangles)"), std::string::npos) << r.err;
}

// Percentages of a tiny A's diagonal can be huge: fixed notation ran past its 32-byte buffer
// ("(1059636245964496754530782254475" with no "%)").
TEST(CompareCli, HugePercentagesAreWrittenInFull) {
    TempDir tmp;
    write_mesh(tmp.path() / "small.stl", {0, 0, 0, 1, 0, 0, 0, 1, 0});
    write_mesh(tmp.path() / "far.stl", {0, 0, 0, 3e30f, 0, 0, 0, 3e30f, 0});
    RunResult r =
        run_cli(tmp.path(), "compare " + (tmp.path() / "small.stl").string() + " " + (tmp.path() / "far.stl").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const size_t b_to_a = r.out.find("B -> A     max ");
    ASSERT_NE(b_to_a, std::string::npos) << r.out;
    const std::string line = r.out.substr(b_to_a, r.out.find('\n', b_to_a) - b_to_a);
    EXPECT_NE(line.find("(2.12e+32%)  mean"), std::string::npos) << line;
    EXPECT_NE(line.find("(1.225e+32%)  "), std::string::npos) << line;
}

TEST(Metro, HeldSamplesFarFromTheStreamedSurfaceAreExactToo) {
    // A fine grid on z = 0 (streamed: the larger) and a square tilted from z = 0 to z = 1 above it
    // (held): each held sample's distance is its height, so near samples (met a streamed
    // triangle at a time) and far ones (met a chunk at a time) mix. Mean 1/2, RMS sqrt(1/3).
    std::vector<float> grid;
    const int n = 60;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const float x0 = float(i) / n, x1 = float(i + 1) / n, y0 = float(j) / n, y1 = float(j + 1) / n;
            const float a[3] = {x0, y0, 0}, b[3] = {x1, y0, 0}, c[3] = {x1, y1, 0}, d[3] = {x0, y1, 0};
            push_tri(grid, a, b, c);
            push_tri(grid, a, c, d);
        }
    const std::vector<float> tilted = {0, 0, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0, 1, 1, 1, 0, 1, 0};
    CompareOptions options;
    options.samples = 40'000;
    const CompareResult r = compare_meshes(memory_source("tilted", tilted), memory_source("grid", grid), options);
    ASSERT_TRUE(r.a.in_memory);
    EXPECT_NEAR(r.a_to_b.mean, 0.5, 0.01);
    EXPECT_NEAR(r.a_to_b.rms, std::sqrt(1.0 / 3), 0.01);
    EXPECT_GT(r.a_to_b.max, 0.99);
    EXPECT_LE(r.a_to_b.max, 1.0 + 1e-6);
    // And every held sample's distance is exactly its height (to float storage).
    const CompareResult flat =
        compare_meshes(memory_source("high", {0, 0, 0.5f, 1, 0, 0.5f, 1, 1, 0.5f, 0, 0, 0.5f, 1, 1, 0.5f, 0, 1, 0.5f}),
                       memory_source("grid", grid), options);
    EXPECT_NEAR(flat.a_to_b.max, 0.5, 1e-7);
    EXPECT_NEAR(flat.a_to_b.mean, 0.5, 1e-7);
    EXPECT_NEAR(flat.b_to_a.max, 0.5, 1e-7);
}
