// The small primitives every part shares: byte order (io/endian.hpp), the position key
// (io/position_key.hpp) and the seeded generators (io/random.hpp).
#include "io/endian.hpp"
#include "io/position_key.hpp"
#include "io/random.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace io = meshstream::io;

namespace {

TEST(Endian, StoresAndLoadsLittleEndianBytes) {
    unsigned char b[8] = {};
    io::store_le(b, uint32_t{0x11223344});
    EXPECT_EQ((std::array<unsigned char, 4>{b[0], b[1], b[2], b[3]}),
              (std::array<unsigned char, 4>{0x44, 0x33, 0x22, 0x11}));
    EXPECT_EQ(io::load_le<uint32_t>(b), 0x11223344u);
    io::store_le(b, 1.0f);  // 0x3f800000
    EXPECT_EQ(b[3], 0x3f);
    EXPECT_EQ(b[2], 0x80);
    EXPECT_EQ(io::load_le<float>(b), 1.0f);
    io::store_le(b, int16_t{-2});
    EXPECT_EQ(b[0], 0xfe);
    EXPECT_EQ(b[1], 0xff);
    EXPECT_EQ(io::load_le<int16_t>(b), -2);
    io::store_le(b, 0x0102030405060708ull);
    EXPECT_EQ(b[0], 0x08);
    EXPECT_EQ(b[7], 0x01);
    EXPECT_EQ(io::load_le<uint64_t>(b), 0x0102030405060708ull);
}

TEST(Endian, AppendsAndCopiesArrays) {
    std::vector<std::byte> out;
    io::append_le(out, uint16_t{0xabcd});
    io::append_le(out, uint8_t{7});
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(out[0], std::byte{0xcd});
    EXPECT_EQ(out[2], std::byte{7});

    const double src[3] = {1.5, -0.0, std::numeric_limits<double>::infinity()};
    std::byte bytes[24];
    EXPECT_EQ(io::store_le_array(bytes, src, 3), bytes + 24);
    double back[3];
    EXPECT_EQ(io::load_le_array(bytes, back, 3), bytes + 24);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(std::bit_cast<uint64_t>(back[i]), std::bit_cast<uint64_t>(src[i]));
    EXPECT_EQ(io::load_le<double>(bytes + 8), src[1]);
}

TEST(Endian, ByteswapReversesBytes) {
    EXPECT_EQ(io::byteswap(uint16_t{0x1234}), 0x3412);
    EXPECT_EQ(io::byteswap(uint32_t{0x11223344}), 0x44332211u);
    EXPECT_EQ(io::byteswap(0x0102030405060708ull), 0x0807060504030201ull);
    EXPECT_EQ(io::byteswap(io::byteswap(-3.25f)), -3.25f);
    EXPECT_EQ(io::byteswap(int8_t{-5}), -5);
}

TEST(PositionKey, FoldsNegativeZeroAndKeepsEveryOtherBit) {
    EXPECT_EQ(io::position_bits(-0.0f), io::position_bits(0.0f));
    EXPECT_NE(io::position_bits(1.0f), io::position_bits(-1.0f));
    EXPECT_NE(io::position_bits(std::numeric_limits<float>::denorm_min()), io::position_bits(0.0f));
    const float a[3] = {0.0f, -0.0f, 2.5f}, b[3] = {-0.0f, 0.0f, 2.5f}, c[3] = {0.0f, 0.0f, 2.5000002f};
    EXPECT_EQ(io::PositionKey::of(a), io::PositionKey::of(b));
    EXPECT_NE(io::PositionKey::of(a), io::PositionKey::of(c));
    EXPECT_LT(io::PositionKey::of(a), io::PositionKey::of(c));
}

// SplitMix64's published outputs for seed 0 (the reference implementation by Vigna).
TEST(Random, SplitMix64MatchesTheReferenceSequence) {
    io::SplitMix64 s{0};
    EXPECT_EQ(s.next(), 0xe220a8397b1dcdafull);
    EXPECT_EQ(s.next(), 0x6e789e6aa1b965f4ull);
    EXPECT_EQ(s.next(), 0x06c45d188009454full);
    io::SplitMix64 u{42};
    for (int i = 0; i < 1000; ++i) {
        double x = u.uniform();
        ASSERT_GE(x, 0.0);
        ASSERT_LT(x, 1.0);
    }
}

// xoshiro256** seeded by SplitMix64: the state words are SplitMix64's first four outputs, and
// the first output is rotl(s1 * 5, 7) * 9 (Blackman & Vigna's definition).
TEST(Random, RngIsXoshiro256StarStarSeededBySplitMix64) {
    io::SplitMix64 s{7};
    uint64_t state[4];
    for (uint64_t& w : state) w = s.next();
    const uint64_t x = state[1] * 5;
    const uint64_t expected = ((x << 7) | (x >> 57)) * 9;
    io::Rng rng(7);
    EXPECT_EQ(rng.next(), expected);

    io::Rng a(123), b(123), c(124);
    bool differs = false;
    for (int i = 0; i < 100; ++i) {
        const uint64_t va = a.next();
        EXPECT_EQ(va, b.next());
        differs |= va != c.next();
    }
    EXPECT_TRUE(differs);
    for (uint32_t n : {1u, 2u, 3u, 1000u}) {
        for (int i = 0; i < 200; ++i) ASSERT_LT(a.below(n), n);
    }
}

}  // namespace
