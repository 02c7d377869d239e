// The chunk's channels: slots start zeroed (opaque black), triangles copy with every channel,
// corner and face records round-trip each channel in the source's type, and the channel
// descriptions name what one stream has and another lacks.
#include "io/chunk.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

using namespace meshstream;

namespace {

io::Channels every_channel() {
    io::Channels ch;
    ch.normal = true;
    ch.color = io::ColorFormat{io::ScalarType::kUInt16, true};
    ch.uv_sets = 2;
    ch.vertex_scalars = {{"intensity", io::ScalarType::kFloat32}, {"confidence", io::ScalarType::kUInt8}};
    ch.vertex_id = true;
    ch.material = true;
    ch.face_scalars = {{"label", io::ScalarType::kInt32}};
    return ch;
}

// Fills triangle i of `c` with values derived from `seed` in every channel.
void fill(io::TriangleChunk& c, size_t i, float seed) {
    for (int k = 0; k < 9; ++k) c.xyz()[9 * i + k] = seed + k;
    for (int k = 0; k < 9; ++k) c.normal_at(i)[k] = seed * 0.5f + k;
    for (int k = 0; k < 12; ++k) c.color_at(i)[k] = float(int(seed * 100 + k * 977) % 65536) / 65535.0f;
    for (int s = 0; s < 2; ++s)
        for (int k = 0; k < 6; ++k) c.uv_at(i, s)[k] = seed + 0.25f * float(s * 6 + k);
    for (size_t s = 0; s < 2; ++s)
        for (int k = 0; k < 3; ++k) c.vertex_scalar_at(i, s)[k] = double(seed) * 3 + double(s) + k;
    for (int k = 0; k < 3; ++k) c.id_at(i)[k] = uint64_t(seed) * 3 + uint64_t(k);
    *c.material_at(i) = uint32_t(seed);
    *c.face_scalar_at(i, 0) = -double(seed);
}

void expect_same_triangle(const io::TriangleChunk& a, size_t i, const io::TriangleChunk& b, size_t j) {
    for (int k = 0; k < 9; ++k) EXPECT_EQ(a.xyz()[9 * i + k], b.xyz()[9 * j + k]);
    for (int k = 0; k < 9; ++k) EXPECT_EQ(a.normal_at(i)[k], b.normal_at(j)[k]);
    for (int k = 0; k < 12; ++k) EXPECT_EQ(a.color_at(i)[k], b.color_at(j)[k]);
    for (int s = 0; s < 2; ++s)
        for (int k = 0; k < 6; ++k) EXPECT_EQ(a.uv_at(i, s)[k], b.uv_at(j, s)[k]);
    for (size_t s = 0; s < 2; ++s)
        for (int k = 0; k < 3; ++k) EXPECT_EQ(a.vertex_scalar_at(i, s)[k], b.vertex_scalar_at(j, s)[k]);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.id_at(i)[k], b.id_at(j)[k]);
    EXPECT_EQ(*a.material_at(i), *b.material_at(j));
    EXPECT_EQ(*a.face_scalar_at(i, 0), *b.face_scalar_at(j, 0));
}

}  // namespace

TEST(TriangleChunk, NewSlotsAreZeroAndOpaque) {
    io::TriangleChunk c(4, every_channel());
    fill(c, (c.push_slot(), 0), 7);
    c.clear();
    c.push_slot();
    for (float v : c.normals()) EXPECT_EQ(v, 0.0f);
    for (int k = 0; k < 12; ++k) EXPECT_EQ(c.colors()[k], k % 4 == 3 ? 1.0f : 0.0f);
    EXPECT_EQ(c.uv_at(0, 1)[5], 0.0f);
    EXPECT_EQ(c.vertex_scalar_at(0, 1)[2], 0.0);
    EXPECT_EQ(c.materials()[0], 0u);
    EXPECT_EQ(c.uv_at(0, 2), nullptr);  // past the chunk's sets
}

TEST(TriangleChunk, CopiesATriangleWithEveryChannel) {
    io::TriangleChunk a(8, every_channel()), b(8, every_channel());
    for (int t = 0; t < 5; ++t) fill(a, (a.push_slot(), size_t(t)), float(t + 1));
    b.push_copy(a, 3);
    expect_same_triangle(a, 3, b, 0);
    a.copy_triangle(1, a, 4);  // within one chunk
    expect_same_triangle(a, 1, a, 4);
    io::Channels too_many;
    too_many.uv_sets = 5;
    EXPECT_THROW(io::TriangleChunk(1, too_many), std::invalid_argument);
}

TEST(CornerLayout, RoundTripsEachChannelInTheSourcesType) {
    const io::Channels ch = every_channel();
    const io::CornerLayout corner(ch);
    const io::FaceLayout face(ch);
    // normal 12 + RGBA16 8 + two uv sets 16 + float and uchar scalars 5; material 4 + one scalar 8.
    EXPECT_EQ(corner.bytes(), 41u);
    EXPECT_EQ(face.bytes(), 12u);
    io::TriangleChunk a(2, ch), b(2, ch);
    fill(a, (a.push_slot(), 0), 5);
    b.push_slot();
    std::vector<std::byte> rec(corner.bytes());
    for (int k = 0; k < 3; ++k) {
        corner.pack(a, 0, k, rec.data());
        corner.unpack(rec.data(), b, 0, k);
    }
    std::vector<std::byte> frec(face.bytes());
    face.pack(a, 0, frec.data());
    face.unpack(frec.data(), b, 0);
    std::copy(a.xyz().begin(), a.xyz().end(), b.xyz().begin());
    std::copy(a.vertex_ids().begin(), a.vertex_ids().end(), b.vertex_ids().begin());
    expect_same_triangle(a, 0, b, 0);  // 16-bit colours survive float exactly
}

TEST(CornerLayout, ScalarsTakeTheirTypesBytesRoundedAndClampedToIntegerRanges) {
    io::Channels ch;
    ch.vertex_scalars = {{"label", io::ScalarType::kUInt8},
                         {"offset", io::ScalarType::kInt16},
                         {"count", io::ScalarType::kUInt32},
                         {"q", io::ScalarType::kFloat32},
                         {"exact", io::ScalarType::kFloat64}};
    const io::CornerLayout layout(ch);
    EXPECT_EQ(layout.bytes(), 1u + 2 + 4 + 4 + 8);
    const double in[5] = {300.0, -2.6, 4294967295.0, 0.1, 0.1};
    std::vector<std::byte> rec(layout.bytes());
    layout.pack_values(nullptr, nullptr, nullptr, in, rec.data());
    double out[5];
    layout.unpack_values(rec.data(), nullptr, nullptr, nullptr, out);
    EXPECT_EQ(out[0], 255.0);  // clamped
    EXPECT_EQ(out[1], -3.0);   // rounded to nearest
    EXPECT_EQ(out[2], 4294967295.0);
    EXPECT_EQ(out[3], double(0.1f));
    EXPECT_EQ(out[4], 0.1);
    const double nan[5] = {std::nan(""), 0, 0, 0, 0};
    layout.pack_values(nullptr, nullptr, nullptr, nan, rec.data());
    layout.unpack_values(rec.data(), nullptr, nullptr, nullptr, out);
    EXPECT_EQ(out[0], 0.0);
}

TEST(CornerLayout, EightBitColourWithoutAlphaTakesThreeBytesAndRoundsToItsSteps) {
    io::Channels ch;
    ch.color = io::ColorFormat{};
    const io::CornerLayout layout(ch);
    EXPECT_EQ(layout.bytes(), 3u);
    const float in[4] = {1.5f, 0.5f, -1.0f, 0.25f};  // clamped; alpha not stored
    std::byte rec[3];
    layout.pack_values(nullptr, in, nullptr, nullptr, rec);
    float out[4];
    layout.unpack_values(rec, nullptr, out, nullptr, nullptr);
    EXPECT_EQ(out[0], 1.0f);
    EXPECT_EQ(out[1], 128.0f / 255.0f);
    EXPECT_EQ(out[2], 0.0f);
    EXPECT_EQ(out[3], 1.0f);
}

TEST(CornerLayout, EveryEightBitComponentUnpacksToItsQuotientBy255) {
    io::Channels ch;
    ch.color = io::ColorFormat{};
    ch.color->alpha = true;
    const io::CornerLayout layout(ch);
    ASSERT_EQ(layout.bytes(), 4u);
    for (int v = 0; v < 256; ++v) {
        const std::byte rec[4] = {std::byte(v), std::byte(255 - v), std::byte(0), std::byte(v)};
        float out[4];
        layout.unpack_values(rec, nullptr, out, nullptr, nullptr);
        EXPECT_EQ(out[0], float(v) / 255.0f) << v;
        EXPECT_EQ(out[1], float(255 - v) / 255.0f) << v;
        EXPECT_EQ(out[2], 0.0f);
        EXPECT_EQ(out[3], float(v) / 255.0f) << v;
        std::byte back[4];
        layout.pack_values(nullptr, out, nullptr, nullptr, back);  // and back to the same bytes
        EXPECT_EQ(std::memcmp(back, rec, 4), 0) << v;
    }
}

TEST(Channels, DescribeWhatAnOutputLacks) {
    const io::Channels all = every_channel();
    io::Channels ply;
    ply.color = io::ColorFormat{};
    ply.vertex_scalars = {{"intensity", io::ScalarType::kFloat32}};
    EXPECT_EQ(
        io::describe_missing(all, ply),
        "normals, colour alpha, texture coordinates, materials, vertex property 'confidence', face property 'label'");
    EXPECT_EQ(io::describe_missing(all, all), "");
    const io::Channels both = io::intersect(all, ply);
    ASSERT_TRUE(both.color.has_value());
    EXPECT_EQ(both.color->type, io::ScalarType::kUInt16);  // the source's type is kept
    EXPECT_FALSE(both.color->alpha);
    EXPECT_EQ(both.vertex_scalars.size(), 1u);
    EXPECT_FALSE(both.normal);
    EXPECT_TRUE(all.has_attributes());
    io::Channels ids;
    ids.vertex_id = true;
    EXPECT_FALSE(ids.has_attributes());
}
