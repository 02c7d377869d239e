// Tests of the sort key mapping and the in-memory LSD radix sort (sort/radix.hpp).
#include "sort/radix.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace meshstream::sort;

TEST(OrderedKey, PreservesFloatOrder) {
    const float inf = std::numeric_limits<float>::infinity();
    const float values[] = {-inf,
                            -3.4e38f,
                            -1.5f,
                            -1e-30f,
                            -std::numeric_limits<float>::denorm_min(),
                            0.0f,
                            std::numeric_limits<float>::denorm_min(),
                            1e-30f,
                            1.0f,
                            1.0000001f,
                            3.4e38f,
                            inf};
    for (size_t i = 1; i < std::size(values); ++i)
        EXPECT_LT(ordered_key(values[i - 1]), ordered_key(values[i])) << values[i - 1] << " vs " << values[i];
    EXPECT_EQ(ordered_key(-0.0f), ordered_key(0.0f));
    EXPECT_EQ(ordered_key(std::nanf("")), 0xFFFFFFFFu);
    EXPECT_EQ(ordered_key(-std::nanf("")), 0xFFFFFFFFu);
    EXPECT_LT(ordered_key(inf), ordered_key(std::nanf("")));
    for (float f : values) EXPECT_EQ(key_to_float(ordered_key(f)), f);
}

TEST(TriangleKey, IsTheMinimumCornerAlongTheAxis) {
    const float tri[9] = {1, 5, -2, 0.5f, 7, 3, 2, -1, 4};
    EXPECT_EQ(triangle_key(tri, 0), ordered_key(0.5f));
    EXPECT_EQ(triangle_key(tri, 1), ordered_key(-1.0f));
    EXPECT_EQ(triangle_key(tri, 2), ordered_key(-2.0f));
    const float with_nan[9] = {std::nanf(""), 0, 0, 3, 0, 0, 2, 0, 0};
    EXPECT_EQ(triangle_key(with_nan, 0), ordered_key(2.0f));  // a NaN corner is ignored
}

TEST(RadixSort, MatchesStableSortOnRandomKeys) {
    std::mt19937_64 rng(42);
    for (size_t n : {size_t{0}, size_t{1}, size_t{2}, size_t{1000}, size_t{100000}}) {
        for (uint32_t distinct : {1u, 7u, 5000u, 0xFFFFFFFFu}) {
            std::vector<uint64_t> items(n), scratch(n);
            for (size_t i = 0; i < n; ++i) {
                uint32_t key = static_cast<uint32_t>(rng() % distinct) * (0xFFFFFFFFu / distinct);
                items[i] = uint64_t{key} << 32 | i;
            }
            std::vector<uint64_t> expect = items;
            std::stable_sort(expect.begin(), expect.end(),
                             [](uint64_t a, uint64_t b) { return (a >> 32) < (b >> 32); });
            auto sorted = radix_sort_by_key(items, scratch);
            ASSERT_EQ(sorted.size(), n);
            EXPECT_TRUE(std::equal(sorted.begin(), sorted.end(), expect.begin()))
                << "n=" << n << " distinct=" << distinct;
        }
    }
}

TEST(RadixSort, SortsKeysThatDifferOnlyInOneDigit) {
    // Keys differing only in the top 10 bits, and only in the low 11 bits: skipped passes
    // must not lose the result.
    for (int shift : {0, 22}) {
        std::vector<uint64_t> items, scratch(1000);
        for (uint64_t i = 0; i < 1000; ++i) items.push_back(uint64_t{(999 - i) % 512 << shift} << 32 | i);
        auto sorted = radix_sort_by_key(items, scratch);
        for (size_t i = 1; i < sorted.size(); ++i) {
            ASSERT_LE(sorted[i - 1] >> 32, sorted[i] >> 32);
            if (sorted[i - 1] >> 32 == sorted[i] >> 32) {
                ASSERT_LT(uint32_t(sorted[i - 1]), uint32_t(sorted[i]));
            }
        }
    }
}
