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
