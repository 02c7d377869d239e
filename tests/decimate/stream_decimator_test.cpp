// End-to-end tests of decimate/stream_decimator on real fixtures and on generated inputs that
// exercise the paths beyond the paper (sorted holes, unsorted input, welding, bad topology).
// All runs use a fixed seed; bounds are invariants, not golden counts.
#include "decimate/stream_decimator.hpp"

#include "compare/metro.hpp"
#include "decimate/random.hpp"
#include "io/error.hpp"
#include "mesh_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <set>

using namespace meshstream::decimate;
using namespace meshstream::decimate::test;

namespace {

const std::vector<float>& bunny() {
    static const std::vector<float> soup =
        load_binary_stl(std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl");
    return soup;
}

// Same vertex id → same position (indexed writers rely on it).
bool ids_consistent(const Decimated& d) {
    std::map<uint64_t, std::array<float, 3>> seen;
    for (size_t c = 0; c < d.ids.size(); ++c) {
        const std::array<float, 3> p{d.xyz[3 * c], d.xyz[3 * c + 1], d.xyz[3 * c + 2]};
        auto [it, inserted] = seen.emplace(d.ids[c], p);
        if (!inserted && it->second != p) return false;
    }
    return true;
}

// A bumpy height-field grid of nx × ny quads with scattered one-quad holes, in row-major
// order along x (sorted along x when `by_x`).
std::vector<float> holey_grid(int nx, int ny) {
    std::vector<float> soup;
    auto z = [](int x, int y) { return 0.05f * float((x * 7 + y * 3) % 5); };
    for (int x = 0; x < nx; ++x)
        for (int y = 0; y < ny; ++y) {
            if ((x * 7 + y * 13) % 17 == 0) continue;  // a hole
            const float a[3] = {float(x), float(y), z(x, y)}, b[3] = {float(x + 1), float(y), z(x + 1, y)};
            const float c[3] = {float(x + 1), float(y + 1), z(x + 1, y + 1)},
                        d[3] = {float(x), float(y + 1), z(x, y + 1)};
            for (const float* p : {a, b, c, a, c, d}) soup.insert(soup.end(), p, p + 3);
        }
    return soup;
}

}  // namespace

class BunnyDecimation : public ::testing::TestWithParam<double> {};

TEST_P(BunnyDecimation, ExactCountManifoldAndFaithful) {
    const double ratio = GetParam();
    Options options;
    options.ratio = ratio;
    options.buffer_triangles = 10000;  // the bunny (69 451) streams through a small buffer
    const Decimated d = run_decimator(bunny(), options);
    const uint64_t target = static_cast<uint64_t>(std::llround(ratio * 69451));
    EXPECT_EQ(d.triangle_count(), target);
    EXPECT_EQ(d.stats.target_triangles, target);
    EXPECT_EQ(d.stats.forced_writes, 0u);
    EXPECT_LE(d.stats.peak_buffer_triangles, 10000u);
    // The bunny is manifold with 223 boundary edges: so must the output be.
    const Topology in = topology(index_by_position(bunny()));
    ASSERT_EQ(in.nonmanifold_edges, 0u);
    ASSERT_EQ(in.boundary_edges, 223u);
    const Topology out = topology(d.ids);
    EXPECT_EQ(out.nonmanifold_edges, 0u);
    EXPECT_EQ(out.misoriented_edges, 0u);
    EXPECT_EQ(out.degenerate_faces, 0u);
    EXPECT_LE(out.boundary_edges, in.boundary_edges);
    EXPECT_TRUE(ids_consistent(d));
    // Ids are the same topology as the positions (no two ids share a position).
    EXPECT_EQ(topology(index_by_position(d.xyz)).boundary_edges, out.boundary_edges);
    // Normals against the input: the proxy (nearest input centroid) misjudges a few coarse
    // triangles across the thin ears; measured 0.15 % of the area at 10 % and 1.0 % at 1 %.
    EXPECT_LT(flipped_area_fraction(bunny(), d.xyz), ratio >= 0.1 ? 0.005 : 0.02);
}

INSTANTIATE_TEST_SUITE_P(TenAndOnePercent, BunnyDecimation, ::testing::Values(0.1, 0.01));

TEST(StreamDecimator, BunnyAtTenPercentIsWithinAQuarterOfGarlandHeckbert) {
    // Quality against in-core Garland–Heckbert: CGAL's edge_collapse with GH plane policies
    // (bench/ref_cgal, --target 6945) gives a symmetric RMS of 0.0252 % of the bounding-box
    // diagonal on this fixture at 10 % (meshstream compare, 10⁶ samples, seed 1; measured
    // 2026-11, see docs/decimation.md). Demand at most 1.25× that. Measured here: 0.0291 %
    // (1.16×) with optimal placement, boundary planes and candidate memory; the half-edge-only
    // decimator gave 0.0366 % (1.45×) and fails this.
    constexpr double kCgalRmsPercent = 0.0252;
    Options options;
    options.ratio = 0.1;
    options.seed = 1;
    const Decimated d = run_decimator(bunny(), options);
    ASSERT_EQ(d.triangle_count(), 6945u);
    meshstream::compare::CompareOptions co;
    co.samples = 200000;  // fast; the figure moves by under 1 % against 10⁶ samples
    co.seed = 1;
    const meshstream::compare::CompareResult r =
        meshstream::compare::compare_meshes(meshstream::compare::memory_source("bunny", bunny()),
                                            meshstream::compare::memory_source("decimated", d.xyz), co);
    const double rms_percent = 100.0 * r.rms() / r.diagonal;
    EXPECT_GT(rms_percent, 0.0);
    EXPECT_LE(rms_percent, 1.25 * kCgalRmsPercent);
}

TEST(StreamDecimator, FlatDiscWithAHighValenceCentreKeepsEveryFaceUp) {
    // A flat polar disc: a centre fan of 500 thin triangles and 95 rings, all facing +z. Before
    // the fold check judged each face by its own edges, 26 faces came out upside down at 10 %.
    constexpr int kSegments = 500, kRings = 95;
    auto point = [&](int ring, int s) {
        const double r = double(ring) / kRings, a = 2 * M_PI * s / kSegments;
        return std::array<float, 3>{float(r * std::cos(a)), float(r * std::sin(a)), 0.0f};
    };
    std::vector<float> soup;
    auto add = [&](std::array<float, 3> a, std::array<float, 3> b, std::array<float, 3> c) {
        for (const auto& p : {a, b, c}) soup.insert(soup.end(), p.begin(), p.end());
    };
    for (int s = 0; s < kSegments; ++s) add(point(0, 0), point(1, s), point(1, s + 1));
    for (int ring = 1; ring < kRings; ++ring)
        for (int s = 0; s < kSegments; ++s) {
            add(point(ring, s), point(ring + 1, s), point(ring + 1, s + 1));
            add(point(ring, s), point(ring + 1, s + 1), point(ring, s + 1));
        }
    for (double ratio : {0.1, 0.01}) {
        Options options;
        options.ratio = ratio;
        const Decimated out = run_decimator(soup, options);
        EXPECT_EQ(out.triangle_count(), StreamDecimator::expected_output(ratio, soup.size() / 9));
        size_t down = 0;
        double area = 0;
        for (size_t f = 0; f < out.triangle_count(); ++f) {
            double n[3];
            triangle_normal(&out.xyz[9 * f], n);
            down += n[2] <= 0;
            area += std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) / 2;
        }
        EXPECT_EQ(down, 0u) << "ratio " << ratio;
        EXPECT_NEAR(area, M_PI, 0.01) << "ratio " << ratio;  // no part covered twice (folds add area)
    }
}

TEST(StreamDecimator, FarFromTheOriginVerticesStayOnTheSurface) {
    // A 45° slope with 2 mm of relief at UTM-like coordinates (500 000, 4 000 000), where a float
    // step in y is 0.25 m: every input position is a float, but a write-time move to the
    // unrounded quadric optimum put vertices up to 9 cm off the slope once stored.
    constexpr int n = 40;
    auto point = [](int i, int j) {
        return std::array<float, 3>{float(500000 + 0.5 * i), float(4000000 + 0.5 * j),
                                    float(100 + 0.5 * j + 0.002 * std::sin(0.7 * i) * std::cos(0.9 * j))};
    };
    std::vector<float> soup;
    auto add = [&](std::array<float, 3> a, std::array<float, 3> b, std::array<float, 3> c) {
        for (const auto& p : {a, b, c}) soup.insert(soup.end(), p.begin(), p.end());
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            add(point(i, j), point(i + 1, j), point(i + 1, j + 1));
            add(point(i, j), point(i + 1, j + 1), point(i, j + 1));
        }
    Options options;
    options.ratio = 0.1;
    const Decimated out = run_decimator(soup, options);
    ASSERT_EQ(out.triangle_count(), 320u);
    double worst = 0;
    for (size_t i = 0; i < out.xyz.size(); i += 3)
        worst = std::max(
            worst, std::abs((double(out.xyz[i + 2]) - 100) - (double(out.xyz[i + 1]) - 4000000)) / std::sqrt(2.0));
    EXPECT_LT(worst, 0.005) << "metres off the slope";
}

TEST(StreamDecimator, CountsTheEdgesLeftWithoutPartner) {
    // 100 triangles sharing no corner: 300 open edges. A closed octahedron: none.
    std::vector<float> soup;
    for (int t = 0; t < 100; ++t)
        soup.insert(soup.end(), {float(3 * t), 0, 0, float(3 * t + 1), 0, 0, float(3 * t), 1, 0});
    Options options;
    options.ratio = 0.5;
    EXPECT_EQ(run_decimator(soup, options).stats.boundary_edges, 300u);
    std::vector<float> octahedron;
    for (const auto& f : octahedron_faces())
        for (int k : f)
            octahedron.insert(octahedron.end(), octahedron_points()[k].begin(), octahedron_points()[k].end());
    EXPECT_EQ(run_decimator(octahedron, options).stats.boundary_edges, 0u);
}

TEST(StreamDecimator, SameSeedSameOutputWhateverTheChunking) {
    Options options;
    options.ratio = 0.05;
    options.buffer_triangles = 4000;
    options.seed = 42;
    const Decimated a = run_decimator(bunny(), options, 4096);
    const Decimated b = run_decimator(bunny(), options, 7);
    const Decimated c = run_decimator(bunny(), options, 1, /*tell_count=*/false);
    EXPECT_EQ(a.xyz, b.xyz);
    EXPECT_EQ(a.ids, b.ids);
    EXPECT_EQ(a.xyz, c.xyz);
    // The seed draws only the candidates of forced writes: without them, the order of
    // collapses is the greedy one, the same for any seed.
    ASSERT_EQ(a.stats.forced_writes, 0u);
    options.seed = 43;
    const Decimated other = run_decimator(bunny(), options, 4096);
    EXPECT_EQ(other.xyz, a.xyz);
}

TEST(StreamDecimator, SmallInputFitsTheBufferAndLandsExactly) {
    Options options;
    options.ratio = 0.1;
    options.buffer_triangles = 100000;  // in-core: the init loop never ends, final loop only
    const Decimated d = run_decimator(bunny(), options);
    EXPECT_EQ(d.triangle_count(), 6945u);
    EXPECT_EQ(d.stats.peak_buffer_triangles, 69451u);
    EXPECT_EQ(topology(d.ids).nonmanifold_edges, 0u);
}

TEST(StreamDecimator, TargetCountInsteadOfRatio) {
    Options options;
    options.target = 1001;
    options.buffer_triangles = 5000;
    const Decimated d = run_decimator(bunny(), options);
    EXPECT_EQ(d.triangle_count(), 1001u);
}

TEST(StreamDecimator, RatioOneKeepsEveryTriangle) {
    Options options;
    options.ratio = 1.0;
    options.buffer_triangles = 3000;
    const Decimated d = run_decimator(bunny(), options);
    EXPECT_EQ(d.triangle_count(), 69451u);
    EXPECT_EQ(d.stats.collapses, 0u);
    // Nothing was collapsed, so nothing moves: the same triangles, corner for corner (in
    // writing order, which differs from the input's).
    auto sorted_triangles = [](const std::vector<float>& xyz) {
        std::vector<std::array<float, 9>> t(xyz.size() / 9);
        for (size_t i = 0; i < t.size(); ++i) std::copy_n(&xyz[9 * i], 9, t[i].begin());
        for (auto& x : t) {  // rotate each to start at its smallest corner, keeping orientation
            int k = 0;
            for (int j = 1; j < 3; ++j)
                if (std::lexicographical_compare(&x[3 * j], &x[3 * j] + 3, &x[3 * k], &x[3 * k] + 3)) k = j;
            std::rotate(x.begin(), x.begin() + 3 * k, x.end());
        }
        std::sort(t.begin(), t.end());
        return t;
    };
    EXPECT_TRUE(sorted_triangles(d.xyz) == sorted_triangles(bunny()));
}

TEST(StreamDecimator, SortedHolesAreFinalizedBySweep) {
    const std::vector<float> soup = holey_grid(300, 40);  // sorted along x, ~22 600 triangles
    Options options;
    // Hole rims never collapse (they are boundary), which puts a floor of about 20 % under
    // this grid; 30 % is reachable.
    options.ratio = 0.3;
    options.buffer_triangles = 1500;
    const Decimated unsorted = run_decimator(soup, options);
    // Without the sweep, every hole rim stays open (P_in) and piles up in the buffer.
    EXPECT_GT(unsorted.stats.forced_writes, 0u);
    options.sorted_axis = 0;
    const Decimated sorted = run_decimator(soup, options);
    EXPECT_EQ(sorted.stats.forced_writes, 0u);
    EXPECT_GT(sorted.stats.vertices_finalized_by_sweep, 0u);
    EXPECT_EQ(sorted.triangle_count(), static_cast<uint64_t>(std::llround(0.3 * double(soup.size() / 9))));
    EXPECT_EQ(topology(sorted.ids).nonmanifold_edges, 0u);
    // Nothing stalled, so nothing went out before its time, whatever the budget's fraction (the
    // planned level is the budget rounded up: a budget of 4000.3 used to count every write from
    // a buffer decimated to 4001 as early).
    for (double ratio : {0.3, 0.3001, 0.3004}) {
        options.ratio = ratio;
        EXPECT_EQ(run_decimator(soup, options).stats.premature_writes, 0u) << ratio;
    }
}

TEST(StreamDecimator, DescendingSortedInputIsSweptToo) {
    const std::vector<float> ascending = holey_grid(300, 40);
    std::vector<float> soup;  // the same triangles, last first: sorted descending along x
    for (size_t t = ascending.size() / 9; t-- > 0;) soup.insert(soup.end(), &ascending[9 * t], &ascending[9 * t + 9]);
    Options options;
    options.ratio = 0.3;
    options.buffer_triangles = 1500;
    options.sorted_axis = 0;
    const Decimated d = run_decimator(soup, options);
    EXPECT_EQ(d.stats.sweep_direction, -1);
    EXPECT_EQ(d.stats.sort_violations, 0u);
    EXPECT_EQ(d.stats.forced_writes, 0u);
    EXPECT_GT(d.stats.vertices_finalized_by_sweep, 0u);
    EXPECT_EQ(d.triangle_count(), static_cast<uint64_t>(std::llround(0.3 * double(soup.size() / 9))));
    EXPECT_EQ(topology(d.ids).nonmanifold_edges, 0u);
    const Decimated up = run_decimator(ascending, options);
    EXPECT_EQ(up.stats.sweep_direction, 1);
    EXPECT_EQ(up.stats.sort_violations, 0u);
}

TEST(StreamDecimator, OneLongTriangleDoesNotHoldTheSweepOffInputSortedByMinimum) {
    // A sliver as long as the grid, first in x order (its minimum is the grid's start), as a
    // scanner's jump edge. The margin was the longest extent ever read, so the sweep never
    // started, and the sliver's far corners, queued early, blocked the queue once it did.
    // Sorted by minimum (as `meshstream sort` writes), nothing to come reaches behind the
    // front: no margin is needed.
    std::vector<float> soup = {0, -2, 0, 280, -2, 0.5f, 0, -1.5f, 0};
    const std::vector<float> grid = holey_grid(300, 40);
    soup.insert(soup.end(), grid.begin(), grid.end());
    Options options;
    options.ratio = 0.3;
    options.buffer_triangles = 1500;
    options.sorted_axis = 0;
    options.sorted_by_minimum = true;
    const Decimated d = run_decimator(soup, options);
    EXPECT_EQ(d.stats.sweep_direction, 1);
    EXPECT_EQ(d.stats.sort_violations, 0u);
    EXPECT_EQ(d.stats.forced_writes, 0u);
    EXPECT_GT(d.stats.vertices_finalized_by_sweep, 0u);
    EXPECT_EQ(d.triangle_count(), static_cast<uint64_t>(std::llround(0.3 * double(soup.size() / 9))));
    EXPECT_EQ(topology(d.ids).nonmanifold_edges, 0u);
    // The same order reversed, said to be sorted by minimum: the second triangle descends, so
    // the sweep stops before it ever ran (no vertex finalized, no crack).
    std::vector<float> reversed;
    for (size_t t = soup.size() / 9; t-- > 0;) reversed.insert(reversed.end(), &soup[9 * t], &soup[9 * t + 9]);
    const Decimated r = run_decimator(reversed, options);
    EXPECT_GT(r.stats.sort_violations, 0u);
    EXPECT_EQ(r.stats.vertices_finalized_by_sweep, 0u);
    EXPECT_EQ(topology(r.ids).nonmanifold_edges, 0u);
    EXPECT_TRUE(ids_consistent(r));
}

TEST(StreamDecimator, WronglyClaimedSortOrderIsDetectedAndTheSweepStops) {
    // The holey grid claimed sorted along y, but it is sorted along x: rows of y restart.
    const std::vector<float> soup = holey_grid(300, 40);
    Options options;
    options.ratio = 0.3;
    options.buffer_triangles = 1500;
    options.sorted_axis = 1;
    const Decimated d = run_decimator(soup, options);
    EXPECT_GT(d.stats.sort_violations, 0u);
    EXPECT_EQ(d.stats.triangles_in, soup.size() / 9);
    EXPECT_TRUE(ids_consistent(d));
    EXPECT_EQ(topology(d.ids).nonmanifold_edges, 0u);
}

TEST(StreamDecimator, ShuffledInputForceWritesButNeverBreaks) {
    std::vector<float> soup = bunny();
    // Shuffle triangles deterministically: no streaming order at all.
    std::vector<uint32_t> order(soup.size() / 9);
    std::iota(order.begin(), order.end(), 0u);
    Rng rng(5);
    for (size_t i = order.size() - 1; i > 0; --i) std::swap(order[i], order[rng.below(uint32_t(i + 1))]);
    std::vector<float> shuffled;
    for (uint32_t t : order) shuffled.insert(shuffled.end(), &soup[9 * size_t{t}], &soup[9 * size_t{t} + 9]);
    Options options;
    options.ratio = 0.1;
    options.buffer_triangles = 2000;
    const Decimated d = run_decimator(shuffled, options);
    EXPECT_GT(d.stats.forced_writes, 0u);
    EXPECT_EQ(d.stats.triangles_in, 69451u);
    EXPECT_GE(d.triangle_count(), 6945u);
    EXPECT_TRUE(ids_consistent(d));
    EXPECT_EQ(topology(d.ids).nonmanifold_edges, 0u);
}

TEST(StreamDecimator, WeldJoinsCrackedScan) {
    // Break the welding: nudge every corner by one float ulp in a per-corner direction.
    std::vector<float> cracked = bunny();
    for (size_t i = 0; i < cracked.size(); ++i)
        cracked[i] = (i / 3) % 2 ? std::nextafter(cracked[i], 1e9f) : cracked[i];
    Options options;
    options.ratio = 0.1;
    options.buffer_triangles = 10000;
    const Decimated broken = run_decimator(cracked, options);
    EXPECT_GT(broken.stats.forced_writes, 0u);  // a soup of islands cannot be decimated
    options.weld_eps = 1e-5;                    // bunny diagonal is 0.25
    const Decimated welded = run_decimator(cracked, options);
    EXPECT_GT(welded.stats.vertices_merged, 10000u);
    EXPECT_EQ(welded.triangle_count(), 6945u);
    EXPECT_LT(welded.stats.forced_writes, broken.stats.forced_writes);
}

TEST(StreamDecimator, BadTopologyIsFrozenAndPassedThrough) {
    // Spider_binary.stl: 56 triangles with repeated corners, orientation conflicts.
    const std::vector<float> spider = load_binary_stl(std::string(MESHSTREAM_FIXTURES_DIR) + "/Spider_binary.stl");
    Options options;
    options.ratio = 0.5;
    options.buffer_triangles = 400;
    const Decimated d = run_decimator(spider, options);
    EXPECT_EQ(d.stats.triangles_in, 1368u);
    EXPECT_EQ(d.stats.degenerate_passed, 56u);
    EXPECT_GT(d.stats.nonmanifold_edges, 0u);
    EXPECT_TRUE(ids_consistent(d));
    EXPECT_LE(d.triangle_count(), 1368u);
    EXPECT_GE(d.triangle_count(), 684u);
}

// Issue 40: a wavy 60×60-cell sheet whose cells on every fifth diagonal are holes, one cell
// each: chains of holes of four edges whose loops touch at the chained cells' shared corners, as
// a low-poly model's boundary loops do. Once those holes had shrunk to three edges nothing on
// them could collapse, the touching vertices never moved, and the decimator stopped far above
// its target (before closing holes of three edges: 1 822 triangles for a target of 603, 1 782
// boundary edges, over two thirds of the input's, RMS 0.24 % of the diagonal).
TEST(StreamDecimator, Issue40_ChainsOfTouchingHolesReachTheTargetAndClose) {
    constexpr int kCells = 60;
    auto point = [](int i, int j, float* out) {
        const double x = double(i) / kCells, y = double(j) / kCells;
        out[0] = float(x);
        out[1] = float(y);
        out[2] = float(0.08 * std::sin(3.1 * x + 0.3) * std::cos(2.3 * y) + 0.03 * std::sin(7.7 * x * y));
    };
    std::vector<float> soup;
    for (int j = 0; j < kCells; ++j)
        for (int i = 0; i < kCells; ++i) {
            if ((i - j) % 5 == 0 && i >= 3 && j >= 3 && i < kCells - 3 && j < kCells - 3) continue;
            float c[4][3];
            point(i, j, c[0]);
            point(i + 1, j, c[1]);
            point(i + 1, j + 1, c[2]);
            point(i, j + 1, c[3]);
            for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}})
                for (const int k : tri) soup.insert(soup.end(), c[k], c[k] + 3);
        }
    const Topology in = topology(index_by_position(soup));
    ASSERT_GT(in.boundary_edges, 1000u);
    Options options;
    options.ratio = 0.1;
    options.seed = 1;
    const Decimated d = run_decimator(soup, options);
    const uint64_t target = static_cast<uint64_t>(std::llround(0.1 * double(soup.size() / 9)));
    EXPECT_EQ(d.triangle_count(), target);
    const Topology out = topology(d.ids);
    EXPECT_EQ(out.nonmanifold_edges, 0u);
    EXPECT_EQ(out.misoriented_edges, 0u);
    EXPECT_EQ(out.degenerate_faces, 0u);
    // The holes shrink and close: well under half of the input's boundary is left.
    EXPECT_LT(out.boundary_edges, in.boundary_edges / 2);
    meshstream::compare::CompareOptions co;
    co.samples = 200000;
    co.seed = 1;
    const meshstream::compare::CompareResult r =
        meshstream::compare::compare_meshes(meshstream::compare::memory_source("sheet", soup),
                                            meshstream::compare::memory_source("decimated", d.xyz), co);
    // Measured 0.11 %.
    EXPECT_LT(100.0 * r.rms() / r.diagonal, 0.15);
}

TEST(StreamDecimator, NoKnifeEdgesOnAGearwheel) {
    // A gear's teeth have narrow top strips between nearly opposite walls: collapsing a strip
    // left the walls back to back (1 and 2 such edges at 10 % with seeds 1 and 2, 10 with seed
    // 3, where CGAL's Garland–Heckbert leaves none). The input has none.
    const std::vector<float> gear = load_binary_stl(std::string(MESHSTREAM_FIXTURES_DIR) + "/gearwheel.bin.stl");
    ASSERT_EQ(back_to_back_edges(gear, index_by_position(gear)), 0u);
    for (const uint64_t seed : {1, 2}) {
        Options options;
        options.ratio = 0.1;
        options.seed = seed;
        const Decimated d = run_decimator(gear, options);
        EXPECT_EQ(d.triangle_count(), 244u) << seed;
        EXPECT_EQ(back_to_back_edges(d.xyz, d.ids), 0u) << seed;
    }
}

TEST(StreamDecimator, ThinTubesReachTheCountThroughKnifeEdgesAtTheEnd) {
    // The Spider's legs are thin closed tubes: at 10 % most of their last collapses leave two
    // faces back to back. Refusing those everywhere stopped at 145–155 of 131 triangles; the end
    // of input takes them when nothing else is left.
    // Without its 56 triangles with repeated corners (passed through, not decimated), as the
    // command reads it: 1 312 triangles.
    const std::vector<float> all = load_binary_stl(std::string(MESHSTREAM_FIXTURES_DIR) + "/Spider_binary.stl");
    auto same = [](const float* a, const float* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; };
    std::vector<float> spider;
    for (size_t i = 0; i < all.size(); i += 9) {
        const float* t = &all[i];
        if (!same(t, t + 3) && !same(t + 3, t + 6) && !same(t + 6, t)) spider.insert(spider.end(), t, t + 9);
    }
    ASSERT_EQ(spider.size(), 9u * 1312);
    for (const uint64_t seed : {1, 2, 3}) {
        Options options;
        options.ratio = 0.1;
        options.seed = seed;
        const Decimated d = run_decimator(spider, options);
        EXPECT_EQ(d.triangle_count(), 131u) << seed;
        EXPECT_FALSE(d.stats.no_valid_collapse_left) << seed;
    }
}

// Options out of range and calls out of order are errors for library callers, not crashes
// (output chunks of 0 triangles crashed, pushing after finish() wrote
// more output). Options are io::OptionErrors naming the setting and the value, in the library's
// words (no command-line flag).
TEST(StreamDecimator, BadOptionsAndCallOrderThrow) {
    using meshstream::io::Setting;
    EXPECT_THROW(meshstream::io::TriangleChunk(0), std::invalid_argument);
    auto refused = [](auto change, Setting setting, const std::string& message,
                      std::optional<uint64_t> count = std::nullopt) {
        SCOPED_TRACE(message);
        Options options;
        change(options);
        try {
            StreamDecimator decimator(options, count);
            ADD_FAILURE() << "accepted";
        } catch (const meshstream::io::OptionError& e) {
            EXPECT_EQ(e.setting(), setting);
            EXPECT_EQ(std::string(e.what()), message);
        }
    };
    refused([](Options& o) { o.output_chunk_triangles = 0; }, Setting::kOutputChunk,
            "the output chunk size must be at least 1 triangle, got 0");
    refused([](Options& o) { o.buffer_triangles = 15; }, Setting::kBuffer,
            "the buffer must hold at least 16 triangles, got 15");
    refused([](Options& o) { o.ratio = 0; }, Setting::kRatio, "the ratio must be in (0, 1], got 0");
    refused([](Options& o) { o.ratio = 1.5; }, Setting::kRatio, "the ratio must be in (0, 1], got 1.5");
    refused([](Options& o) { o.sorted_axis = 3; }, Setting::kSortedAxis, "the sorted axis must be 0, 1 or 2, got 3");
    refused([](Options& o) { o.target = 10; }, Setting::kTarget,  // without the input count
            "the target needs the input's triangle count, which is not known");
    refused([](Options& o) { o.target = 50; }, Setting::kTarget,  // more than the input (it kept all, saying 50)
            "the target 50 is more than the 10 triangles of the input", 10);
    refused([](Options& o) { o.sorted_by_minimum = true; }, Setting::kSortedAxis,  // without the axis
            "sorting by minimum needs the sorted axis");
    refused(
        [](Options& o) {
            o.part = Part::kRange;
            o.target = 5;
        },
        Setting::kTarget, "a range or the seam pass takes the ratio, not the target", 10);
    refused(
        [](Options& o) {
            o.sorted_axis = 0;
            o.earlier_span = std::array<double, 2>{0, 1};
        },
        Setting::kPart, "an earlier span needs a range (Part::kRange) on a sorted axis");
    Options options;
    options.ratio = 1;
    StreamDecimator decimator(options, std::nullopt);
    meshstream::io::TriangleChunk chunk(4);
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::copy(tri, tri + 9, chunk.push_slot());
    size_t written = 0;
    auto out = [&](const meshstream::io::TriangleChunk& c) { written += c.size(); };
    decimator.push(chunk, out);
    decimator.finish(out);
    EXPECT_EQ(written, 1u);
    EXPECT_THROW(decimator.push(chunk, out), std::logic_error);
    EXPECT_THROW(decimator.finish(out), std::logic_error);
    EXPECT_EQ(written, 1u);
}

// With Options::target the decimator follows the read loop's count (io::InputCount): triangles
// dropped before it (here 20 000 of a promised 89 451, all first) leave the ratio at target /
// what the input can still hold, so the output lands on the target as for the clean input.
TEST(StreamDecimator, TargetFollowsTheTrianglesTheReadLoopDropped) {
    Options options;
    options.target = 6945;
    options.buffer_triangles = 10000;
    const std::vector<float>& soup = bunny();
    const size_t n = soup.size() / 9;
    meshstream::io::InputCount count{n + 20000};
    StreamDecimator decimator(options, count);
    count.read = count.dropped = 20000;  // what the loop dropped before handing anything on
    uint64_t out = 0;
    const Emit emit = [&](const meshstream::io::TriangleChunk& chunk) { out += chunk.size(); };
    meshstream::io::TriangleChunk chunk(4096);
    for (size_t i = 0; i < n; ++i) {
        float tri[9];
        std::copy(&soup[9 * i], &soup[9 * i] + 9, tri);
        chunk.push(tri);
        ++count.read;
        if (chunk.full() || i + 1 == n) {
            decimator.push(chunk, emit);
            chunk.clear();
        }
    }
    decimator.finish(emit);
    EXPECT_NEAR(double(out), 6945.0, 1.0);
    EXPECT_NEAR(decimator.ratio(), 6945.0 / double(n), 1e-12);
}

// Parallel decimation's parts (engine/ranges.hpp runs them on threads): the bunny cut
// into two ranges, each decimated by a Part::kRange decimator, and their outputs joined in
// range order by a Part::kSeams decimator with the weights the ranges give.
TEST(StreamDecimator, RangesKeepTheirSeamsAndTheSeamPassJoinsThem) {
    const std::vector<float> bunny =
        load_binary_stl(std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl");
    const size_t n = bunny.size() / 9, cut = n / 2;
    Options options;
    options.ratio = 0.1;
    options.buffer_triangles = 8000;
    const Decimated whole = run_decimator(bunny, options);

    // Positions used on both sides of the cut.
    std::set<std::array<float, 3>> first_half, shared;
    for (size_t c = 0; c < 3 * cut; ++c) first_half.insert({bunny[3 * c], bunny[3 * c + 1], bunny[3 * c + 2]});
    for (size_t c = 3 * cut; c < 3 * n; ++c)
        if (first_half.count({bunny[3 * c], bunny[3 * c + 1], bunny[3 * c + 2]}))
            shared.insert({bunny[3 * c], bunny[3 * c + 1], bunny[3 * c + 2]});
    ASSERT_GT(shared.size(), 50u);

    struct Piece {
        std::vector<float> xyz;
        std::vector<double> weights;  // one per chunk
        std::vector<size_t> sizes;
    };
    Piece pieces[2][3];  // per range: interior, first seam, last seam
    Options range_options = options;
    range_options.part = Part::kRange;
    for (int r = 0; r < 2; ++r) {
        StreamDecimator decimator(range_options, std::nullopt);
        auto collect = [&](int piece, double weight) -> Emit {
            return [&, piece, weight](const meshstream::io::TriangleChunk& chunk) {
                Piece& p = pieces[r][piece];
                p.xyz.insert(p.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
                p.weights.push_back(weight);
                p.sizes.push_back(chunk.size());
            };
        };
        const Emit interior = collect(0, 1 / options.ratio), first = collect(1, 1), last = collect(2, 1);
        meshstream::io::TriangleChunk chunk(1000);
        for (size_t t = r == 0 ? 0 : cut; t < (r == 0 ? cut : n); ++t) {
            float tri[9];
            std::memcpy(tri, &bunny[9 * t], sizeof tri);
            chunk.push(tri);
            if (chunk.full()) {
                decimator.push(chunk, interior);
                chunk.clear();
            }
        }
        decimator.push(chunk, interior);
        decimator.finish_range(interior, first, last);
        EXPECT_EQ(decimator.stats().forced_writes, 0u);
        // Every shared position is still in the range's output, where it was read.
        std::set<std::array<float, 3>> out;
        for (const Piece& p : pieces[r])
            for (size_t c = 0; c < p.xyz.size() / 3; ++c)
                out.insert({p.xyz[3 * c], p.xyz[3 * c + 1], p.xyz[3 * c + 2]});
        for (const auto& s : shared) EXPECT_TRUE(out.count(s)) << "range " << r;
    }

    Options seam_options = options;
    seam_options.part = Part::kSeams;
    seam_options.buffer_triangles = 2000;
    StreamDecimator seams(seam_options, std::nullopt);
    Decimated joined;
    const Emit emit = [&](const meshstream::io::TriangleChunk& chunk) {
        joined.xyz.insert(joined.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
    };
    auto feed = [&](const Piece& p) {
        size_t at = 0;
        for (size_t i = 0; i < p.sizes.size(); ++i) {
            meshstream::io::TriangleChunk chunk(p.sizes[i] > 0 ? p.sizes[i] : 1);
            for (size_t t = 0; t < p.sizes[i]; ++t, ++at) {
                float tri[9];
                std::memcpy(tri, &p.xyz[9 * at], sizeof tri);
                chunk.push(tri);
            }
            seams.push(chunk, p.weights[i], emit);
        }
    };
    for (const int piece : {0, 1, 2}) feed(pieces[0][piece]);
    for (const int piece : {1, 0, 2}) feed(pieces[1][piece]);
    const uint64_t target = StreamDecimator::expected_output(options.ratio, n);
    seams.finish_at(target, emit);
    EXPECT_EQ(seams.stats().forced_writes, 0u);
    EXPECT_LE(joined.xyz.size() / 9, target + 1);
    EXPECT_GE(joined.xyz.size() / 9, target);

    // As one decimator's output: no non-manifold or mis-oriented edge, and about as much
    // boundary (the bunny's holes).
    const Topology one = topology(index_by_position(whole.xyz)), two = topology(index_by_position(joined.xyz));
    EXPECT_EQ(two.nonmanifold_edges, one.nonmanifold_edges);
    EXPECT_EQ(two.misoriented_edges, 0u);
    EXPECT_LE(two.boundary_edges, one.boundary_edges + one.boundary_edges / 5);
}

// ---- Channels (decimate/attributes.hpp): what the decimator carries besides positions.

namespace {

// A flat n × n grid over [0,1]² (z = 0), two triangles a cell, each corner's single uv set and
// colour given by functions of the corner's position and of the triangle's cell.
struct ChannelMesh {
    meshstream::io::Channels channels;
    std::vector<float> xyz, uv, rgba;  // per triangle: 9, 6, 12
};

template <class Uv, class Rgb>
ChannelMesh channel_grid(int n, Uv uv_of, Rgb rgb_of) {
    ChannelMesh m;
    m.channels.uv_sets = 1;
    m.channels.color = meshstream::io::ColorFormat{meshstream::io::ScalarType::kFloat32, false};
    auto corner = [&](int i, int j, int ci, int cj) {
        const float x = float(i) / float(n), y = float(j) / float(n);
        m.xyz.insert(m.xyz.end(), {x, y, 0.0f});
        const std::array<float, 2> t = uv_of(x, y, ci, cj);
        m.uv.insert(m.uv.end(), t.begin(), t.end());
        const std::array<float, 3> c = rgb_of(x, y);
        m.rgba.insert(m.rgba.end(), {c[0], c[1], c[2], 1.0f});
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            for (const auto& [di, dj] : {std::pair{0, 0}, {1, 0}, {1, 1}}) corner(i + di, j + dj, i, j);
            for (const auto& [di, dj] : {std::pair{0, 0}, {1, 1}, {0, 1}}) corner(i + di, j + dj, i, j);
        }
    return m;
}

struct ChannelResult {
    std::vector<float> xyz, uv, rgba;
    Stats stats;
};

ChannelResult run_with_channels(const ChannelMesh& m, const Options& options, const AttributeWeights& weights) {
    const size_t n = m.xyz.size() / 9;
    StreamDecimator decimator(options, std::optional<uint64_t>(n), AttributeLayout(m.channels, weights));
    ChannelResult r;
    const Emit emit = [&](const meshstream::io::TriangleChunk& chunk) {
        r.xyz.insert(r.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        for (size_t i = 0; i < chunk.size(); ++i) {
            r.uv.insert(r.uv.end(), chunk.uv_at(i, 0), chunk.uv_at(i, 0) + 6);
            r.rgba.insert(r.rgba.end(), chunk.color_at(i), chunk.color_at(i) + 12);
        }
    };
    meshstream::io::TriangleChunk chunk(1000, m.channels);
    for (size_t i = 0; i < n; ++i) {
        std::copy_n(&m.xyz[9 * i], 9, chunk.push_slot());
        std::copy_n(&m.uv[6 * i], 6, chunk.uv_at(chunk.size() - 1, 0));
        std::copy_n(&m.rgba[12 * i], 12, chunk.color_at(chunk.size() - 1));
        if (chunk.full()) {
            decimator.push(chunk, emit);
            chunk.clear();
        }
    }
    if (!chunk.empty()) decimator.push(chunk, emit);
    decimator.finish(emit);
    r.stats = decimator.stats();
    return r;
}

std::array<float, 2> uv_is_xy(float x, float y, int, int) { return {x, y}; }
// Weights that leave the grid's channels (colour, uv) out of the error.
AttributeWeights geometry_only() {
    AttributeWeights w;
    w.color = 0;
    w.uv = 0;
    return w;
}
std::array<float, 3> ramp(float x, float y) { return {0.1f + 0.8f * x, 0.9f - 0.5f * y, 0.3f + 0.2f * x + 0.3f * y}; }

}  // namespace

TEST(StreamDecimatorChannels, LinearFieldsComeOutExactWhereverVerticesMove) {
    const ChannelMesh m = channel_grid(40, uv_is_xy, ramp);
    Options options;
    options.ratio = 0.1;
    options.buffer_triangles = 1000;  // decimated in a stream, not in one piece
    const ChannelResult r = run_with_channels(m, options, {});
    ASSERT_EQ(r.xyz.size() / 9, StreamDecimator::expected_output(0.1, m.xyz.size() / 9));
    EXPECT_GT(r.stats.vertices_moved + r.stats.collapses, 0u);
    for (size_t c = 0; c < r.xyz.size() / 3; ++c) {
        const float x = r.xyz[3 * c], y = r.xyz[3 * c + 1];
        const std::array<float, 3> expect = ramp(x, y);
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(r.rgba[4 * c + k], expect[k], 2e-4) << "corner " << c;
        ASSERT_NEAR(r.uv[2 * c], x, 2e-4);
        ASSERT_NEAR(r.uv[2 * c + 1], y, 2e-4);
        ASSERT_EQ(r.rgba[4 * c + 3], 1.0f);
    }
}

TEST(StreamDecimatorChannels, NoTriangleSpansAUvSeamWhileItSlidesAlongItself) {
    // Cells right of x = 0.5 belong to another texture chart (u + 10): the column of vertices at
    // x = 0.5 is a seam.
    const int n = 32;
    const ChannelMesh m = channel_grid(
        n,
        [&](float x, float y, int ci, int) {
            return std::array<float, 2>{x + (ci >= n / 2 ? 10.0f : 0.0f), y};
        },
        ramp);
    Options options;
    options.ratio = 0.25;
    options.buffer_triangles = 800;
    // The seam holds by rule, whatever the weights: here the uv error weighs nothing.
    AttributeWeights no_uv_error;
    no_uv_error.uv = 0;
    const ChannelResult r = run_with_channels(m, options, no_uv_error);
    EXPECT_EQ(r.xyz.size() / 9, StreamDecimator::expected_output(0.25, m.xyz.size() / 9));
    EXPECT_EQ(r.stats.seam_vertices, uint64_t(n + 1));
    std::set<float> seam_ys;
    for (size_t t = 0; t < r.xyz.size() / 9; ++t) {
        int chart[3];
        for (int k = 0; k < 3; ++k) {
            const size_t c = 3 * t + size_t(k);
            const float offset = r.uv[2 * c] - r.xyz[3 * c];
            ASSERT_TRUE(std::fabs(offset) < 1e-3 || std::fabs(offset - 10) < 1e-3) << offset;
            chart[k] = offset > 5;
            if (r.xyz[3 * c] == 0.5f) seam_ys.insert(r.xyz[3 * c + 1]);
        }
        EXPECT_TRUE(chart[0] == chart[1] && chart[1] == chart[2]) << "triangle " << t << " spans the seam";
    }
    // The seam slides along itself (a straight column: nothing lost), its ends stay.
    EXPECT_LT(seam_ys.size(), size_t(n + 1));
    EXPECT_EQ(seam_ys.count(0.0f), 1u);
    EXPECT_EQ(seam_ys.count(1.0f), 1u);
}

namespace {

// RMS over the input grid's vertices of the colour difference between the input's colour there
// and the output's interpolated colour at the same (x, y) (flat meshes: found in 2D).
double colour_rms(const ChannelMesh& in, const ChannelResult& out) {
    double sum = 0;
    size_t count = 0;
    for (size_t c = 0; c < in.xyz.size() / 3; c += 1) {
        const double px = in.xyz[3 * c], py = in.xyz[3 * c + 1];
        for (size_t t = 0; t < out.xyz.size() / 9; ++t) {
            const float* a = &out.xyz[9 * t];
            const double x0 = a[0], y0 = a[1], x1 = a[3], y1 = a[4], x2 = a[6], y2 = a[7];
            const double d = (y1 - y2) * (x0 - x2) + (x2 - x1) * (y0 - y2);
            if (d == 0) continue;
            const double l0 = ((y1 - y2) * (px - x2) + (x2 - x1) * (py - y2)) / d;
            const double l1 = ((y2 - y0) * (px - x2) + (x0 - x2) * (py - y2)) / d;
            const double l2 = 1 - l0 - l1;
            if (l0 < -1e-6 || l1 < -1e-6 || l2 < -1e-6) continue;
            for (int k = 0; k < 3; ++k) {
                const double v =
                    l0 * out.rgba[12 * t + k] + l1 * out.rgba[12 * t + 4 + k] + l2 * out.rgba[12 * t + 8 + k];
                sum += (v - in.rgba[4 * c + size_t(k)]) * (v - in.rgba[4 * c + size_t(k)]);
            }
            ++count;
            break;
        }
    }
    return std::sqrt(sum / double(std::max<size_t>(count, 1)));
}

}  // namespace

TEST(StreamDecimatorChannels, ColourErrorKeepsASharpBorderThatGeometryAloneSmears) {
    // A flat grid (no geometric error anywhere), red left of x = 0.5 and blue right of it.
    auto border = [](float x, float) {
        return x < 0.5f ? std::array<float, 3>{1, 0, 0} : std::array<float, 3>{0, 0, 1};
    };
    const ChannelMesh m = channel_grid(32, uv_is_xy, border);
    Options options;
    options.ratio = 0.1;
    options.buffer_triangles = 1000;
    const double weighted = colour_rms(m, run_with_channels(m, options, {}));
    const double unweighted = colour_rms(m, run_with_channels(m, options, geometry_only()));
    EXPECT_LT(weighted, 0.5 * unweighted) << weighted << " vs " << unweighted;
}

TEST(StreamDecimatorChannels, UnweightedChannelsLeaveTheGeometryAsPositionsOnly) {
    // Weights 0 and no seams: the same collapses as a positions-only run, so the same triangles.
    const ChannelMesh m = channel_grid(30, uv_is_xy, ramp);
    Options options;
    options.ratio = 0.2;
    options.buffer_triangles = 600;
    const ChannelResult with = run_with_channels(m, options, geometry_only());
    const Decimated without = run_decimator(m.xyz, options, 1000);
    EXPECT_EQ(with.xyz, without.xyz);
}

TEST(StreamDecimatorChannels, DegenerateTrianglesPassThroughWithTheirValues) {
    ChannelMesh m = channel_grid(4, uv_is_xy, ramp);
    // One more triangle with a repeated corner and colours of its own.
    const float tri[9] = {2, 2, 0, 2, 2, 0, 3, 2, 0};
    m.xyz.insert(m.xyz.end(), tri, tri + 9);
    m.uv.insert(m.uv.end(), {0.5f, 0.5f, 0.5f, 0.5f, 0.25f, 0.75f});
    m.rgba.insert(m.rgba.end(), {0.2f, 0.4f, 0.6f, 1, 0.2f, 0.4f, 0.6f, 1, 0.8f, 0.6f, 0.4f, 1});
    Options options;
    options.ratio = 1.0;
    const ChannelResult r = run_with_channels(m, options, {});
    ASSERT_EQ(r.stats.degenerate_passed, 1u);
    bool found = false;
    for (size_t t = 0; t < r.xyz.size() / 9; ++t)
        if (r.xyz[9 * t] == 2 && r.xyz[9 * t + 6] == 3) {
            found = true;
            EXPECT_FLOAT_EQ(r.rgba[12 * t + 8], 0.8f);
            EXPECT_FLOAT_EQ(r.uv[6 * t + 5], 0.75f);
        }
    EXPECT_TRUE(found);
}

TEST(StreamDecimatorChannels, RefusesChunksWithoutItsChannels) {
    const ChannelMesh m = channel_grid(2, uv_is_xy, ramp);
    Options options;
    StreamDecimator decimator(options, std::optional<uint64_t>(8), AttributeLayout(m.channels, {}));
    meshstream::io::TriangleChunk positions(8);
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    positions.push(tri);
    EXPECT_THROW(decimator.push(positions, [](const meshstream::io::TriangleChunk&) {}), std::invalid_argument);
}
