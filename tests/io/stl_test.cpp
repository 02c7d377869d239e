// STL reader/writer tests: exact counts on real fixtures, round trips over both encodings and
// gzip with bit-exact floats, chunk-boundary runs, a binary file's records selected without
// reading those before, truncation at every byte, and bad input as
// small inline strings asserting file, line or byte and the message.
#include "io/stl.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/triangle_input.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>

namespace io = meshstream::io;
namespace fs = std::filesystem;

using meshstream::test::slurp;

namespace {

std::string fixture(const std::string& name) { return std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name; }

// Bytes in memory as a RawInput: with or without a known size (a file vs. stdin), handing out at
// most `piece` bytes per read to exercise refills.
class MemoryInput : public io::RawInput {
public:
    MemoryInput(std::string bytes, bool sized, size_t piece) : bytes_(std::move(bytes)), sized_(sized), piece_(piece) {}
    size_t read(void* dst, size_t n) override {
        size_t take = std::min({n, piece_, bytes_.size() - pos_});
        std::memcpy(dst, bytes_.data() + pos_, take);
        pos_ += take;
        return take;
    }
    std::optional<uint64_t> size() const override {
        return sized_ ? std::optional<uint64_t>(bytes_.size()) : std::nullopt;
    }

private:
    std::string bytes_;
    bool sized_;
    size_t piece_;
    size_t pos_ = 0;
};

std::unique_ptr<io::ByteSource> memory_source(std::string bytes, const std::string& name, bool sized,
                                              size_t piece = std::numeric_limits<size_t>::max()) {
    return std::make_unique<io::ByteSource>(std::make_unique<MemoryInput>(std::move(bytes), sized, piece), name);
}

struct Mesh {
    std::vector<float> xyz;
    io::MeshHeader header;
    std::string format;
    size_t chunks = 0;
};

// Reads every chunk, checking that all but the last are full; the header as it is at the end
// (with the reader's warnings).
Mesh drain(io::Reader& reader, size_t capacity) {
    Mesh mesh;
    io::TriangleChunk chunk(capacity);
    bool short_seen = false;
    while (reader.next(chunk)) {
        EXPECT_FALSE(short_seen) << "a short chunk was followed by more triangles";
        short_seen = !chunk.full();
        mesh.xyz.insert(mesh.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        ++mesh.chunks;
    }
    EXPECT_TRUE(chunk.empty());
    mesh.header = reader.header();
    return mesh;
}

Mesh read_path(const std::string& path, size_t capacity = io::TriangleChunk::kDefaultCapacity,
               std::string_view from = {}) {
    io::Input in = io::open_input(path, from);
    Mesh mesh = drain(*in.reader, capacity);
    mesh.format = in.format->name;
    return mesh;
}

// Reads from memory through the "stl" format's reader (auto-detecting binary/ASCII).
Mesh read_memory(std::string bytes, const std::string& name, bool sized, size_t capacity = 4096,
                 size_t piece = std::numeric_limits<size_t>::max(), const io::ReadOptions& options = {}) {
    auto source = memory_source(std::move(bytes), name, sized, piece);
    auto reader = io::kStlFormat.open_reader(*source, options);
    return drain(*reader, capacity);
}

constexpr size_t kWhole = std::numeric_limits<size_t>::max();  // read_memory's piece: all at once

io::ReadOptions strict_options() {
    io::ReadOptions o;
    o.strict = true;
    return o;
}

// The reader's warning that starts with `text`, or one with count 0 when there is none.
io::ReaderWarning warning_of(const Mesh& mesh, std::string_view text) {
    for (const io::ReaderWarning& w : mesh.header.warnings)
        if (w.text.starts_with(text)) return w;
    return {std::string(text), 0};
}

void write_path(const std::string& path, const std::vector<float>& xyz, std::string_view to,
                io::WriteOptions options = {}, size_t capacity = 1000) {
    io::Output out = io::open_output(path, to, options);
    io::TriangleChunk chunk(capacity);
    for (size_t t = 0; t < xyz.size() / 9; ++t) {
        float tri[9];
        std::memcpy(tri, &xyz[9 * t], sizeof tri);
        chunk.push(tri);
        if (chunk.full()) {
            out.write(chunk);
            chunk.clear();
        }
    }
    if (!chunk.empty()) out.write(chunk);
    out.finish();
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

// Runs f and returns the io::Error it throws (fails the test when it throws nothing).
io::Error error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const io::Error& e) {
        return e;
    }
    ADD_FAILURE() << "no io::Error thrown";
    return io::Error("", "none");
}

// A binary STL in memory: `header` padded with NULs (or the given pad byte) to 80 bytes.
std::string binary_stl(std::string header, const std::vector<float>& xyz, uint32_t count_field, char pad = '\0') {
    header.resize(80, pad);
    std::string out = header;
    for (int i = 0; i < 4; ++i) out += static_cast<char>(count_field >> (8 * i));
    for (size_t t = 0; t < xyz.size() / 9; ++t) {
        float facet[12] = {0, 0, 1};
        std::memcpy(facet + 3, &xyz[9 * t], 9 * sizeof(float));
        out.append(reinterpret_cast<const char*>(facet), sizeof facet);  // little-endian host
        out += std::string("\x07\x00", 2);                               // attribute bytes, ignored
    }
    return out;
}

class StlTest : public ::testing::Test {
protected:
    void SetUp() override {
        std::string pattern = (fs::temp_directory_path() / "stl_test-XXXXXX").string();
        ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
        dir_ = pattern;
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    fs::path dir_;
};

const std::vector<float> kTwoTriangles = {0,     0,    0,         1,     0,     0, 0,      1, 0,  //
                                          -0.0f, 1.5f, -2.25e-7f, 3e30f, -0.0f, 1, 1e-40f, 2, 3};

TEST(StlReader, ExactCountsOnFixtures) {
    struct Case {
        const char* file;
        uint64_t triangles;
        const char* variant;
    };
    const Case cases[] = {
        {"bunny_from_draco.bin.stl", 69451, "binary"},
        {"cube.bin.stl", 12, "binary"},
        {"cube_crlf.ascii.stl", 12, "ascii"},
        {"faceless.ascii.stl", 0, "ascii"},
        {"gearwheel.ascii.stl", 2444, "ascii"},
        {"gearwheel.bin.stl", 2444, "binary"},
        {"Spider_binary.stl", 1368, "binary"},
        {"cgal_sphere_attrbytes.bin.stl", 320, "binary"},
        {"missingNormal.ascii.stl", 4, "ascii"},
        {"notANumberNormal.ascii.stl", 4, "ascii"},
        {"multiWordName.ascii.stl", 4, "ascii"},
        {"tetrahedronMinusZero.bin.stl", 4, "binary"},
        {"tetrahedron.ascii.stl", 4, "ascii"},
        {"sphereWithHole.stl", 285, "ascii"},
        {"wrongHeader.bin.stl", 12, "binary"},
        {"triangle_with_two_solids.stl", 2, "ascii"},
        {"cube.bin.stl.gz", 12, "binary"},
        {"gearwheel.ascii.stl.gz", 2444, "ascii"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        Mesh mesh = read_path(fixture(c.file));
        EXPECT_EQ(mesh.xyz.size(), 9 * c.triangles);
        EXPECT_EQ(mesh.header.variant, c.variant);
        if (std::string_view(c.variant) == "binary") {
            EXPECT_EQ(mesh.format, "stl");
            EXPECT_EQ(mesh.header.triangle_count, c.triangles);
        } else {
            EXPECT_EQ(mesh.format, "stl-ascii");
            EXPECT_FALSE(mesh.header.triangle_count.has_value());
        }
        EXPECT_FALSE(mesh.header.sorted_axis.has_value());
    }
}

TEST(StlReader, ReportsHeaderTextAndSolidName) {
    auto note = [](const std::string& file) {
        io::Input in = io::open_input(fixture(file));
        return in.reader->header().notes.at(0);
    };
    EXPECT_EQ(
        note("bunny_from_draco.bin.stl"),
        std::make_pair(std::string("header"), std::string("Stanford bunny, 69451 triangles, from Draco test data")));
    EXPECT_EQ(note("Spider_binary.stl").second, "Generated by Caligari's trueSpace");
    EXPECT_EQ(note("cgal_sphere_attrbytes.bin.stl").second, "FileType: Binary");
    EXPECT_EQ(note("multiWordName.ascii.stl"),
              std::make_pair(std::string("solid"), std::string("Model with a multi word name")));
    EXPECT_EQ(note("faceless.ascii.stl").second, "empty");
}

TEST(StlReader, AsciiAndBinaryFixturesOfTheSameMeshAgree) {
    // stl-models ships the cube and tetrahedron in both encodings with identical coordinates.
    EXPECT_TRUE(same_bits(read_path(fixture("cube_crlf.ascii.stl")).xyz, read_path(fixture("cube.bin.stl")).xyz));
    EXPECT_TRUE(same_bits(read_path(fixture("tetrahedron.ascii.stl")).xyz,
                          read_path(fixture("tetrahedronMinusZero.bin.stl")).xyz));
    // The gzip fixtures decode to their plain twins.
    EXPECT_TRUE(same_bits(read_path(fixture("cube.bin.stl.gz")).xyz, read_path(fixture("cube.bin.stl")).xyz));
    EXPECT_TRUE(
        same_bits(read_path(fixture("gearwheel.ascii.stl.gz")).xyz, read_path(fixture("gearwheel.ascii.stl")).xyz));
}

TEST(StlReader, AttributeBytesAndNormalsAreIgnored) {
    Mesh mesh = read_memory(binary_stl("attr", kTwoTriangles, 2), "attr.stl", true);
    EXPECT_TRUE(same_bits(mesh.xyz, kTwoTriangles));
}

TEST(StlReader, SolidHeaderBinaryIsBinary) {
    // wrongHeader.bin.stl: a real binary STL whose header is "solid" + NULs.
    std::string bytes = slurp(fixture("wrongHeader.bin.stl"));
    ASSERT_EQ(bytes.substr(0, 5), "solid");
    for (bool sized : {true, false}) {
        SCOPED_TRACE(sized);
        Mesh mesh = read_memory(bytes, "wrongHeader.bin.stl", sized);
        EXPECT_EQ(mesh.header.variant, "binary");
        EXPECT_EQ(mesh.xyz.size(), 9u * 12);
    }
    // Worse: a header that is all text, "solid ..." padded with spaces; only the count and the
    // floats are not text.
    std::string made = binary_stl("solid written by a careless exporter", kTwoTriangles, 2, ' ');
    for (bool sized : {true, false}) {
        SCOPED_TRACE(sized);
        Mesh mesh = read_memory(made, "made.stl", sized);
        EXPECT_EQ(mesh.header.variant, "binary");
        EXPECT_TRUE(same_bits(mesh.xyz, kTwoTriangles));
    }
    EXPECT_TRUE(io::probe_stl_binary(std::as_bytes(std::span(made.data(), made.size())), made.size()));
    EXPECT_FALSE(io::kStlAsciiFormat.probe(std::as_bytes(std::span(made.data(), made.size())), made.size()));
    // And its count lying: still read as binary, so the error is about the count.
    std::string lying = binary_stl("solid written by a careless exporter", kTwoTriangles, 3, ' ');
    io::Error e = error_of([&] { read_memory(lying, "lying.stl", true); });
    EXPECT_STREQ(e.what(), "lying.stl: byte 84: header promises 3 triangles, file holds 2");
}

TEST(StlProbe, DecidesBySizeThenContent) {
    std::string cube = slurp(fixture("cube.bin.stl"));
    std::string ascii = slurp(fixture("tetrahedron.ascii.stl"));
    auto head = [](const std::string& s) {
        return std::as_bytes(std::span(s.data(), std::min<size_t>(s.size(), 4096)));
    };
    EXPECT_TRUE(io::probe_stl_binary(head(cube), 684));
    EXPECT_FALSE(io::probe_stl_binary(head(cube), 685));
    EXPECT_TRUE(io::probe_stl_binary(head(cube), std::nullopt));
    EXPECT_FALSE(io::probe_stl_binary(head(cube).first(83), std::nullopt));
    EXPECT_FALSE(io::probe_stl_binary(head(ascii), ascii.size()));
    EXPECT_FALSE(io::probe_stl_binary(head(ascii), std::nullopt));
    EXPECT_TRUE(io::kStlAsciiFormat.probe(head(ascii), ascii.size()));
    EXPECT_TRUE(io::kStlAsciiFormat.probe(head(ascii), std::nullopt));
    EXPECT_FALSE(io::kStlAsciiFormat.probe(head(cube), std::nullopt));
    // Leading BOM and whitespace before "solid"; "solidus" is not "solid".
    std::string bom = "\xef\xbb\xbf  \n solid x\nendsolid x\n";
    EXPECT_TRUE(io::kStlAsciiFormat.probe(head(bom), bom.size()));
    std::string solidus = "solidus\n";
    EXPECT_FALSE(io::kStlAsciiFormat.probe(head(solidus), solidus.size()));
}

TEST_F(StlTest, RoundTripsBothEncodingsPlainAndGzipBitExact) {
    const std::vector<float> bunny = read_path(fixture("bunny_from_draco.bin.stl")).xyz;
    ASSERT_EQ(bunny.size(), 9u * 69451);
    // The whole bunny through binary -> ASCII -> binary.
    write_path(path("bunny.ascii.stl"), bunny, "stl-ascii");
    write_path(path("bunny.bin.stl"), read_path(path("bunny.ascii.stl")).xyz, "stl");
    Mesh whole = read_path(path("bunny.bin.stl"));
    EXPECT_TRUE(same_bits(whole.xyz, bunny));
    EXPECT_EQ(whole.header.triangle_count, 69451u);
    // Each encoding x plain/gzip x count known or not (patched, spooled or written up front),
    // on the bunny's first 5000 triangles to keep the suite fast.
    const std::vector<float> part(bunny.begin(), bunny.begin() + 9 * 5000);
    for (std::string_view to : {"stl", "stl-ascii"}) {
        for (std::string_view suffix : {".stl", ".stl.gz"}) {
            for (bool announce : {false, true}) {
                std::string out = path("rt" + std::string(suffix));
                SCOPED_TRACE(std::string(to) + " " + out + (announce ? " announced" : ""));
                io::WriteOptions options;
                if (announce) options.triangle_count = 5000;
                write_path(out, part, to, options);
                std::string bytes = slurp(out);
                EXPECT_EQ(bytes.substr(0, 2) == "\x1f\x8b", suffix == ".stl.gz");
                Mesh back = read_path(out);
                EXPECT_TRUE(same_bits(back.xyz, part));
                EXPECT_EQ(back.header.variant, to == "stl" ? "binary" : "ascii");
                if (to == "stl") {
                    EXPECT_EQ(back.header.triangle_count, 5000u);
                }
                if (to == "stl" && suffix == ".stl") {
                    EXPECT_EQ(bytes.size(), 84u + 50 * 5000);
                }
            }
        }
    }
    // ASCII -> binary -> ASCII gives the same ASCII bytes.
    write_path(path("a.stl"), read_path(fixture("gearwheel.ascii.stl")).xyz, "stl-ascii");
    write_path(path("b.stl"), read_path(path("a.stl")).xyz, "stl");
    write_path(path("c.stl"), read_path(path("b.stl")).xyz, "stl-ascii");
    EXPECT_EQ(slurp(path("a.stl")), slurp(path("c.stl")));
}

TEST_F(StlTest, BinaryReaderSelectsItsRecordsInAPlainFile) {
    // Seven distinct triangles, the fifth degenerate: a selection reads exactly its records,
    // gives their ordinals in the file, and is refused where the reader cannot seek.
    std::vector<float> xyz;
    for (int t = 0; t < 7; ++t)
        for (int c = 0; c < 9; ++c)
            xyz.push_back(t == 4 && c >= 3 && c < 6 ? float(10 * t + c - 3) : float(10 * t + c));
    const std::string stl = binary_stl("seven", xyz, 7);
    const std::string file = path("seven.stl");
    meshstream::test::spit(file, stl);
    const std::vector<float> middle(xyz.begin() + 9 * 2, xyz.begin() + 9 * 6);  // triangles [2, 6)
    {
        io::Input in = io::open_input(file);
        ASSERT_TRUE(in.reader->select_triangles(2, 6));
        EXPECT_TRUE(same_bits(drain(*in.reader, 3).xyz, middle));
    }
    {
        // An empty selection, and one from the last record to the end.
        io::Input in = io::open_input(file);
        ASSERT_TRUE(in.reader->select_triangles(3, 3));
        EXPECT_TRUE(drain(*in.reader, 4).xyz.empty());
        io::Input last = io::open_input(file);
        ASSERT_TRUE(last.reader->select_triangles(6, 7));
        EXPECT_TRUE(same_bits(drain(*last.reader, 4).xyz, std::vector<float>(xyz.end() - 9, xyz.end())));
    }
    {
        // The read loop counts from the selection's first triangle: the dropped one is the
        // fifth of the file, refused by its ordinal there.
        io::TriangleInput drop(io::open_input(file), io::BadTriangles::kDrop);
        ASSERT_TRUE(drop.select_triangles(2, 6));
        io::TriangleChunk chunk;
        uint64_t passed = 0;
        while (drop.next(chunk)) passed += chunk.size();
        EXPECT_EQ(passed, 3u);
        EXPECT_EQ(drop.count().read, 6u);
        EXPECT_EQ(drop.degenerate(), 1u);
        io::TriangleInput refuse(io::open_input(file), io::BadTriangles::kRefuse);
        ASSERT_TRUE(refuse.select_triangles(3, 7));
        const io::Error e = error_of([&] {
            while (refuse.next(chunk)) {}
        });
        EXPECT_NE(std::string(e.what()).find("triangle 5 is degenerate"), std::string::npos) << e.what();
    }
    {
        // Refused: out of order, past the count, after reading has begun, through gzip, from a
        // source of unknown size.
        io::Input in = io::open_input(file);
        EXPECT_FALSE(in.reader->select_triangles(4, 2));
        EXPECT_FALSE(in.reader->select_triangles(0, 8));
        io::TriangleChunk chunk(1);
        ASSERT_TRUE(in.reader->next(chunk));
        EXPECT_FALSE(in.reader->select_triangles(2, 6));
        EXPECT_EQ(drain(*in.reader, 3).xyz.size(), 9u * 6);  // the rest, as if never asked
        {
            auto sink = io::ByteSink::open(path("seven.stl.gz"), {6});
            sink->write(stl.data(), stl.size());
            sink->commit();
        }
        io::Input gz = io::open_input(path("seven.stl.gz"));
        EXPECT_FALSE(gz.reader->select_triangles(2, 6));
        EXPECT_TRUE(same_bits(drain(*gz.reader, 3).xyz, xyz));
        auto source = memory_source(stl, "stdin", false);
        auto reader = io::kStlFormat.open_reader(*source, {});
        EXPECT_FALSE(reader->select_triangles(2, 6));
    }
}

TEST_F(StlTest, AsciiKeepsNegativeZeroTinyAndHugeFloats) {
    write_path(path("z.stl"), kTwoTriangles, "stl-ascii");
    std::string text = slurp(path("z.stl"));
    EXPECT_NE(text.find("vertex -0 1.5 -2.25e-07\n"), std::string::npos) << text;
    EXPECT_NE(text.find("vertex 3e+30 -0 1\n"), std::string::npos) << text;
    Mesh back = read_path(path("z.stl"));
    EXPECT_TRUE(same_bits(back.xyz, kTwoTriangles));
    EXPECT_TRUE(std::signbit(back.xyz[9]));
    EXPECT_EQ(text.substr(0, 17), "solid meshstream\n");
    EXPECT_EQ(text.substr(text.size() - 20), "endsolid meshstream\n");
}

TEST_F(StlTest, ChunkCapacitiesGiveIdenticalOutput) {
    for (const char* file : {"bunny_from_draco.bin.stl", "gearwheel.ascii.stl", "gearwheel.ascii.stl.gz"}) {
        SCOPED_TRACE(file);
        Mesh whole = read_path(fixture(file));
        for (size_t capacity : {size_t{1}, size_t{7}}) {
            Mesh bits = read_path(fixture(file), capacity);
            EXPECT_TRUE(same_bits(bits.xyz, whole.xyz)) << capacity;
            EXPECT_EQ(bits.chunks, (whole.xyz.size() / 9 + capacity - 1) / capacity);
        }
        if (std::string_view(file) == "bunny_from_draco.bin.stl") continue;  // writers: smaller meshes suffice
        // Writers fed chunks of 1 and 7 produce the same bytes as one big chunk.
        write_path(path("big.stl"), whole.xyz, "stl", {}, 1 << 20);
        write_path(path("one.stl"), whole.xyz, "stl", {}, 1);
        write_path(path("seven.stl"), whole.xyz, "stl-ascii", {}, 7);
        write_path(path("big_ascii.stl"), whole.xyz, "stl-ascii", {}, 1 << 20);
        EXPECT_EQ(slurp(path("big.stl")), slurp(path("one.stl")));
        EXPECT_EQ(slurp(path("big_ascii.stl")), slurp(path("seven.stl")));
    }
    // A source handing out 3 bytes per read puts facets across every refill boundary.
    std::string bytes = slurp(fixture("gearwheel.bin.stl"));
    Mesh trickle = read_memory(bytes, "gearwheel.bin.stl", false, 7, 3);
    EXPECT_TRUE(same_bits(trickle.xyz, read_path(fixture("gearwheel.bin.stl")).xyz));
    std::string text = slurp(fixture("sphereWithHole.stl"));
    Mesh trickle_text = read_memory(text, "sphereWithHole.stl", false, 7, 5);
    EXPECT_TRUE(same_bits(trickle_text.xyz, read_path(fixture("sphereWithHole.stl")).xyz));
}

TEST(StlReader, RejectsTruncatedBinaryAtEveryByte) {
    for (const char* file : {"cube.bin.stl", "wrongHeader.bin.stl"}) {
        const std::string bytes = slurp(fixture(file));
        ASSERT_EQ(bytes.size(), 684u);
        for (size_t length = 0; length < bytes.size(); ++length) {
            for (bool sized : {true, false}) {
                SCOPED_TRACE(std::string(file) + " length " + std::to_string(length) + (sized ? " sized" : " stream"));
                io::Error e = error_of([&] { read_memory(bytes.substr(0, length), "cut.stl", sized); });
                EXPECT_EQ(e.file(), "cut.stl");
                // "solid" + NULs cut short of any NUL looks like ASCII STL and fails as such.
                bool ascii = std::string_view(file) == "wrongHeader.bin.stl" && length == 5;
                if (ascii) {
                    EXPECT_EQ(e.line(), 1u) << e.what();
                } else if (length < 84) {
                    EXPECT_EQ(e.byte_offset(), length) << e.what();
                } else if (sized) {
                    EXPECT_EQ(e.byte_offset(), 84u);
                    EXPECT_EQ(
                        e.message(),
                        "header promises 12 triangles, file holds " + std::to_string((length - 84) / 50) +
                            ((length - 84) % 50 ? " and " + std::to_string((length - 84) % 50) + " stray bytes" : ""));
                } else {
                    EXPECT_EQ(e.byte_offset(), length) << e.what();
                    EXPECT_NE(e.message().find("file ends inside triangle " + std::to_string((length - 84) / 50 + 1)),
                              std::string::npos)
                        << e.what();
                }
            }
        }
    }
}

// A cut inside a facet or a keyword is an error. A cut between facets is a file whose facets
// are complete but lacks 'endsolid' (issue 21): read, with one warning, and an error under
// --strict. A cut in the name after 'endsolid' (or of the final newline) loses nothing.
TEST(StlReader, TruncatedAsciiFailsUnlessCutBetweenFacetsOrInTheEndsolidName) {
    const std::string text = slurp(fixture("tetrahedron.ascii.stl"));
    const size_t endsolid = text.rfind("endsolid");
    ASSERT_NE(endsolid, std::string::npos);
    size_t between = 0;
    for (size_t length = 0; length < text.size(); ++length) {
        SCOPED_TRACE(length);
        std::string cut = text.substr(0, length);
        std::string_view trimmed = cut;
        while (!trimmed.empty() && std::isspace(static_cast<unsigned char>(trimmed.back()))) trimmed.remove_suffix(1);
        if (length >= endsolid + 8) {
            Mesh mesh = read_memory(cut, "cut.stl", false);
            EXPECT_EQ(mesh.xyz.size(), 9u * 4);
            EXPECT_TRUE(mesh.header.warnings.empty());
        } else if (trimmed.ends_with("endfacet")) {
            ++between;
            size_t facets = 0;
            for (size_t at = cut.find("endfacet"); at != std::string::npos; at = cut.find("endfacet", at + 1)) ++facets;
            Mesh mesh = read_memory(cut, "cut.stl", false);
            EXPECT_EQ(mesh.xyz.size(), 9 * facets);
            EXPECT_EQ(warning_of(mesh, "no 'endsolid' at the end").count, 1u);
            EXPECT_THROW(read_memory(cut, "cut.stl", false, 4096, kWhole, strict_options()), io::Error);
        } else {
            EXPECT_THROW(read_memory(cut, "cut.stl", false), io::Error);
        }
    }
    EXPECT_GT(between, 3u);  // after each of the 4 facets, with and without its line end
}

// Issue 21: facets of more than three vertices are triangulated as PLY and OBJ polygons are
// (the fan when convex, else ear clipping), facets of fewer are skipped, and a file lacking
// 'endsolid' is read: each one counted warning naming the first facet's line; under --strict
// each is an error naming the line.
TEST(StlReader, AsciiLenientFacetsAreCountedWarningsOrStrictErrors) {
    const std::string text =
        "solid lenient\n"
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 2 0 0\n  vertex 2 2 0\n  vertex 0 2 0\n"  // line 2:
                                                                                                             // a square
        " endloop\nendfacet\n"
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 1\n  vertex 1 0 1\n endloop\nendfacet\n"  // line 10: two
                                                                                                 // vertices
        "facet normal 0 0 1\n outer loop\n endloop\nendfacet\n"                                  // line 16: none
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 2\n  vertex 4 0 2\n  vertex 4 4 2\n  vertex 2 1 2\n"  // line 20:
        "  vertex 0 4 2\n endloop\nendfacet\n"  // a concave arrow
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 3\n  vertex 1 0 3\n  vertex 0 1 3\n endloop\nendfacet\n";
    const std::vector<float> expected = {
        0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 0, 0, 2, 2, 0, 0, 2, 0,  // the square's fan
    };
    Mesh whole = read_memory(text, "lenient.stl", true);
    ASSERT_EQ(whole.xyz.size(), 9u * (2 + 3 + 1));
    EXPECT_TRUE(std::equal(expected.begin(), expected.end(), whole.xyz.begin()));
    // The arrow's three triangles keep its orientation (+z) and cover its area (10) once.
    double area = 0;
    for (size_t t = 2; t < 5; ++t) {
        const float* p = &whole.xyz[9 * t];
        const double cross_z = double(p[3] - p[0]) * (p[7] - p[1]) - double(p[4] - p[1]) * (p[6] - p[0]);
        EXPECT_GT(cross_z, 0) << t;
        area += cross_z / 2;
    }
    EXPECT_DOUBLE_EQ(area, 10.0);
    const io::ReaderWarning split = warning_of(whole, "facets with more than 3 vertices split into triangles");
    EXPECT_EQ(split.count, 2u);
    EXPECT_EQ(split.first_line, 2u);
    const io::ReaderWarning skipped = warning_of(whole, "facets with fewer than 3 vertices skipped");
    EXPECT_EQ(skipped.count, 2u);
    EXPECT_EQ(skipped.first_line, 10u);
    const io::ReaderWarning end = warning_of(whole, "no 'endsolid' at the end of the file");
    EXPECT_EQ(end.count, 1u);
    EXPECT_EQ(io::describe_warning("lenient.stl", split),
              "lenient.stl: facets with more than 3 vertices split into triangles (first at line 2)");
    for (size_t capacity : {size_t{1}, size_t{2}, size_t{7}}) {
        SCOPED_TRACE(capacity);
        Mesh part = read_memory(text, "lenient.stl", false, capacity, 5);
        EXPECT_TRUE(same_bits(part.xyz, whole.xyz));
        EXPECT_EQ(part.header.warnings, whole.header.warnings);
    }
    // --strict: the first of them is an error naming its line.
    EXPECT_STREQ(error_of([&] { read_memory(text, "lenient.stl", true, 16, kWhole, strict_options()); }).what(),
                 "lenient.stl:2: facet with 4 vertices (strict mode)");
    const std::string two = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n";
    EXPECT_STREQ(error_of([&] { read_memory(two, "two.stl", true, 16, kWhole, strict_options()); }).what(),
                 "two.stl:2: facet with 2 vertices (strict mode)");
    const std::string open =
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
        "endloop\nendfacet\n";
    EXPECT_STREQ(error_of([&] { read_memory(open, "open.stl", true, 16, kWhole, strict_options()); }).what(),
                 "open.stl:9: expected 'facet' or 'endsolid', found end of file");
    EXPECT_EQ(read_memory(open, "open.stl", true).xyz.size(), 9u);
    // A solid with no facet and no 'endsolid' is a file cut after its first line: an error.
    EXPECT_STREQ(error_of([&] { read_memory("solid t\n", "empty.stl", true); }).what(),
                 "empty.stl:2: expected 'facet' or 'endsolid', found end of file");
}

// Binary STL's attribute word has two colour conventions (VisCAM/SolidView: bit 15 set means
// a colour; Materialise Magics: bit 15 clear means one, red and blue swapped) that no byte of
// the file tells apart, and most writers leave it 0 or fill it with junk (CGAL's sphere.stl
// holds two spaces in every facet): it is not read as colour.
TEST(StlReader, BinaryAttributeBytesAreNotColour) {
    Mesh mesh = read_path(fixture("cgal_sphere_attrbytes.bin.stl"));
    EXPECT_EQ(mesh.xyz.size(), 9u * 320);
    EXPECT_EQ(mesh.header.channels, io::Channels{});
    EXPECT_TRUE(mesh.header.warnings.empty());
    EXPECT_EQ(io::kStlFormat.keep_channels, nullptr);  // writes positions only
    EXPECT_EQ(io::kStlAsciiFormat.keep_channels, nullptr);
}

TEST(StlReader, HeaderCountLyingBothWays) {
    const std::string cube = slurp(fixture("cube.bin.stl"));
    auto with_count = [&](uint32_t n) {
        std::string bytes = cube;
        for (int i = 0; i < 4; ++i) bytes[80 + i] = static_cast<char>(n >> (8 * i));
        return bytes;
    };
    // Size known: checked up front.
    EXPECT_STREQ(error_of([&] { read_memory(with_count(13), "more.stl", true); }).what(),
                 "more.stl: byte 84: header promises 13 triangles, file holds 12");
    EXPECT_STREQ(error_of([&] { read_memory(with_count(11), "fewer.stl", true); }).what(),
                 "fewer.stl: byte 84: header promises 11 triangles, file holds 12");
    // Streams (stdin, gzip): detected where the bytes run out, or where extra ones follow.
    EXPECT_STREQ(error_of([&] { read_memory(with_count(13), "more.stl", false); }).what(),
                 "more.stl: byte 684: file ends inside triangle 13 (header promises 13 triangles)");
    EXPECT_STREQ(error_of([&] { read_memory(with_count(11), "fewer.stl", false); }).what(),
                 "fewer.stl: byte 634: header promises 11 triangles, but more bytes follow");
    // A huge count, as when a text file is mistaken for binary, does not allocate or hang.
    EXPECT_EQ(error_of([&] { read_memory(with_count(0xffffffffu), "huge.stl", true); }).message(),
              "header promises 4294967295 triangles, file holds 12");
}

TEST(StlReader, AsciiMissingEndloopNamesFileAndLine) {
    const std::string text =
        "solid scan\n"
        "  facet normal 0 0 1\n"
        "    outer loop\n"
        "      vertex 0 0 0\n"
        "      vertex 1 0 0\n"
        "      vertex 0 1 0\n"
        "  endfacet\n"  // line 7: endloop missing
        "endsolid scan\n";
    io::Error e = error_of([&] { read_memory(text, "scan.stl", true); });
    EXPECT_STREQ(e.what(), "scan.stl:7: expected 'endloop', found 'endfacet'");
    EXPECT_EQ(e.line(), 7u);
}

TEST(StlReader, AsciiBadInputNamesLine) {
    struct Case {
        const char* text;
        const char* what;
    };
    const Case cases[] = {
        // CRLF lines count once each.
        {"solid x\r\nfacet normal 0 0 1\r\nouter loop\r\nvertex 1 2 zz\r\n",
         "bad.stl:4: expected a number, found 'zz'"},
        {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2 3 4\n", "bad.stl:4: expected 'vertex', found '4'"},
        // Read with a counted warning, except under --strict (as here).
        {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2 3\nvertex 1 2 3\nendloop\n",
         "bad.stl:2: facet with 2 vertices (strict mode)"},
        {"solid x\nfacet normal 0 0 1 7 8\nouter loop\n", "bad.stl:2: expected 'outer', found '7'"},
        {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 +-2 3\n", "bad.stl:4: expected a number, found '+-2'"},
        {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 1 2 1e999z\n",
         "bad.stl:4: expected a number, found '1e999z'"},
        {"solid x\nfacet normal 0 0 1\nouter\n", "bad.stl:4: expected 'loop', found end of file"},
        // Every facet complete but no endsolid: a warning, an error under --strict (as here).
        {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
         "bad.stl:9: expected 'facet' or 'endsolid', found end of file"},
        {"solid x\nendsolid x\ngarbage\n", "bad.stl:3: expected 'solid', found 'garbage'"},
        {"solid x\nvertex 1 2 3\n", "bad.stl:2: expected 'facet' or 'endsolid', found 'vertex'"},
        {"", "bad.stl:1: expected 'solid', found end of file"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        EXPECT_STREQ(error_of([&] {
                         auto source = memory_source(c.text, "bad.stl", true);
                         auto reader = io::kStlAsciiFormat.open_reader(*source, strict_options());
                         drain(*reader, 16);
                     }).what(),
                     c.what);
    }
}

TEST(StlReader, AsciiAcceptsCaseWhitespaceSignsAndSeveralSolids) {
    const std::string good =
        "\xef\xbb\xbf  SOLID Part One\r\n"
        "FACET NORMAL nan -inf garbage\r\n"
        "\tOUTER LOOP\r\n"
        "\t\tVERTEX +1.5e+2 -0 1E-3\r\n"
        "\t\tVertex\t.5\v2.\f-3e-2\r\n"
        "  vertex 1e-50 3.4028235e38 -7\r\n"
        "ENDLOOP\r\nENDFACET\r\n"
        "ENDSOLID Part One\r\n"
        "solid two\n"
        "facet outer loop vertex 1 2 3 vertex 4 5 6 vertex 7 8 9 endloop endfacet\n"
        "endsolid";  // no final newline
    Mesh mesh = read_memory(good, "good.stl", true);
    const std::vector<float> expected = {150, -0.0f, 1e-3f, 0.5f, 2, -0.03f, 0, 3.4028235e38f, -7, 1, 2,
                                         3,   4,     5,     6,    7, 8,      9};
    EXPECT_TRUE(same_bits(mesh.xyz, expected));
    EXPECT_EQ(mesh.header.variant, "ascii");
    EXPECT_EQ(mesh.header.notes.at(0).second, "Part One");
    // A hex-looking token is not a decimal number.
    EXPECT_THROW(read_memory("solid x\nfacet normal\nouter loop\nvertex 0x1 0 0\n", "hex.stl", true), io::Error);
    // Past float's range is infinite, as in OBJ and PLY (1e400 used to be "not a number" here,
    // while 1e39 was read as inf); the commands then count the triangle as non-finite.
    Mesh huge = read_memory(
        "solid x\nfacet normal 0 0 0\nouter loop\nvertex 1e400 -1e999 1e39\nvertex 0 0 0\n"
        "vertex 1 1 1\nendloop\nendfacet\nendsolid\n",
        "huge.stl", true);
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(std::vector<float>(huge.xyz.begin(), huge.xyz.begin() + 3), (std::vector<float>{inf, -inf, inf}));
    EXPECT_THROW(read_memory("solid x\nfacet normal\nouter loop\nvertex 1e400x 0 0\n", "junk.stl", true), io::Error);
}

TEST(StlReader, LineLongerThanTheBufferFailsLoudly) {
    std::string text = "solid x\nfacet normal " + std::string(3 << 20, '1') + "\n";
    io::Error e = error_of([&] { read_memory(text, "long.stl", false); });
    EXPECT_EQ(e.line(), 2u);
    EXPECT_NE(e.message().find("line longer than 1 MiB"), std::string::npos) << e.what();
}

TEST(StlReader, EmptyAndTinyFilesAreErrors) {
    EXPECT_STREQ(error_of([] { read_memory("", "empty.stl", true); }).what(),
                 "empty.stl: byte 0: file ends inside the 84-byte binary STL header (neither binary nor ASCII STL)");
    EXPECT_EQ(error_of([] { read_memory("hello", "hello.stl", false); }).byte_offset(), 5u);
}

TEST_F(StlTest, WriterComputesNormalsAndAHeader) {
    const std::vector<float> tris = {0, 0, 0, 2, 0, 0, 0, 2, 0,   // normal +z
                                     0, 0, 0, 0, 0, 3, 0, 3, 0,   // normal -x
                                     1, 1, 1, 2, 2, 2, 3, 3, 3};  // degenerate: zero normal
    write_path(path("n.stl"), tris, "stl");
    std::string bytes = slurp(path("n.stl"));
    ASSERT_EQ(bytes.size(), 84u + 3 * 50);
    EXPECT_EQ(bytes.substr(0, 11), "meshstream ");
    EXPECT_EQ(bytes.substr(80, 4), std::string("\x03\0\0\0", 4));
    const float normals[3][3] = {{0, 0, 1}, {-1, 0, 0}, {0, 0, 0}};
    for (int t = 0; t < 3; ++t) {
        float n[3];
        std::memcpy(n, bytes.data() + 84 + 50 * t, sizeof n);
        EXPECT_EQ(n[0], normals[t][0]);
        EXPECT_EQ(n[1], normals[t][1]);
        EXPECT_EQ(n[2], normals[t][2]);
        EXPECT_EQ(bytes.substr(84 + 50 * t + 48, 2), std::string("\0\0", 2));
    }
    EXPECT_EQ(read_path(path("n.stl")).header.notes.at(0).second, "meshstream");
}

TEST_F(StlTest, SortMarkerRoundTrips) {
    for (std::string_view to : {"stl", "stl-ascii"}) {
        for (int axis = 0; axis < 3; ++axis) {
            io::WriteOptions options;
            options.sorted_axis = axis;
            write_path(path("s.stl"), kTwoTriangles, to, options);
            EXPECT_EQ(read_path(path("s.stl")).header.sorted_axis, axis) << to;
        }
    }
    EXPECT_NE(slurp(path("s.stl")).find("solid meshstream sorted-axis=z\n"), std::string::npos);
    write_path(path("b.stl"), kTwoTriangles, "stl", [] {
        io::WriteOptions o;
        o.sorted_axis = 1;
        return o;
    }());
    EXPECT_EQ(slurp(path("b.stl")).substr(0, 24), "meshstream sorted-axis=y");
}

TEST_F(StlTest, WriterChecksAnnouncedCountAndLeavesNoFileOnFailure) {
    const std::string out = path("c.stl");
    io::WriteOptions options;
    options.triangle_count = 3;
    io::TriangleChunk two(4);
    float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    two.push(tri);
    two.push(tri);
    {
        io::Output output = io::open_output(out, "stl", options);
        output.write(two);
        EXPECT_STREQ(error_of([&] { output.finish(); }).what(),
                     (out + ": header promises 3 triangles, 2 were written").c_str());
    }
    {
        io::Output output = io::open_output(out, "stl", options);
        output.write(two);
        io::Error e = error_of([&] { output.write(two); });  // 4 > 3, refused before any byte goes out
        EXPECT_NE(e.message().find("more triangles than the 3 announced"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_empty(dir_)) << "an unfinished writer left a file behind";

    options.triangle_count = uint64_t{1} << 32;
    io::Error too_many = error_of([&] { io::open_output(out, "stl", options); });
    EXPECT_NE(too_many.message().find("at most 4294967295 triangles"), std::string::npos) << too_many.what();
    EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(StlTest, ForcedAsciiReaderRejectsBinary) {
    io::Error e = error_of([] { read_path(fixture("cube.bin.stl"), 16, "stl-ascii"); });
    EXPECT_EQ(e.line(), 1u);
    EXPECT_NE(e.message().find("expected 'solid'"), std::string::npos) << e.what();
}

}  // namespace
