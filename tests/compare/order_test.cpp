// Tests of the stream-width measure (compare/order.hpp): exact widths of hand-made streams, a
// brute-force check of the definition, the sampled estimate under a tiny budget and the buffer
// verdict.
#include "compare/order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <random>
#include <vector>

using namespace meshstream;
using Tri = std::array<float, 9>;

namespace {

compare::OrderReport measure(const std::vector<Tri>& tris, uint64_t budget = uint64_t{64} << 20) {
    compare::OrderMeter meter(budget);
    io::TriangleChunk chunk(100);
    for (const Tri& t : tris) {
        chunk.push(reinterpret_cast<const float(&)[9]>(*t.data()));
        if (chunk.full()) {
            meter.add(chunk);
            chunk.clear();
        }
    }
    meter.add(chunk);
    return meter.finish();
}

// The definition, computed directly: width = max_j #{i <= j < L(i)}.
uint64_t brute_force_width(const std::vector<Tri>& tris) {
    std::map<std::array<float, 3>, size_t> last;
    for (size_t i = 0; i < tris.size(); ++i)
        for (int v = 0; v < 3; ++v) last[{tris[i][3 * v], tris[i][3 * v + 1], tris[i][3 * v + 2]}] = i;
    std::vector<size_t> L(tris.size());
    for (size_t i = 0; i < tris.size(); ++i)
        for (int v = 0; v < 3; ++v)
            L[i] = std::max(L[i], last[{tris[i][3 * v], tris[i][3 * v + 1], tris[i][3 * v + 2]}]);
    uint64_t best = 0;
    for (size_t j = 0; j < tris.size(); ++j) {
        uint64_t open = 0;
        for (size_t i = 0; i <= j; ++i) open += j < L[i];
        best = std::max(best, open);
    }
    return best;
}

// A strip t_k = (v_k, v_k+1, v_k+2) with v_k on a zig-zag along z.
std::vector<Tri> strip(size_t n) {
    auto v = [](size_t k) { return std::array<float, 3>{float(k % 2), 0, float(k)}; };
    std::vector<Tri> tris;
    for (size_t k = 0; k < n; ++k) {
        auto a = v(k), b = v(k + 1), c = v(k + 2);
        tris.push_back({a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]});
    }
    return tris;
}

// A w × h grid of quads, two triangles each, row by row (sorted along y).
std::vector<Tri> grid(int w, int h) {
    std::vector<Tri> tris;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float x0 = float(x), x1 = float(x + 1), y0 = float(y), y1 = float(y + 1);
            tris.push_back({x0, y0, 0, x1, y0, 0, x1, y1, 0});
            tris.push_back({x0, y0, 0, x1, y1, 0, x0, y1, 0});
        }
    return tris;
}

}  // namespace

TEST(OrderMeter, StripInOrderHasWidthTwo) {
    compare::OrderReport r = measure(strip(1000));
    EXPECT_TRUE(r.exact());
    EXPECT_EQ(r.triangles, 1000u);
    EXPECT_EQ(r.width, 2u);  // t_j-1 and t_j wait for t_j+1
    EXPECT_EQ(r.descents[2], 0u);
}

TEST(OrderMeter, MatchesTheDefinitionOnShuffledAndSortedGrids) {
    std::vector<Tri> sorted = grid(20, 15);
    std::vector<Tri> shuffled = sorted;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(11));
    const uint64_t w_sorted = brute_force_width(sorted), w_shuffled = brute_force_width(shuffled);
    EXPECT_EQ(measure(sorted).width, w_sorted);
    EXPECT_EQ(measure(shuffled).width, w_shuffled);
    // A row-by-row grid holds about two rows; a shuffled one most of the mesh.
    EXPECT_LE(w_sorted, 2u * 2 * 20 + 2);
    EXPECT_GT(w_shuffled, sorted.size() / 2);
    EXPECT_EQ(measure(sorted).descents[1], 0u);
    EXPECT_GT(measure(shuffled).descents[1], 100u);
}

TEST(OrderMeter, NegativeZeroIsTheSameVertex) {
    std::vector<Tri> tris = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {5, 5, 5, 6, 5, 5, 5, 6, 5}, {-0.0f, 0, 0, 2, 2, 0, 3, 3, 0}};
    EXPECT_EQ(measure(tris).width, brute_force_width(tris));
    // t0 stays open while t1 is read, until t2 reuses (±0, 0, 0); were -0 another vertex, 0.
    EXPECT_EQ(measure(tris).width, 1u);
}

TEST(OrderMeter, SampledEstimateIsWithinItsErrorUnderTinyBudget) {
    std::vector<Tri> tris = grid(200, 200);  // 80 000 triangles, 40 401 vertices
    std::shuffle(tris.begin(), tris.end(), std::mt19937_64(5));
    compare::OrderReport exact = measure(tris);
    ASSERT_TRUE(exact.exact());
    compare::OrderReport sampled = measure(tris, 1 << 20);
    EXPECT_FALSE(sampled.exact());
    EXPECT_LT(sampled.sample_rate, 0.5);
    EXPECT_GT(sampled.width_error, 0);
    EXPECT_LE(double(sampled.width), double(exact.width) + sampled.width_error);
    EXPECT_GE(double(sampled.width), double(exact.width) - sampled.width_error);
    EXPECT_EQ(sampled.descents, exact.descents);  // descents are always exact
}

TEST(OrderMeter, BufferVerdict) {
    compare::OrderReport r;
    r.triangles = 1000000;
    r.width = 500000;
    r.descents = {10, 20, 30000};
    EXPECT_EQ(compare::buffer_verdict(r, 400000, 0.1), compare::BufferVerdict::kTooSmall);
    EXPECT_EQ(compare::buffer_verdict(r, 500000, 0.1), compare::BufferVerdict::kUncertain);  // no room behind the front
    // The room behind the front grows with the ratio: 2.2 + 2·ratio times the width.
    EXPECT_EQ(compare::buffer_needed(r, 0.1), 1200000u);
    EXPECT_EQ(compare::buffer_verdict(r, 1200000, 0.1), compare::BufferVerdict::kSuffices);
    EXPECT_EQ(compare::buffer_verdict(r, 1200000, 0.5), compare::BufferVerdict::kUncertain);
    EXPECT_EQ(compare::buffer_verdict(r, 1600000, 0.5), compare::BufferVerdict::kSuffices);
    r.sample_rate = 1.0 / 16;
    r.width_error = 200000;
    EXPECT_EQ(compare::buffer_verdict(r, 400000, 0.1), compare::BufferVerdict::kUncertain);
}
