// The meshstream triangle stream (io/triangle_stream.cpp): every channel and the material table
// bit for bit (NaN payloads and -0 included), any chunk capacity, plain and gzip, detection by
// magic bytes whatever the name, truncation at every byte an error, and each bad field named at
// its byte.
#include "io/triangle_stream.hpp"

#include "indexed_test_util.hpp"
#include "io/error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace {

using namespace meshstream;
using meshstream::test::TempDir;

io::Channels all_channels() {
    io::Channels c;
    c.normal = true;
    c.color = io::ColorFormat{io::ScalarType::kUInt16, true};
    c.uv_sets = 2;
    c.vertex_scalars = {{"intensity", io::ScalarType::kFloat32}, {"confidence", io::ScalarType::kUInt8}};
    c.vertex_id = true;
    c.material = true;
    c.face_scalars = {{"label", io::ScalarType::kInt32}};
    return c;
}

std::vector<io::Material> materials() {
    io::Material plain{"plain", {0.5f, 0.25f, 1, 1}, std::nullopt};
    io::Material textured{"wood", {1, 1, 1, 0.5f}, io::Texture{"wood.png", "image/png", {std::byte{1}, std::byte{0}}}};
    return {plain, textured};
}

// `n` triangles with every channel set to distinct values, positions with a NaN payload, -0
// and infinities among them.
io::TriangleChunk sample_chunk(size_t n) {
    io::TriangleChunk chunk(n, all_channels());
    const float odd_nan = std::bit_cast<float>(uint32_t{0xFFC01234});
    for (size_t t = 0; t < n; ++t) {
        float* xyz = chunk.push_slot();
        for (int k = 0; k < 9; ++k) xyz[k] = float(t * 9 + k) * 0.5f;
        if (t % 5 == 1) xyz[0] = -0.0f;
        if (t % 7 == 2) xyz[4] = odd_nan;
        if (t % 11 == 3) xyz[8] = -std::numeric_limits<float>::infinity();
        if (t % 3 == 0) std::memcpy(xyz + 6, xyz, 3 * sizeof(float));  // degenerate
        for (int k = 0; k < 9; ++k) chunk.normal_at(t)[k] = float(k) - float(t);
        for (int k = 0; k < 12; ++k) chunk.color_at(t)[k] = float(k) / 12.0f;
        for (int s = 0; s < 2; ++s)
            for (int k = 0; k < 6; ++k) chunk.uv_at(t, s)[k] = float(s * 10 + k) + float(t);
        for (size_t c = 0; c < 2; ++c)
            for (int k = 0; k < 3; ++k) chunk.vertex_scalar_at(t, c)[k] = double(t) + 0.1 * double(c * 3 + k);
        for (int k = 0; k < 3; ++k) chunk.id_at(t)[k] = (uint64_t{1} << 40) + t * 3 + k;
        *chunk.material_at(t) = uint32_t(t % 2);
        *chunk.face_scalar_at(t, 0) = -double(t);
    }
    return chunk;
}

io::WriteOptions options_for(const io::Channels& channels, std::optional<uint64_t> count = std::nullopt) {
    io::WriteOptions o;
    o.channels = channels;
    o.materials = materials();
    o.sorted_axis = 1;
    o.triangle_count = count;
    return o;
}

void write_stream(const std::string& path, const io::TriangleChunk& chunk, std::optional<uint64_t> count = {}) {
    io::Output out = io::open_output(path, "stream", options_for(chunk.channels(), count), 6);
    out.write(chunk);
    out.finish();
}

// Every byte of every slot the two chunks' channels share.
void expect_same_bits(const io::TriangleChunk& a, const io::TriangleChunk& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    auto same = [&](const void* x, const void* y, size_t bytes) { return std::memcmp(x, y, bytes) == 0; };
    for (size_t t = 0; t < a.size(); ++t) {
        EXPECT_TRUE(same(&a.xyz()[9 * t], &b.xyz()[9 * t], 36)) << what << " triangle " << t;
        EXPECT_TRUE(same(a.normal_at(t), b.normal_at(t), 36)) << what << " " << t;
        EXPECT_TRUE(same(a.color_at(t), b.color_at(t), 48)) << what << " " << t;
        for (int s = 0; s < 2; ++s) EXPECT_TRUE(same(a.uv_at(t, s), b.uv_at(t, s), 24)) << what << " " << t;
        for (size_t c = 0; c < 2; ++c)
            EXPECT_TRUE(same(a.vertex_scalar_at(t, c), b.vertex_scalar_at(t, c), 24)) << what << " " << t;
        EXPECT_TRUE(same(a.id_at(t), b.id_at(t), 24)) << what << " " << t;
        EXPECT_EQ(*a.material_at(t), *b.material_at(t)) << what << " " << t;
        EXPECT_TRUE(same(a.face_scalar_at(t, 0), b.face_scalar_at(t, 0), 8)) << what << " " << t;
    }
}

io::TriangleChunk read_all(const std::string& path, size_t capacity, io::MeshHeader* header = nullptr) {
    io::Input in = io::open_input(path);
    EXPECT_EQ(in.format, &io::kTriangleStreamFormat);
    if (header) *header = in.reader->header();
    io::TriangleChunk part(capacity, in.reader->header().channels);
    io::TriangleChunk all(1000, in.reader->header().channels);
    while (in.reader->next(part))
        for (size_t i = 0; i < part.size(); ++i) all.push_copy(part, i);
    return all;
}

TEST(TriangleStream, EveryChannelAndTheMaterialTableGoThroughBitForBit) {
    TempDir dir;
    const io::TriangleChunk chunk = sample_chunk(40);
    for (const char* name : {"a.mstream", "a.mstream.gz", "no-extension"}) {
        write_stream(dir / name, chunk, 40);
        for (size_t capacity : {size_t{1}, size_t{7}, io::TriangleChunk::kDefaultCapacity}) {
            io::MeshHeader header;
            const io::TriangleChunk back = read_all(dir / name, capacity, &header);
            expect_same_bits(chunk, back, std::string(name) + " capacity " + std::to_string(capacity));
            EXPECT_EQ(header.channels, all_channels());
            EXPECT_EQ(header.materials, materials());
            EXPECT_EQ(header.sorted_axis, 1);
            EXPECT_EQ(header.triangle_count, 40u);
        }
    }
}

TEST(TriangleStream, CountIsOptionalAndAReaderTakesTheChannelsItAsksFor) {
    TempDir dir;
    const io::TriangleChunk chunk = sample_chunk(9);
    write_stream(dir / "a.mstream", chunk);
    io::Input in = io::open_input(dir / "a.mstream");
    EXPECT_EQ(in.reader->header().triangle_count, std::nullopt);
    io::Channels some;
    some.material = true;
    some.face_scalars = {{"label", io::ScalarType::kInt32}};
    io::TriangleChunk part(4, some);
    size_t seen = 0;
    while (in.reader->next(part))
        for (size_t i = 0; i < part.size(); ++i, ++seen) {
            EXPECT_EQ(std::memcmp(&part.xyz()[9 * i], &chunk.xyz()[9 * seen], 36), 0);
            EXPECT_EQ(*part.material_at(i), seen % 2);
            EXPECT_EQ(*part.face_scalar_at(i, 0), -double(seen));
        }
    EXPECT_EQ(seen, 9u);
}

TEST(TriangleStream, AnEmptyStreamIsAValidEmptyMesh) {
    TempDir dir;
    io::Output out = io::open_output(dir / "e.mstream", "stream", io::WriteOptions{}, 6);
    out.finish();
    EXPECT_EQ(read_all(dir / "e.mstream", 16).size(), 0u);
}

TEST(TriangleStream, TruncationAtEveryByteIsAnError) {
    TempDir dir;
    io::Channels material;
    material.material = true;
    io::TriangleChunk chunk(2, material);
    for (int t = 0; t < 2; ++t) {
        float* xyz = chunk.push_slot();
        for (int k = 0; k < 9; ++k) xyz[k] = float(t + k);
        *chunk.material_at(size_t(t)) = uint32_t(t);
    }
    write_stream(dir / "a.mstream", chunk);
    const std::string bytes = meshstream::test::slurp(dir / "a.mstream");
    for (size_t cut = 1; cut < bytes.size(); ++cut) {
        std::ofstream(dir / "cut.mstream", std::ios::binary).write(bytes.data(), std::streamsize(cut));
        try {
            read_all(dir / "cut.mstream", 2);
            ADD_FAILURE() << "cut at " << cut << " read without error";
        } catch (const io::Error& e) {
            EXPECT_EQ(e.file(), dir / "cut.mstream") << cut;
            EXPECT_GT(e.byte_offset(), 0u) << e.what();
        }
    }
}

// Each field a corrupt stream can get wrong, named at its byte.
TEST(TriangleStream, BadFieldsAreNamedAtTheirByte) {
    TempDir dir;
    write_stream(dir / "good.mstream", sample_chunk(2), 2);
    const std::string good = meshstream::test::slurp(dir / "good.mstream");
    auto error_of = [&](std::string bytes) {
        std::ofstream(dir / "bad.mstream", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
        try {
            io::ReadOptions small;
            small.memory_budget_bytes = 1 << 20;
            io::Input in = io::open_input(dir / "bad.mstream", "stream", small);
            io::TriangleChunk chunk(16, in.reader->header().channels);
            while (in.reader->next(chunk)) {}
        } catch (const io::Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    std::string version = good;
    version[8] = 2;
    EXPECT_EQ(error_of(version),
              dir / "bad.mstream" + ": byte 8: triangle stream version 2 (this meshstream reads version 1)");
    std::string huge_header = good;
    huge_header[12 + 4] = 1;  // 2^32 + ... bytes
    EXPECT_NE(error_of(huge_header).find(": byte 12: header of 42949"), std::string::npos) << error_of(huge_header);
    std::string tail = good + "x";
    EXPECT_NE(error_of(tail).find("data after the end marker"), std::string::npos) << error_of(tail);
    std::string end_count = good;
    end_count[end_count.size() - 12] = 3;  // the end marker's count
    EXPECT_NE(error_of(end_count).find("end marker counts 3 triangles, the stream holds 2"), std::string::npos)
        << error_of(end_count);
    std::string end_tag = good;
    end_tag.back() = 'X';
    EXPECT_NE(error_of(end_tag).find("bad end marker"), std::string::npos);
    std::string promised = good;
    promised[20] = 5;  // the header's count
    EXPECT_NE(error_of(promised).find("header promises 5 triangles, stream holds 2"), std::string::npos)
        << error_of(promised);
    const size_t body = 20 + std::bit_cast<uint64_t>(*reinterpret_cast<const std::array<char, 8>*>(good.data() + 12));
    std::string chunk_count = good;
    chunk_count[body + 3] = char(0x7F);  // a chunk of about 2^31 triangles
    EXPECT_NE(error_of(chunk_count).find("byte " + std::to_string(body) + ": chunk of 21"), std::string::npos)
        << error_of(chunk_count);
    std::string scalars = good;
    scalars[36] = char(0xFF);  // the vertex scalar count
    EXPECT_NE(error_of(scalars).find("byte 36: 255 vertex scalar channels (at most 64)"), std::string::npos)
        << error_of(scalars);
    std::string axis = good;
    axis[28] = 7;
    EXPECT_NE(error_of(axis).find("byte 28: sorted axis 7"), std::string::npos) << error_of(axis);
}

TEST(TriangleStream, DetectedByMagicWhateverTheName) {
    TempDir dir;
    write_stream(dir / "looks.stl", sample_chunk(4));
    EXPECT_EQ(io::open_input(dir / "looks.stl").format, &io::kTriangleStreamFormat);
    EXPECT_TRUE(io::probe_triangle_stream(std::as_bytes(std::span("\x89MSH\r\n\x1a\n", 8))));
    EXPECT_FALSE(io::probe_triangle_stream(std::as_bytes(std::span("\x89MSH\r\n\n\n", 8))));
}

}  // namespace

// A stream with a count in a plain file is read from any triangle to any other, past whole
// chunks; a stream without a count, or gzipped, cannot be: the reader says so and changes nothing.
TEST(TriangleStream, ASelectionGoesPastWholeChunksToItsFirstTriangleAndStopsAtItsEnd) {
    TempDir dir;
    const io::TriangleChunk sample = sample_chunk(40);
    auto write_in_chunks = [&](const std::string& path, std::optional<uint64_t> count) {
        io::Output out = io::open_output(path, "stream", options_for(sample.channels(), count), 6);
        for (size_t from = 0, n = 3; from < sample.size(); from += n, n = n % 9 + 4) {  // chunks of 3, 7, 11, 6, ...
            io::TriangleChunk part(n, sample.channels());
            for (size_t i = from; i < std::min(sample.size(), from + n); ++i) part.push_copy(sample, i);
            out.write(part);
        }
        out.finish();
    };
    write_in_chunks(dir / "s.mstream", 40);
    write_in_chunks(dir / "nocount.mstream", std::nullopt);
    write_in_chunks(dir / "s.mstream.gz", 40);
    const io::TriangleChunk all = read_all(dir / "s.mstream", 1000);
    ASSERT_EQ(all.size(), 40u);
    for (const auto& [first, end] : std::vector<std::pair<uint64_t, uint64_t>>{
             {0, 40}, {0, 5}, {3, 10}, {10, 10}, {17, 33}, {21, 40}, {39, 40}, {40, 40}}) {
        const std::string what = std::to_string(first) + ".." + std::to_string(end);
        io::Input in = io::open_input(dir / "s.mstream");
        if (first == 40) {  // nothing to go to: read as it comes
            EXPECT_FALSE(in.reader->select_triangles(first, end)) << what;
            continue;
        }
        ASSERT_TRUE(in.reader->select_triangles(first, end)) << what;
        io::TriangleChunk part(4, sample.channels()), got(1000, sample.channels()), want(1000, sample.channels());
        while (in.reader->next(part))
            for (size_t i = 0; i < part.size(); ++i) got.push_copy(part, i);
        for (uint64_t i = first; i < end; ++i) want.push_copy(all, i);
        expect_same_bits(got, want, what);
    }
    for (const std::string& path : {dir / "nocount.mstream", dir / "s.mstream.gz"}) {
        io::Input in = io::open_input(path);
        EXPECT_FALSE(in.reader->select_triangles(5, 10)) << path;
        io::TriangleChunk part(1000, sample.channels());
        ASSERT_TRUE(in.reader->next(part)) << path;  // from the start, as before
        EXPECT_EQ(std::memcmp(part.xyz().data(), all.xyz().data(), 36), 0) << path;
    }
}
