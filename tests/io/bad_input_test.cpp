// The bad-input suite of issue 7 at the library level: every reader against empty files,
// random bytes under its extension, truncation at every byte of a small file it wrote itself,
// header counts that lie in both directions, indices out of range, a gzip stream cut inside a
// block, a PLY list count of 2^31, a 100 MB OBJ line, and 64-bit counts and sizes faked
// through a RawInput. Each must end in io::Error naming the file and a position (byte or
// line), within the test's time and a bounded memory, or give a documented sensible result
// (docs/robustness.md). CLI behaviour (exit codes, no output left, signals) is in
// tests/tools/cli_bad_input_test.cpp.
#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/format.hpp"

#include "format_util.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

namespace io = meshstream::io;
namespace fs = std::filesystem;

using meshstream::test::file_extension;
using meshstream::test::readable_extensions;
using meshstream::test::slurp;
using meshstream::test::TempDir;

namespace {

void write_file(const std::string& path, std::string_view bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(out.good()) << path;
}

// Bytes in memory, optionally without a known size (like stdin).
class MemoryInput : public io::RawInput {
public:
    MemoryInput(std::string bytes, bool sized) : bytes_(std::move(bytes)), sized_(sized) {}
    size_t read(void* dst, size_t n) override {
        size_t k = std::min(n, bytes_.size() - pos_);
        std::memcpy(dst, bytes_.data() + pos_, k);
        pos_ += k;
        return k;
    }
    std::optional<uint64_t> size() const override {
        return sized_ ? std::optional<uint64_t>(bytes_.size()) : std::nullopt;
    }

private:
    std::string bytes_;
    bool sized_;
    size_t pos_ = 0;
};

// Reads everything through `format`; returns the triangle count.
uint64_t read_with(const io::Format& format, std::string bytes, const std::string& name, bool sized = true,
                   const io::ReadOptions& options = {}) {
    io::ByteSource source(std::make_unique<MemoryInput>(std::move(bytes), sized), name);
    std::unique_ptr<io::Reader> reader = format.open_reader(source, options);
    io::TriangleChunk chunk(5, reader->header().channels);
    uint64_t n = 0;
    while (reader->next(chunk)) n += chunk.size();
    return n;
}

// Reads a file through detection; returns the triangle count.
uint64_t read_path(const std::string& path, const io::ReadOptions& options = {}) {
    io::Input in = io::open_input(path, {}, options);
    io::TriangleChunk chunk(1024, in.reader->header().channels);
    uint64_t n = 0;
    while (in.reader->next(chunk)) n += chunk.size();
    return n;
}

// The io::Error `f` throws; fails the test when it throws nothing (or something else).
template <class F>
io::Error error_of(F&& f) {
    try {
        f();
    } catch (const io::Error& e) {
        return e;
    }
    ADD_FAILURE() << "no io::Error thrown";
    return io::Error("", "none");
}

bool has_position(const io::Error& e) { return e.byte_offset() != io::Error::kNoOffset || e.line() != 0; }

// An ASCII STL cut right after a facet ('endfacet', then blanks) is a file whose facets are
// complete but which lacks 'endsolid': read, with a warning (issue 21), and an error under
// --strict. Checks that for `cut` and returns true when it is such a cut.
bool check_cut_between_stl_facets(std::string_view format, const std::string& cut, const std::string& name) {
    if (format != "stl-ascii") return false;
    const size_t end = cut.find_last_not_of(" \t\r\n");
    if (end == std::string::npos || end < 7 || cut.compare(end - 7, 8, "endfacet") != 0) return false;
    io::ReadOptions strict;
    strict.strict = true;
    const io::Format& stl = *io::find_format("stl-ascii");
    EXPECT_THROW(read_with(stl, cut, name, true, strict), io::Error) << name;
    EXPECT_LE(read_with(stl, cut, name), 2u) << name;
    return true;
}

// Two triangles sharing an edge, with distinct corners.
io::TriangleChunk two_triangles() {
    io::TriangleChunk c(2);
    c.push({0, 0, 0, 1, 0, 0, 1, 1, 0.5f});
    c.push({0, 0, 0, 1, 1, 0.5f, 0, 1, 0.25f});
    return c;
}

// A file in `format_name` written by meshstream's own writer.
std::string written(const TempDir& dir, const std::string& format_name, const std::string& ext) {
    const std::string path = dir / ("mesh." + ext);
    io::WriteOptions wo;
    wo.triangle_count = 2;
    io::Output out = io::open_output(path, format_name, wo, 6);
    out.write(two_triangles());
    out.finish();
    return slurp(path);
}

// Every format that both writes and reads, except OBJ (no counts: a cut at a line boundary is
// a valid shorter file; TruncatedObjReadsFewerTrianglesOrThrows covers it).
std::vector<const io::Format*> round_trip_formats_with_counts() {
    std::vector<const io::Format*> out;
    for (const io::Format* f : io::formats())
        if (f->open_reader != nullptr && f->open_writer != nullptr && f->name != "obj") out.push_back(f);
    return out;
}

std::string gzip(std::string_view bytes) {
    uLongf n = compressBound(static_cast<uLong>(bytes.size())) + 64;
    std::string out(n, '\0');
    z_stream zs{};
    deflateInit2(&zs, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
    zs.avail_in = static_cast<uInt>(bytes.size());
    zs.next_out = reinterpret_cast<Bytef*>(out.data());
    zs.avail_out = static_cast<uInt>(out.size());
    EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
    out.resize(zs.total_out);
    deflateEnd(&zs);
    return out;
}

const char* const kPlyTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

uint64_t peak_rss_bytes() {
    struct rusage ru {};
    getrusage(RUSAGE_SELF, &ru);
    return uint64_t(ru.ru_maxrss) * 1024;
}

}  // namespace

// ---- empty files, zero triangles, random bytes ----

TEST(BadInput, EmptyFileOfEachFormatIsAnErrorAtByteZeroOrLineOne) {
    TempDir dir;
    std::vector<std::string> exts = readable_extensions();
    ASSERT_GE(exts.size(), 7u);  // stl ply obj mstream drc glb gltf
    exts.push_back("stl.gz");
    for (const std::string& ext : exts) {
        if (ext == "obj") continue;  // below
        const std::string path = dir / ("empty." + ext);
        write_file(path, "");
        io::Error e = error_of([&] { read_path(path); });
        EXPECT_EQ(e.file(), path) << ext;
        EXPECT_TRUE(has_position(e)) << e.what();
    }
    // An empty OBJ is a valid OBJ without statements: zero triangles, no error.
    write_file(dir / "empty.obj", "");
    EXPECT_EQ(read_path(dir / "empty.obj"), 0u);
}

// Writing to a finished writer, or finishing it twice, is a programming error, refused before
// it reaches the file: a binary STL took the chunk after its patched header (a file whose count
// no longer matched), PLY and OBJ dropped it, and finishing twice gave "Bad file descriptor".
TEST(BadInput, WritingAfterFinishOrFinishingTwiceIsRefusedAndTheFileStaysWhole) {
    TempDir dir;
    for (const io::Format* f : io::formats()) {
        if (f->open_writer == nullptr) continue;
        const std::string ext(f->extensions.substr(0, f->extensions.find(' ')));
        const std::string path = dir / ("after-" + std::string(f->name) + "." + ext);
        io::Output out = io::open_output(path, f->name, io::WriteOptions{}, 6);
        out.write(two_triangles());
        out.finish();
        const std::string bytes = slurp(path);
        EXPECT_THROW(out.write(two_triangles()), std::logic_error) << f->name;
        EXPECT_THROW(out.finish(), std::logic_error) << f->name;
        EXPECT_EQ(slurp(path), bytes) << f->name;
        EXPECT_EQ(read_path(path), 2u) << f->name;
    }
}

TEST(BadInput, ZeroTrianglesIsAValidEmptyMesh) {
    TempDir dir;
    std::string stl(80, ' ');
    stl += std::string(4, '\0');  // count 0
    write_file(dir / "zero.stl", stl);
    EXPECT_EQ(read_path(dir / "zero.stl"), 0u);
    write_file(dir / "zero.ply",
               "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
               "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n");
    EXPECT_EQ(read_path(dir / "zero.ply"), 0u);
    write_file(dir / "zero.stl-ascii.stl", "solid empty\nendsolid empty\n");
    EXPECT_EQ(read_path(dir / "zero.stl-ascii.stl"), 0u);
}

TEST(BadInput, RandomBytesUnderEachExtensionAreAnErrorNamingTheFile) {
    TempDir dir;
    std::mt19937 rng(7);
    for (int round = 0; round < 8; ++round) {
        std::string bytes(4096, '\0');
        for (char& c : bytes) c = static_cast<char>(rng());
        for (const std::string& ext : readable_extensions()) {
            const std::string path = dir / ("random" + std::to_string(round) + "." + ext);
            write_file(path, bytes);
            io::Error e = error_of([&] { read_path(path); });
            EXPECT_EQ(e.file(), path);
            EXPECT_TRUE(has_position(e)) << e.what();
        }
    }
}

// Compressed, a stream has no size to test a binary STL's 84 + 50n against: random bytes in a
// .ply.gz used to read as binary STL ("header promises 1428015842 triangles"); the name wins.
TEST(BadInput, RandomBytesInGzipAreJudgedByTheInnerExtension) {
    TempDir dir;
    std::mt19937 rng(11);
    std::string bytes(3000, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    const std::string path = dir / "random.ply.gz";
    write_file(path, gzip(bytes));
    io::Error e = error_of([&] { read_path(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(e.message().find("not a PLY file"), std::string::npos) << e.what();
}

// Random bytes under .obj used to read as an OBJ of unknown statements: zero triangles, exit 0.
TEST(BadInput, Issue7_ObjStatementKeywordMustBeText) {
    io::Error e = error_of([] { read_with(*io::find_format("obj"), "v 0 0 0\n\x9a\x01\xffq 1 2\n", "junk.obj"); });
    EXPECT_EQ(e.line(), 2u);
    EXPECT_NE(e.message().find("not an OBJ statement"), std::string::npos) << e.what();
    // Statement names of the OBJ spec with digits and underscores still pass.
    EXPECT_EQ(read_with(*io::find_format("obj"),
                        "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nc_interp off\ncurv2 1 2\nf 1 2 3\n", "ok.obj"),
              1u);
}

// ---- truncation at every byte of each format's own output ----

TEST(BadInput, TruncationAtEveryByteOfEachBinaryFormatThrowsWithFileName) {
    TempDir dir;
    for (const io::Format* f : round_trip_formats_with_counts()) {
        if (f->side_files != nullptr) continue;  // a .gltf needs its .bin: read by name below
        const std::string format_name(f->name), ext = file_extension(*f);
        const struct {
            const char* format;
            const char* ext;
        } c{format_name.c_str(), ext.c_str()};
        const std::string full = written(dir, c.format, c.ext);
        const io::Format& format = *io::find_format(c.format);
        ASSERT_EQ(read_with(format, full, "full"), 2u) << c.format;
        for (size_t cut = 0; cut < full.size(); ++cut) {
            // ASCII formats may end in whitespace after the last keyword: cutting that is harmless.
            if (std::string_view(c.format).ends_with("ascii") &&
                full.find_first_not_of(" \r\n", cut) == std::string::npos)
                continue;
            // The name after ASCII STL's final "endsolid" is optional.
            if (std::string_view(c.format) == "stl-ascii" && cut >= full.rfind("endsolid") + 8) continue;
            const std::string name = std::string("cut.") + c.ext;
            if (check_cut_between_stl_facets(c.format, full.substr(0, cut), name)) continue;
            io::Error e = error_of([&] { read_with(format, full.substr(0, cut), name); });
            EXPECT_EQ(e.file(), name) << c.format << " cut at " << cut;
            // Draco's decoder does not say where it stopped, so those errors name only the file.
            if (std::string_view(c.format) != "glb" && std::string_view(c.format) != "draco") {
                EXPECT_TRUE(has_position(e)) << c.format << " cut at " << cut << ": " << e.what();
            }
        }
    }
}

// The same cuts named by extension and detected, as the commands read them: a GLB cut to its
// first byte, "g", was read as an empty OBJ, exit 0 (OBJ's first-statement test ran before the
// extension, and "g" is its group statement); so were a PLY cut to "p" and an ASCII STL cut to
// "s". A file named for a format is read by that format's reader and reported as cut.
TEST(BadInput, TruncationAtEveryByteIsAnErrorOfTheFormatTheNameSays) {
    TempDir dir;
    // The error for the first byte alone, per format: a new format adds its line here.
    const std::map<std::string, std::string> at_byte_one = {
        {"stl", "byte 1: file ends inside the 84-byte binary STL header"},
        {"stl-ascii", "byte 1: file ends inside the 84-byte binary STL header"},
        {"ply", ":1: file ends inside the header"},
        {"ply-ascii", ":1: file ends inside the header"},
        {"stream", "byte 1: stream ends inside its 20-byte preamble"},
        {"draco", "byte 1: bitstream ends inside its 5-byte magic 'DRACO'"},
        {"glb", "byte 1: file ends inside the 12-byte GLB header"},
        {"gltf", "byte 1: file ends inside the JSON document (1 array or object still open)"}};
    for (const io::Format* f : round_trip_formats_with_counts()) {
        const std::string format(f->name), ext = file_extension(*f);
        ASSERT_TRUE(at_byte_one.count(format)) << format << " has no expected first-byte error";
        const struct {
            const char* format;
            const char* ext;
            const char* at_byte_one;
        } c{format.c_str(), ext.c_str(), at_byte_one.at(format).c_str()};
        const std::string full = written(dir, c.format, c.ext);
        const std::string path = dir / (std::string("cut.") + c.ext);
        const bool text = std::string_view(c.format).ends_with("ascii") || std::string_view(c.format) == "gltf";
        // Every byte through the headers, then every 7th (each cut is a file opened by name).
        for (size_t cut = 1; cut < full.size(); cut += cut < 128 ? 1 : 7) {
            if (text && full.find_first_not_of(" \r\n", cut) == std::string::npos) continue;  // as above
            if (std::string_view(c.format) == "stl-ascii" && cut >= full.rfind("endsolid") + 8) continue;
            if (check_cut_between_stl_facets(c.format, full.substr(0, cut), path)) continue;
            write_file(path, full.substr(0, cut));
            io::Error e = error_of([&] { read_path(path); });
            EXPECT_EQ(e.file(), path) << c.format << " cut at " << cut;
            EXPECT_TRUE(has_position(e)) << c.format << " cut at " << cut << ": " << e.what();
            if (cut == 1) {
                EXPECT_NE(std::string(e.what()).find(c.at_byte_one), std::string::npos) << c.format << ": " << e.what();
            }
        }
    }
}

// OBJ has no counts: a cut at a line boundary is a valid shorter file. Every cut must still give
// either io::Error or at most the full triangle count.
TEST(BadInput, TruncatedObjReadsFewerTrianglesOrThrows) {
    TempDir dir;
    const std::string full = written(dir, "obj", "obj");
    const io::Format& obj = *io::find_format("obj");
    for (size_t cut = 0; cut < full.size(); ++cut) {
        try {
            EXPECT_LE(read_with(obj, full.substr(0, cut), "cut.obj"), 2u);
        } catch (const io::Error& e) {
            EXPECT_EQ(e.file(), "cut.obj");
            EXPECT_NE(e.line(), 0u) << e.what();
        }
    }
}

// A cut inside the last index of a text file ("f 10 11 1" of "f 10 11 12") is a valid file
// with a wrong last triangle; only the missing line end shows it, so the reader notes that.
TEST(BadInput, TextFileCutInsideItsLastIndexIsNoted) {
    const std::string vertices =
        "0 0 0\n1 0 0\n0 1 0\n5 5 5\n6 5 5\n5 6 5\n5 5 6\n6 6 6\n7 7 7\n10 10 10\n11 10 10\n10 11 10\n";
    std::string obj;
    for (size_t at = 0; at < vertices.size();) {
        const size_t end = vertices.find('\n', at);
        obj += "v " + vertices.substr(at, end + 1 - at);
        at = end + 1;
    }
    obj += "f 1 2 3\nf 10 11 12\n";
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n" +
        vertices + "3 0 1 2\n3 9 10 11\n";
    auto last_line_note = [](const char* format, const std::string& bytes) {
        io::ByteSource source(std::make_unique<MemoryInput>(bytes, true), "cut");
        std::unique_ptr<io::Reader> reader = io::find_format(format)->open_reader(source, {});
        io::TriangleChunk chunk(5, reader->header().channels);
        uint64_t n = 0;
        while (reader->next(chunk)) n += chunk.size();
        EXPECT_EQ(n, 2u) << format;  // the cut file is valid: counting cannot tell
        for (const auto& [key, text] : reader->header().notes)
            if (key == io::kLastLineNote) return text;
        return std::string();
    };
    for (const auto& [format, full] : {std::pair{"obj", obj}, std::pair{"ply-ascii", ply}}) {
        EXPECT_EQ(last_line_note(format, full), "") << format;
        EXPECT_EQ(last_line_note(format, full.substr(0, full.size() - 2)), io::kLastLineText) << format;
        // A final line end is all it takes, with or without CR or blanks.
        EXPECT_EQ(last_line_note(format, full.substr(0, full.size() - 1) + " \r\n"), "") << format;
    }
}

// ---- header counts that lie, indices out of range ----

TEST(BadInput, BinaryStlCountLyingEitherWayNamesByte84) {
    auto stl = [](uint32_t stated, int held) {
        std::string s(80, ' ');
        s.append(reinterpret_cast<const char*>(&stated), 4);
        s.append(size_t(50) * held, '\0');
        return s;
    };
    const io::Format& f = *io::find_format("stl");
    for (auto [stated, held] : {std::pair{5u, 3}, std::pair{1u, 3}, std::pair{0xFFFFFFFFu, 3}}) {
        io::Error e = error_of([&] { read_with(f, stl(stated, held), "lie.stl"); });
        EXPECT_EQ(e.byte_offset(), 84u) << e.what();
        EXPECT_NE(e.message().find("header promises " + std::to_string(stated)), std::string::npos) << e.what();
    }
    // Without a known size (stdin) the short file is found where it ends.
    io::Error e = error_of([&] { read_with(f, stl(5, 3), "lie.stl", false); });
    EXPECT_EQ(e.byte_offset(), 84u + 150u) << e.what();
}

TEST(BadInput, PlyCountsLyingEitherWay) {
    const io::Format& ply = *io::find_format("ply");
    const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    // More faces promised than present: ends early.
    std::string more = kPlyTriangleHeader;
    more.replace(more.find("face 1"), 6, "face 2");
    io::Error e1 = error_of([&] { read_with(ply, more + body, "more.ply"); });
    EXPECT_NE(e1.message().find("file ends early"), std::string::npos) << e1.what();
    EXPECT_EQ(e1.line(), 14u);
    // Fewer faces promised than present: the extra face is data the header does not describe.
    io::Error e2 = error_of([&] { read_with(ply, kPlyTriangleHeader + body + "3 0 1 2\n", "fewer.ply"); });
    EXPECT_EQ(e2.line(), 14u) << e2.what();
    EXPECT_NE(e2.message().find("after the last"), std::string::npos) << e2.what();
    // Trailing blank lines are not data.
    EXPECT_EQ(read_with(ply, kPlyTriangleHeader + body + "\n\r\n  \n", "blank.ply"), 1u);
    // More vertices promised than present: a face line is read as a vertex, then the file ends.
    std::string verts = kPlyTriangleHeader;
    verts.replace(verts.find("vertex 3"), 8, "vertex 4");
    io::Error e3 = error_of([&] { read_with(ply, verts + body, "verts.ply"); });
    EXPECT_TRUE(has_position(e3)) << e3.what();
    // Fewer vertices promised: the third vertex line is read as a face.
    std::string fewer_verts = kPlyTriangleHeader;
    fewer_verts.replace(fewer_verts.find("vertex 3"), 8, "vertex 2");
    io::Error e4 = error_of([&] { read_with(ply, fewer_verts + body, "fv.ply"); });
    EXPECT_TRUE(has_position(e4)) << e4.what();
}

TEST(BadInput, IndicesOutOfRangeNameTheItem) {
    const io::Format& ply = *io::find_format("ply");
    for (const char* face : {"3 0 1 3\n", "3 0 1 -1\n", "3 0 1 2147483647\n"}) {
        io::Error e = error_of(
            [&] { read_with(ply, kPlyTriangleHeader + std::string("0 0 0\n1 0 0\n0 1 0\n") + face, "i.ply"); });
        EXPECT_EQ(e.line(), 13u) << e.what();
        EXPECT_NE(e.message().find("out of range"), std::string::npos) << e.what();
    }
    const io::Format& obj = *io::find_format("obj");
    for (const char* face : {"f 1 2 4\n", "f 1 2 0\n", "f 1 2 -4\n", "f 1 2 99999999999999999999\n"}) {
        io::Error e = error_of([&] { read_with(obj, std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\n") + face, "i.obj"); });
        EXPECT_EQ(e.line(), 4u) << e.what();
        EXPECT_EQ(e.byte_offset(), 24u) << e.what();
    }
}

// NaN and inf are numbers to the readers: they pass through, and the commands' read loop
// (io::TriangleInput) keeps, drops or refuses them (tests/tools/cli_bad_input_test.cpp).
TEST(BadInput, NanAndInfCoordinatesAreReadAsNumbers) {
    const io::Format& ply = *io::find_format("ply");
    EXPECT_EQ(read_with(ply, kPlyTriangleHeader + std::string("nan 0 0\n1 inf 0\n0 1 -inf\n3 0 1 2\n"), "n.ply"), 1u);
    EXPECT_EQ(read_with(*io::find_format("obj"), "v nan 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n", "n.obj"), 1u);
}

// ---- hostile sizes ----

TEST(BadInput, PlyListCountOfTwoToThe31IsAnErrorWithoutAllocatingIt) {
    const io::Format& ply = *io::find_format("ply");
    std::string ascii = kPlyTriangleHeader;
    ascii.replace(ascii.find("list uchar int"), 14, "list uint int");
    io::Error e1 = error_of([&] { read_with(ply, ascii + "0 0 0\n1 0 0\n0 1 0\n2147483648 0 1 2\n", "l.ply"); });
    EXPECT_GE(e1.line(), 13u) << e1.what();  // the face line, or where its indices run out

    std::string binary =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    binary.append(reinterpret_cast<const char*>(v), sizeof v);
    const uint32_t count = 0x80000000u;
    binary.append(reinterpret_cast<const char*>(&count), 4);
    const int32_t idx[3] = {0, 1, 2};
    binary.append(reinterpret_cast<const char*>(idx), sizeof idx);
    const uint64_t rss_before = peak_rss_bytes();
    io::Error e2 = error_of([&] { read_with(ply, binary, "l.ply"); });
    EXPECT_NE(e2.byte_offset(), io::Error::kNoOffset) << e2.what();
    EXPECT_LT(peak_rss_bytes(), rss_before + (uint64_t{256} << 20));
}

TEST(BadInput, PlyVertexCountOfTwoToThe40IsAnErrorNotAnAllocation) {
    std::string header = kPlyTriangleHeader;
    header.replace(header.find("vertex 3"), 8, "vertex 1099511627776");
    io::ReadOptions small;
    small.memory_budget_bytes = uint64_t{1} << 20;  // spills to a (sparse) temp file past 1 MiB
    io::Error e = error_of([&] { read_with(*io::find_format("ply"), header + "0 0 0\n", "huge.ply", true, small); });
    EXPECT_TRUE(has_position(e)) << e.what();
}

TEST(BadInput, GzipStreamCutMidBlockNamesTheCompressedOffset) {
    std::string text = "solid t\n";
    for (int i = 0; i < 3000; ++i)
        text += "facet normal 0 0 1\nouter loop\nvertex " + std::to_string(i) +
                " 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
    text += "endsolid t\n";
    const std::string gz = gzip(text);
    ASSERT_EQ(read_with(*io::find_format("stl-ascii"), gz, "whole.stl.gz"), 3000u);
    for (size_t cut : {size_t{10}, gz.size() / 3, gz.size() / 2, gz.size() - 9, gz.size() - 1}) {
        io::Error e = error_of([&] { read_with(*io::find_format("stl-ascii"), gz.substr(0, cut), "cut.stl.gz"); });
        EXPECT_EQ(e.file(), "cut.stl.gz");
        EXPECT_TRUE(has_position(e)) << e.what();
    }
    // Garbage after a complete member is not a second member.
    io::Error e = error_of([&] { read_with(*io::find_format("stl-ascii"), gz + "garbage!", "tail.stl.gz"); });
    EXPECT_EQ(e.file(), "tail.stl.gz");
}

TEST(BadInput, ObjLineOf100MBFailsAtItsLineInBoundedTimeAndMemory) {
    TempDir dir;
    const std::string path = dir / "long.obj";
    {
        std::ofstream out(path, std::ios::binary);
        out << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# ";
        std::string block(1 << 20, 'x');
        for (int i = 0; i < 100; ++i) out << block;
        out << "\nf 1 2 3\n";
    }
    const auto t0 = std::chrono::steady_clock::now();
    const uint64_t rss_before = peak_rss_bytes();
    io::Error e = error_of([&] { read_path(path); });
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 5u) << e.what();
    EXPECT_NE(e.message().find("longer than"), std::string::npos) << e.what();
    EXPECT_LT(peak_rss_bytes(), rss_before + (uint64_t{64} << 20));
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30));
}

// ---- 64-bit counts and sizes through a generated RawInput ----

// An ASCII PLY whose header promises `faces` faces over 3 vertices and that generates
// "3 0 1 2" lines for ever (the stream is never materialised).
class EndlessPly : public io::RawInput {
public:
    explicit EndlessPly(uint64_t faces) {
        head_ = std::string(kPlyTriangleHeader);
        head_.replace(head_.find("face 1"), 6, "face " + std::to_string(faces));
        head_ += "0 0 0\n1 0 0\n0 1 0\n";
    }
    size_t read(void* dst, size_t n) override {
        char* out = static_cast<char*>(dst);
        for (size_t i = 0; i < n; ++i, ++pos_)
            out[i] = pos_ < head_.size() ? head_[pos_] : "3 0 1 2\n"[(pos_ - head_.size()) % 8];
        return n;
    }

private:
    std::string head_;
    uint64_t pos_ = 0;
};

TEST(BadInput, PlyFaceCountOver2To32IsKeptIn64Bits) {
    const uint64_t faces = (uint64_t{1} << 32) + 5;
    io::ByteSource source(std::make_unique<EndlessPly>(faces), "big.ply");
    std::unique_ptr<io::Reader> reader = io::find_format("ply")->open_reader(source, {});
    // Faces are polygons, so the triangle count is known only once read; the face count is
    // reported as stated.
    const auto& notes = reader->header().notes;
    auto it = std::find_if(notes.begin(), notes.end(), [](const auto& n) { return n.first == "faces"; });
    ASSERT_NE(it, notes.end());
    EXPECT_EQ(it->second, std::to_string(faces));
    io::TriangleChunk chunk(4096);
    ASSERT_TRUE(reader->next(chunk));
    EXPECT_EQ(chunk.size(), 4096u);
}
