// io::ReadAhead, io::IndexedReadAhead and io::WriteBehind: the same chunks (triangles), counts and
// bytes as the calls made on the caller's thread, for every format; a reader's error comes after the chunks read before it,
// with its message; a writer's error stops the stream and leaves no file; stopping early joins.
#include "io/pipeline.hpp"

#include "format_util.hpp"
#include "io/error.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace meshstream;
using test::slurp;
using test::spit;
using test::TempDir;

const std::string kFixtures = MESHSTREAM_FIXTURES_DIR;

io::TriangleInput open(const std::string& path) {
    return io::TriangleInput(io::open_input(path), io::BadTriangles::kKeep);
}

// What a read loop saw: every chunk's positions and material indices, and the counts after it.
struct Seen {
    std::vector<std::vector<float>> xyz;
    std::vector<std::vector<uint32_t>> materials;
    std::vector<uint64_t> read;
    std::vector<uint64_t> stored_offset;
    std::string error;
};

void record(Seen& seen, const io::TriangleChunk& chunk, uint64_t read, uint64_t stored_offset) {
    seen.xyz.emplace_back(chunk.xyz().begin(), chunk.xyz().end());
    std::vector<uint32_t> m;
    for (size_t i = 0; i < chunk.size(); ++i) m.push_back(chunk.material_at(i) ? *chunk.material_at(i) : 0);
    seen.materials.push_back(m);
    seen.read.push_back(read);
    seen.stored_offset.push_back(stored_offset);
}

Seen read_direct(const std::string& path, size_t capacity) {
    Seen seen;
    try {
        io::TriangleInput in = open(path);
        io::TriangleChunk chunk(capacity, in.header().channels);
        while (in.next(chunk)) record(seen, chunk, in.count().read, in.source().stored_offset());
    } catch (const io::Error& e) {
        seen.error = e.what();
    }
    return seen;
}

Seen read_ahead(const std::string& path, size_t capacity) {
    Seen seen;
    try {
        io::TriangleInput in = open(path);
        io::TriangleChunk chunk(capacity, in.header().channels);
        io::ReadAhead reader(in, capacity, chunk.channels());
        while (reader.next(chunk)) record(seen, chunk, reader.count().read, reader.stored_offset());
        EXPECT_TRUE(chunk.empty());
        // The reader thread has ended: the input is the caller's again.
        EXPECT_EQ(in.count().read, seen.read.empty() ? 0 : seen.read.back());
        EXPECT_TRUE(in.at_end());
    } catch (const io::Error& e) {
        seen.error = e.what();
    }
    return seen;
}

void expect_same(const Seen& a, const Seen& b, const std::string& what) {
    EXPECT_EQ(a.xyz, b.xyz) << what;
    EXPECT_EQ(a.materials, b.materials) << what;
    EXPECT_EQ(a.read, b.read) << what;
    EXPECT_EQ(a.stored_offset, b.stored_offset) << what;
    EXPECT_EQ(a.error, b.error) << what;
}

TEST(ReadAhead, GivesTheChunksAndCountsOfTheInputForEveryFormat) {
    TempDir dir;
    const std::string wuson = kFixtures + "/obj/WusonOBJ.obj";  // materials, 3732 triangles
    for (const io::Format* f : io::formats()) {
        if (f->open_reader == nullptr || f->open_writer == nullptr) continue;
        for (const std::string suffix : {"", ".gz"}) {
            // A directory each: a .gltf's buffer goes beside it.
            const std::string sub = dir / (std::string(f->name) + suffix);
            std::filesystem::create_directory(sub);
            const std::string path = sub + "/in." + test::file_extension(*f) + suffix;
            {
                io::TriangleInput in = open(wuson);
                io::WriteOptions wo;
                wo.channels = io::writable_channels(*f, in.header().channels, wo);
                wo.materials = in.header().materials;
                io::Output out = io::open_output(path, f->name, wo);
                io::TriangleChunk chunk(1000, wo.channels);
                while (in.next(chunk)) out.write(chunk);
                out.finish();
            }
            // Chunks of 100 triangles: dozens handed over, the queue full most of the time.
            const Seen direct = read_direct(path, 100);
            EXPECT_EQ(direct.read.back(), 3732u) << path;
            EXPECT_TRUE(direct.error.empty()) << path << ": " << direct.error;
            expect_same(direct, read_ahead(path, 100), path);
        }
    }
}

TEST(ReadAhead, RethrowsTheReadersErrorAfterTheChunksBeforeIt) {
    TempDir dir;
    // The bunny gzipped and cut in half (found out mid-stream: a gzip stream states no size),
    // and as ASCII STL with facet 40 000's "endloop" misspelt.
    const std::string gz = dir / "bunny.stl.gz", ascii = dir / "bad.stl";
    for (const auto& [path, format] : {std::pair{gz, "stl"}, std::pair{ascii, "stl-ascii"}}) {
        io::TriangleInput in = open(kFixtures + "/bunny_from_draco.bin.stl");
        io::Output out = io::open_output(path, format, {});
        io::TriangleChunk chunk;
        while (in.next(chunk)) out.write(chunk);
        out.finish();
    }
    const std::string cut_gz = dir / "cut.stl.gz";
    spit(cut_gz, slurp(gz).substr(0, slurp(gz).size() / 2));
    std::string text = slurp(ascii);
    size_t at = 0;
    for (int i = 0; i < 40000; ++i) at = text.find("endloop", at) + 1;
    text.replace(at - 1, 7, "endlop");
    spit(ascii, text);
    for (const std::string& path : {cut_gz, ascii}) {
        const Seen direct = read_direct(path, 64);
        EXPECT_GT(direct.xyz.size(), 10u) << path;
        EXPECT_EQ(direct.error.rfind(path + ":", 0), 0u) << direct.error;
        expect_same(direct, read_ahead(path, 64), path);
    }
}

TEST(ReadAhead, StoppedEarlyJoinsItsThread) {
    io::TriangleInput in = open(kFixtures + "/bunny_from_draco.bin.stl");
    io::TriangleChunk chunk(256, in.header().channels);
    {
        io::ReadAhead reader(in, 256, chunk.channels());
        ASSERT_TRUE(reader.next(chunk));
        EXPECT_EQ(reader.count().read, 256u);
    }
    // The reader stopped after at most the chunks the queue holds.
    EXPECT_LE(in.count().read, 256u * io::kPipelineChunks);
    EXPECT_FALSE(in.at_end());
}

// Writes WusonOBJ (normals, texture coordinates, materials) to `path` as `format` in chunks of
// 500 triangles, through a WriteBehind or not.
void write_wuson(const std::string& path, const io::Format& format, bool threaded) {
    io::TriangleInput in = open(kFixtures + "/obj/WusonOBJ.obj");
    io::WriteOptions wo;
    wo.channels = io::writable_channels(format, in.header().channels, wo);
    wo.materials = in.header().materials;
    io::Output out = io::open_output(path, format.name, wo);
    io::TriangleChunk chunk(500, wo.channels);
    if (!threaded) {
        while (in.next(chunk)) out.write(chunk);
    } else {
        io::WriteBehind writer(out, chunk.capacity(), chunk.channels());
        while (in.next(chunk)) {
            writer.write(chunk);
            EXPECT_TRUE(chunk.empty());
        }
        writer.close();
    }
    out.finish();
}

TEST(WriteBehind, WritesTheSameBytesForEveryFormat) {
    TempDir dir;
    for (const io::Format* f : io::formats()) {
        if (f->open_writer == nullptr) continue;
        for (const std::string suffix : {"", ".gz"}) {
            const std::string ext = test::file_extension(*f) + suffix;
            // A directory each: a .gltf's buffer goes beside it; every file written is compared.
            const std::string a = dir / (std::string(f->name) + suffix + "_a");
            const std::string b = dir / (std::string(f->name) + suffix + "_b");
            std::filesystem::create_directory(a);
            std::filesystem::create_directory(b);
            write_wuson(a + "/out." + ext, *f, false);
            write_wuson(b + "/out." + ext, *f, true);
            size_t files = 0, bytes = 0;
            for (const auto& entry : std::filesystem::directory_iterator(a)) {
                const std::string name = entry.path().filename().string();
                const std::string content = slurp(entry.path().string());
                EXPECT_TRUE(content == slurp(b + "/" + name)) << f->name << " " << name;
                ++files;
                bytes += content.size();
            }
            EXPECT_GT(bytes, 3732u * 3) << ext;
            const auto b_files = std::distance(std::filesystem::directory_iterator(b), {});
            EXPECT_EQ(files, size_t(b_files)) << ext;
        }
    }
}

// Writes its chunks as 36 bytes a triangle, and fails at the chunk numbered `fail_at`.
class FailingWriter final : public io::Writer {
public:
    FailingWriter(io::ByteSink& sink, int fail_at) : sink_(sink), fail_at_(fail_at) {}
    int chunks = 0;

private:
    void write_chunk(const io::TriangleChunk& chunk) override {
        if (chunks++ == fail_at_) throw io::Error(sink_.name(), "disk on fire at chunk " + std::to_string(fail_at_));
        sink_.write(chunk.xyz().data(), chunk.xyz().size_bytes());
    }
    void finish_output() override {}
    io::ByteSink& sink_;
    int fail_at_;
};

TEST(WriteBehind, RethrowsTheWritersErrorAndLeavesNoFile) {
    TempDir dir;
    const std::string path = dir / "out.bin";
    std::string error;
    int written = 0;
    {
        io::Output out;
        out.sink = io::ByteSink::open(path);
        auto writer = std::make_unique<FailingWriter>(*out.sink, 3);
        FailingWriter* failing = writer.get();
        out.writer = std::move(writer);
        io::TriangleChunk chunk(10);
        try {
            io::WriteBehind behind(out, 10, {});
            for (int i = 0; i < 100; ++i) {
                const float tri[9] = {float(i), 0, 0, 1, 0, 0, 0, 1, 0};
                chunk.push(tri);
                behind.write(chunk);
            }
            behind.close();
            out.finish();
        } catch (const io::Error& e) {
            error = e.what();
        }
        written = failing->chunks;
    }
    EXPECT_EQ(error, path + ": disk on fire at chunk 3");
    EXPECT_EQ(written, 4);  // nothing written after the failure
    EXPECT_EQ(dir.entries(), std::vector<std::string>{});
}

}  // namespace

// io::IndexedReadAhead against the reader's own next(): the same triangles (positions, colours,
// vertex ids) in the same order and the same counts, whether the vertex table is in memory or
// read from a file through two caches; a bad face's error after the triangles before it; a
// refused triangle named as next() names it; a polygon larger than a chunk; stopping early.
namespace {

// A binary PLY of a k×k grid of coloured vertices (vertex (1, 1) has a NaN x): its squares as
// triangles, every 7th as a quad, one 12-gon over the first row, a degenerate triangle, and,
// when `bad_face` is given, a face there indexing past the vertices.
std::string grid_ply(int k, int bad_face = -1) {
    std::string body;
    auto put = [&](const auto& v) { body.append(reinterpret_cast<const char*>(&v), sizeof v); };
    for (int y = 0; y < k; ++y)
        for (int x = 0; x < k; ++x) {
            put(x == 1 && y == 1 ? std::nanf("") : float(x));
            put(float(y));
            put(float((x * y) % 5) * 0.25f);
            const uint8_t rgb[3] = {uint8_t(x), uint8_t(y), uint8_t(x ^ y)};
            body.append(reinterpret_cast<const char*>(rgb), 3);
        }
    int faces = 0;
    auto face = [&](std::vector<int32_t> v) {
        if (faces == bad_face) v[0] = k * k + 5;
        put(uint8_t(v.size()));
        for (int32_t i : v) put(i);
        ++faces;
    };
    std::vector<int32_t> row;
    for (int x = 0; x < 12; ++x) row.push_back(x);
    face(row);  // 12 collinear corners: 10 triangles
    face({3, 3, k + 3});  // degenerate
    for (int y = 0; y + 1 < k; ++y)
        for (int x = 0; x + 1 < k; ++x) {
            const int32_t a = y * k + x, b = a + 1, c = a + k + 1, d = a + k;
            if ((y * k + x) % 7 == 0) {
                face({a, b, c, d});
            } else {
                face({a, b, c});
                face({a, c, d});
            }
        }
    return "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(k * k) +
           "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
           "property uchar blue\nelement face " +
           std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n" + body;
}

// Every triangle read (positions, colours, vertex ids, in order), the counts, the error.
struct Stream {
    std::vector<float> xyz, rgba;
    std::vector<uint64_t> ids;
    uint64_t read = 0, dropped = 0, non_finite = 0, degenerate = 0;
    std::string error;
    bool operator==(const Stream&) const = default;
};

Stream read_ply(const std::string& path, uint64_t memory, io::BadTriangles policy, bool indexed, size_t capacity) {
    Stream s;
    io::ReadOptions options;
    options.memory_budget_bytes = memory;
    io::TriangleInput in(io::open_input(path, "", options), policy);
    io::Channels channels = in.header().channels;
    channels.vertex_id = true;
    io::TriangleChunk chunk(capacity, channels);
    auto take = [&] {
        s.xyz.insert(s.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        for (size_t i = 0; i < chunk.size(); ++i) {
            s.rgba.insert(s.rgba.end(), chunk.color_at(i), chunk.color_at(i) + 12);
            s.ids.insert(s.ids.end(), chunk.id_at(i), chunk.id_at(i) + 3);
        }
    };
    try {
        if (indexed) {
            EXPECT_TRUE(io::IndexedReadAhead::possible(in, channels));
            io::IndexedReadAhead reader(in, capacity, channels, options.channels.of(in.header().channels));
            while (reader.next(chunk)) take();
        } else {
            while (in.next(chunk)) take();
        }
    } catch (const io::Error& e) {
        s.error = e.what();
    }
    s.read = in.count().read, s.dropped = in.count().dropped;
    s.non_finite = in.non_finite(), s.degenerate = in.degenerate();
    return s;
}

}  // namespace

TEST(IndexedReadAhead, GivesTheTrianglesAndCountsOfTheReadersNext) {
    TempDir dir;
    spit(dir / "grid.ply", grid_ply(60));
    for (uint64_t memory : {io::kDefaultMemoryBudget, uint64_t{4096}}) {  // 54 KB of vertices: in memory, in a file
        for (size_t capacity : {size_t{7}, size_t{1000}}) {
            SCOPED_TRACE("memory " + std::to_string(memory) + ", capacity " + std::to_string(capacity));
            const Stream direct = read_ply(dir / "grid.ply", memory, io::BadTriangles::kDrop, false, capacity);
            EXPECT_TRUE(direct.error.empty()) << direct.error;
            EXPECT_EQ(direct.degenerate, 1u);
            EXPECT_EQ(direct.non_finite, 6u);  // the squares at vertex (1, 1)
            EXPECT_EQ(direct.read, 10u + 1u + uint64_t(59 * 59 * 2));
            EXPECT_EQ(read_ply(dir / "grid.ply", memory, io::BadTriangles::kDrop, true, capacity), direct);
        }
    }
}

// An error read by both: the same message, after the same triangles, give or take the batch or
// chunk it came in (next() drops the chunk it was filling too, and the two cut at other places).
void expect_same_up_to_the_error(const Stream& indexed, const Stream& direct, size_t capacity) {
    EXPECT_FALSE(direct.error.empty());
    EXPECT_EQ(indexed.error, direct.error);
    const size_t n = std::min(indexed.xyz.size(), direct.xyz.size());
    if (n > 0) {  // bit for bit: NaN kept
        EXPECT_EQ(std::memcmp(indexed.xyz.data(), direct.xyz.data(), n * sizeof(float)), 0);
    }
    EXPECT_LE(std::max(indexed.xyz.size(), direct.xyz.size()) - n, 9 * (capacity + 10));
    EXPECT_EQ(indexed.read, indexed.xyz.size() / 9 + indexed.dropped);
}

TEST(IndexedReadAhead, ErrorsComeAfterTheTrianglesBeforeThemAsTheReadersNextSaysThem) {
    TempDir dir;
    spit(dir / "bad.ply", grid_ply(60, 3000));
    spit(dir / "grid.ply", grid_ply(60));
    for (uint64_t memory : {io::kDefaultMemoryBudget, uint64_t{4096}}) {
        SCOPED_TRACE("memory " + std::to_string(memory));
        const Stream bad = read_ply(dir / "bad.ply", memory, io::BadTriangles::kKeep, false, 100);
        EXPECT_NE(bad.error.find("out of range"), std::string::npos) << bad.error;
        EXPECT_GT(bad.xyz.size(), 9u * 2000u);
        expect_same_up_to_the_error(read_ply(dir / "bad.ply", memory, io::BadTriangles::kKeep, true, 100), bad, 100);
        const Stream refused = read_ply(dir / "grid.ply", memory, io::BadTriangles::kRefuse, false, 100);
        EXPECT_NE(refused.error.find("triangle 11 is degenerate"), std::string::npos) << refused.error;
        expect_same_up_to_the_error(read_ply(dir / "grid.ply", memory, io::BadTriangles::kRefuse, true, 100), refused,
                                    100);
    }
}

TEST(IndexedReadAhead, StoppedEarlyJoinsItsThreads) {
    TempDir dir;
    spit(dir / "grid.ply", grid_ply(60));
    io::ReadOptions options;
    options.memory_budget_bytes = 4096;
    io::TriangleInput in(io::open_input(dir / "grid.ply", "", options), io::BadTriangles::kKeep);
    io::TriangleChunk chunk(50, in.header().channels);
    {
        io::IndexedReadAhead reader(in, 50, chunk.channels(), in.header().channels);
        ASSERT_TRUE(reader.next(chunk));
        EXPECT_EQ(chunk.size(), 50u);
    }
    EXPECT_EQ(in.count().read, 50u);
    EXPECT_FALSE(in.at_end());
}
