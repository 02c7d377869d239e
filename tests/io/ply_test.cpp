// PLY reader and writer: corpus fixtures with the MANIFEST's counts, concave polygons covered
// once, chunk boundaries, round trips through every encoding (big endian made by a
// byte-swapping helper, or encoded by this test from the ascii output), every channel value for
// value (normals, colours, texture coordinates, named vertex and face scalars), bounded memory
// giving the same bytes as the in-memory path, the lenient cases with their counted warnings,
// and bad input (counts that disagree with the data too) with file + element + offset.
#include "io/ply.hpp"

#include "indexed_test_util.hpp"
#include "io/text_number.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>

using namespace meshstream;
using test::fixture;
using test::read_error;
using test::read_soup;
using test::TempDir;

namespace {

// Rewrites a meshstream binary_little_endian PLY (float xyz [+ uchar rgb], `list uchar int`
// triangles) as binary_big_endian.
std::string to_big_endian(const std::string& le) {
    size_t end = le.find("end_header\n") + 11;
    std::string header = le.substr(0, end);
    size_t at = header.find("binary_little_endian");
    header.replace(at, 20, "binary_big_endian");
    auto count_of = [&](const std::string& element) {
        size_t p = header.find("element " + element + " ") + 9 + element.size();
        return std::stoull(header.substr(p));
    };
    bool color = header.find("property uchar red") != std::string::npos;
    uint64_t vertices = count_of("vertex"), faces = count_of("face");
    std::string body = le.substr(end);
    size_t p = 0;
    auto swap4 = [&](size_t at4) { std::swap(body[at4], body[at4 + 3]), std::swap(body[at4 + 1], body[at4 + 2]); };
    for (uint64_t v = 0; v < vertices; ++v, p += color ? 15 : 12)
        for (int a = 0; a < 3; ++a) swap4(p + 4 * a);
    for (uint64_t f = 0; f < faces; ++f, p += 13)
        for (int k = 0; k < 3; ++k) swap4(p + 1 + 4 * k);
    EXPECT_EQ(p, body.size());
    return header + body;
}

// Every channel of a file as read: per corner (3 a triangle) and per triangle.
struct Full {
    io::MeshHeader header;  // as it is at the end (with the reader's warnings)
    std::vector<float> xyz, normals, rgba;
    std::vector<std::vector<float>> uv;         // per set: 6 a triangle
    std::vector<std::vector<double>> vscalars;  // per channel: 3 a triangle
    std::vector<std::vector<double>> fscalars;  // per channel: 1 a triangle
    std::vector<uint64_t> ids;
    size_t triangles() const { return xyz.size() / 9; }
};

// Reads `path` with chunks of `capacity` that have `channels` (default: all the file has).
Full read_full(const std::string& path, size_t capacity = io::TriangleChunk::kDefaultCapacity,
               const io::ReadOptions& options = {}, std::optional<io::Channels> channels = std::nullopt) {
    io::Input in = io::open_input(path, {}, options);
    const io::Channels ch = channels.value_or(in.reader->header().channels);
    io::TriangleChunk chunk(capacity, ch);
    Full f;
    f.uv.resize(size_t(ch.uv_sets));
    f.vscalars.resize(ch.vertex_scalars.size());
    f.fscalars.resize(ch.face_scalars.size());
    while (in.reader->next(chunk)) {
        f.xyz.insert(f.xyz.end(), chunk.xyz().begin(), chunk.xyz().end());
        f.normals.insert(f.normals.end(), chunk.normals().begin(), chunk.normals().end());
        f.rgba.insert(f.rgba.end(), chunk.colors().begin(), chunk.colors().end());
        f.ids.insert(f.ids.end(), chunk.vertex_ids().begin(), chunk.vertex_ids().end());
        for (size_t t = 0; t < chunk.size(); ++t) {
            for (int s = 0; s < ch.uv_sets; ++s)
                f.uv[size_t(s)].insert(f.uv[size_t(s)].end(), chunk.uv_at(t, s), chunk.uv_at(t, s) + 6);
            for (size_t c = 0; c < ch.vertex_scalars.size(); ++c)
                f.vscalars[c].insert(f.vscalars[c].end(), chunk.vertex_scalar_at(t, c),
                                     chunk.vertex_scalar_at(t, c) + 3);
            for (size_t c = 0; c < ch.face_scalars.size(); ++c) f.fscalars[c].push_back(*chunk.face_scalar_at(t, c));
        }
    }
    f.header = in.reader->header();
    return f;
}

// The same triangles with the same values in every channel, bit for bit (and the same channel
// descriptions); vertex ids too when `ids`.
void expect_same(const Full& a, const Full& b, bool ids = true) {
    auto same_bits = [](const std::vector<float>& x, const std::vector<float>& y) {
        return x.size() == y.size() && (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0);
    };
    EXPECT_TRUE(same_bits(a.xyz, b.xyz));
    EXPECT_TRUE(same_bits(a.normals, b.normals));
    EXPECT_EQ(a.rgba, b.rgba);
    ASSERT_EQ(a.uv.size(), b.uv.size());
    for (size_t s = 0; s < a.uv.size(); ++s) EXPECT_TRUE(same_bits(a.uv[s], b.uv[s])) << "uv set " << s;
    EXPECT_EQ(a.vscalars, b.vscalars);
    EXPECT_EQ(a.fscalars, b.fscalars);
    EXPECT_EQ(a.header.channels.color, b.header.channels.color);
    EXPECT_EQ(a.header.channels.vertex_scalars, b.header.channels.vertex_scalars);
    EXPECT_EQ(a.header.channels.face_scalars, b.header.channels.face_scalars);
    if (ids) {
        EXPECT_EQ(a.ids, b.ids);
    }
}

// Converts `from` to `to` keeping every channel the output format holds, as `convert` does.
void convert_all(const std::string& from, const std::string& to, std::string_view to_format = {},
                 uint64_t budget = uint64_t{256} << 20, size_t capacity = io::TriangleChunk::kDefaultCapacity) {
    io::ReadOptions ro;
    ro.memory_budget_bytes = budget;
    io::Input in = io::open_input(from, {}, ro);
    io::WriteOptions wo;
    wo.memory_budget_bytes = budget;
    wo.channels = io::writable_channels(io::output_format(to, to_format), in.reader->header().channels, wo);
    io::Output out = io::open_output(to, to_format, wo);
    io::TriangleChunk chunk(capacity, wo.channels);
    while (in.reader->next(chunk)) out.write(chunk);
    out.finish();
}

// Re-encodes an ascii PLY as binary (big or little endian) with the test's own encoder, so
// that binary reading is checked against ascii, and meshstream's binary writer against it.
std::string ascii_to_binary(const std::string& ascii, bool big_endian) {
    const size_t end = ascii.find("end_header\n") + 11;
    std::string header = ascii.substr(0, end);
    header.replace(header.find("format ascii 1.0"), 16,
                   big_endian ? "format binary_big_endian 1.0" : "format binary_little_endian 1.0");
    struct Prop {
        std::string type, count_type;
    };
    std::vector<std::pair<uint64_t, std::vector<Prop>>> elements;
    std::istringstream lines(header);
    for (std::string line; std::getline(lines, line);) {
        std::istringstream words(line);
        std::string key, a, b, c;
        words >> key >> a >> b >> c;
        if (key == "element") elements.push_back({std::stoull(b), {}});
        if (key == "property") elements.back().second.push_back(a == "list" ? Prop{c, b} : Prop{a, ""});
    }
    std::istringstream tokens(ascii.substr(end));
    std::string out = header;
    auto put = [&](const std::string& type, const std::string& token) {
        char bytes[8];
        size_t n = 0;
        if (type == "float") {
            float v = 0;
            std::from_chars(token.data(), token.data() + token.size(), v);
            std::memcpy(bytes, &v, n = 4);
        } else if (type == "double") {
            double v = 0;
            std::from_chars(token.data(), token.data() + token.size(), v);
            std::memcpy(bytes, &v, n = 8);
        } else {
            const int64_t v = std::stoll(token);
            n = type == "char" || type == "uchar" ? 1 : type == "short" || type == "ushort" ? 2 : 4;
            std::memcpy(bytes, &v, n);  // little-endian host: the low bytes
        }
        if (big_endian) std::reverse(bytes, bytes + n);
        out.append(bytes, n);
    };
    std::string token;
    for (const auto& [count, props] : elements)
        for (uint64_t i = 0; i < count; ++i)
            for (const Prop& p : props) {
                tokens >> token;
                if (p.count_type.empty()) {
                    put(p.type, token);
                    continue;
                }
                put(p.count_type, token);
                for (int k = std::stoi(token); k > 0; --k) {
                    std::string item;
                    tokens >> item;
                    put(p.type, item);
                }
            }
    EXPECT_FALSE(tokens >> token) << "tokens left over: " << token;
    return out;
}

// The reader's warning that starts with `text`; count 0 when there is none.
io::ReaderWarning warning_of(const io::MeshHeader& header, std::string_view text) {
    for (const io::ReaderWarning& w : header.warnings)
        if (w.text.starts_with(text)) return w;
    return {std::string(text), 0};
}

const char* const kChannelFixtures[] = {"ply/elephant_normals.binary_be.ply", "ply/cube_uv.ply",
                                        "ply/cgal_colored_tetra.ply",         "ply/float-color.ply",
                                        "ply/cactus_vcolor.binary_le.ply",    "ply/cactus_vcolor.binary_le.ply.gz"};

}  // namespace

TEST(PlyReader, ReadsCorpusFixturesWithManifestCounts) {
    struct Case {
        const char* file;
        size_t triangles;
        uint64_t vertices;
        const char* variant;
    };
    const Case cases[] = {
        {"ply/cactus_vcolor.binary_le.ply", 1236, 620, "binary_little_endian"},
        {"ply/cactus_vcolor.binary_le.ply.gz", 1236, 620, "binary_little_endian"},
        {"ply/cgal_colored_tetra.ply", 4, 4, "ascii"},
        {"ply/cgal_sphere.ply", 320, 162, "ascii"},
        {"ply/cube.ply", 12, 8, "ascii"},
        {"ply/cube.ascii.ply.gz", 12, 8, "ascii"},
        {"ply/cube_binary.ply", 12, 8, "binary_little_endian"},
        {"ply/cube_quads.binary_be.ply", 12, 8, "binary_big_endian"},
        {"ply/cube_uv.ply", 12, 24, "ascii"},
        {"ply/elephant_normals.binary_be.ply", 5558, 2775, "binary_big_endian"},
        {"ply/elephant_normals.binary_be.ply.gz", 5558, 2775, "binary_big_endian"},
        {"ply/float-color.ply", 1, 3, "ascii"},
        {"ply/mpi_ngons.ascii.ply", 180, 90, "ascii"},
        {"ply/points.ply", 0, 4, "ascii"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        test::Soup s = read_soup(fixture(c.file));
        EXPECT_EQ(s.triangles(), c.triangles);
        EXPECT_EQ(s.header.variant, c.variant);
        ASSERT_TRUE(s.header.vertex_count.has_value());
        EXPECT_EQ(*s.header.vertex_count, c.vertices);
        ASSERT_EQ(s.ids.size(), 3 * s.triangles());
        for (uint64_t id : s.ids) EXPECT_LT(id, c.vertices);
    }
}

TEST(PlyReader, ConvexPolygonsAreFans) {
    // cube.ply's first face is the square "4 0 1 2 3": triangles (0 1 2) and (0 2 3).
    test::Soup s = read_soup(fixture("ply/cube.ply"));
    ASSERT_GE(s.ids.size(), 6u);
    EXPECT_EQ((std::vector<uint64_t>(s.ids.begin(), s.ids.begin() + 6)), (std::vector<uint64_t>{0, 1, 2, 0, 2, 3}));
}

// An E (12 corners) and a star (10) on a tilted plane, in ascii with a colour per vertex: each
// is covered once, whatever the chunk size, and every corner has its vertex's colour.
TEST(PlyReader, ConcavePolygonsAreCoveredOnceWithTheirColours) {
    const std::vector<test::PlacedPolygon> polygons = {test::place_polygon(test::e_shape()),
                                                       test::place_polygon(test::star_shape(5, 0.4))};
    std::string vertices, faces;
    uint64_t first = 0;
    for (const test::PlacedPolygon& p : polygons) {
        io::append_number(faces, p.corners());
        for (size_t k = 0; k < p.corners(); ++k) {
            for (int a = 0; a < 3; ++a) {
                io::append_number(vertices, p.xyz[3 * k + a]);
                vertices += ' ';
            }
            vertices += std::to_string(first + k) + " " + std::to_string(255 - (first + k)) + " 7\n";
            faces += ' ';
            io::append_number(faces, first + k);
        }
        faces += '\n';
        first += p.corners();
    }
    TempDir dir;
    test::spit(dir / "p.ply",
               "ply\nformat ascii 1.0\nelement vertex 22\nproperty float x\nproperty float y\n"
               "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
               "element face 2\nproperty list uchar int vertex_indices\nend_header\n" +
                   vertices + faces);
    for (size_t capacity : {size_t{1}, size_t{7}, io::TriangleChunk::kDefaultCapacity}) {
        SCOPED_TRACE(capacity);
        test::Soup s = read_soup(dir / "p.ply", capacity);
        test::expect_polygons(s, polygons);
        ASSERT_EQ(s.triangles(), 10u + 8);
        ASSERT_EQ(s.rgb.size(), 3 * s.ids.size());
        for (size_t c = 0; c < s.ids.size(); ++c)
            EXPECT_EQ((std::vector<uint8_t>(s.rgb.begin() + 3 * c, s.rgb.begin() + 3 * c + 3)),
                      (std::vector<uint8_t>{uint8_t(s.ids[c]), uint8_t(255 - s.ids[c]), 7}));
    }
}

TEST(PlyReader, ChunkCapacitiesGiveIdenticalTriangles) {
    for (const char* file : {"ply/mpi_ngons.ascii.ply", "ply/cube_quads.binary_be.ply",
                             "ply/cactus_vcolor.binary_le.ply", "ply/elephant_normals.binary_be.ply.gz"}) {
        SCOPED_TRACE(file);
        test::Soup whole = read_soup(fixture(file));
        for (size_t capacity : {size_t{1}, size_t{7}}) {
            test::Soup part = read_soup(fixture(file), capacity);
            EXPECT_EQ(part.xyz, whole.xyz);
            EXPECT_EQ(part.ids, whole.ids);
            EXPECT_EQ(part.rgb, whole.rgb);
        }
    }
}

TEST(PlyReader, FillsColourFromUcharAndFloatChannels) {
    test::Soup cactus = read_soup(fixture("ply/cactus_vcolor.binary_le.ply"));
    EXPECT_TRUE(cactus.header.channels.color);
    ASSERT_EQ(cactus.rgb.size(), 9 * cactus.triangles());
    bool any_nonzero = false;
    for (uint8_t c : cactus.rgb) any_nonzero |= c != 0;
    EXPECT_TRUE(any_nonzero);

    TempDir dir;  // float colours in [0, 1] scale to 0..255
    test::spit(
        dir / "c.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "property float red\nproperty float green\nproperty float blue\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n0 0 0 1 0 0.5\n1 0 0 0 1 0\n0 1 0 0 0 1\n3 0 1 2\n");
    test::Soup s = read_soup(dir / "c.ply");
    EXPECT_EQ(s.rgb, (std::vector<uint8_t>{255, 0, 128, 0, 255, 0, 0, 0, 255}));
}

TEST(PlyReader, DoubleCoordinatesRoundedToFloatAreNoted) {
    // Chunks hold floats: double coordinates are rounded, which at UTM-like coordinates moves
    // them by up to 0.125 m. The header note says by how much (the commands warn with it); when
    // every double is a float exactly, by 0.
    TempDir dir;
    auto note = [](const test::Soup& s) {
        for (const auto& [k, v] : s.header.notes)
            if (k == io::kPrecisionNote) return v;
        return std::string("<none>");
    };
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
        "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    test::spit(dir / "utm.ply", header + "500000 4000000.12 100\n500001 4000000 100\n500000 4000001 100.5\n3 0 1 2\n");
    test::Soup utm = read_soup(dir / "utm.ply");
    EXPECT_EQ(utm.xyz[1], 4000000.0f);
    EXPECT_EQ(note(utm), "double, rounded to float: moved by up to 0.12 (at 4000000.12)");
    EXPECT_EQ(utm.header.coordinate_rounding, double(0.12f));
    test::spit(dir / "exact.ply", header + "0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n");
    const test::Soup exact = read_soup(dir / "exact.ply");
    EXPECT_EQ(note(exact), "double, rounded to float: moved by up to 0");
    EXPECT_EQ(exact.header.coordinate_rounding, 0.0);
    test::spit(dir / "float.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
               "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
               "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    const test::Soup single = read_soup(dir / "float.ply");
    EXPECT_EQ(note(single), "<none>");
    EXPECT_FALSE(single.header.coordinate_rounding.has_value());
}

TEST(PlyReader, AnyCoordinateTypeAndElementsAroundVertexAndFace) {
    TempDir dir;
    // An element before the vertices, int16 coordinates, a uint index list with a uint16
    // count, a face property after the list, and a list-bearing element between and after.
    test::spit(dir / "t.ply",
               "ply\r\nformat ascii 1.0 \r\ncomment made by hand\r\nobj_info nothing\r\n"
               "element material 1\r\nproperty uchar ambient\r\nproperty list uchar float weights\r\n"
               "element vertex 4\r\nproperty int16 x\r\nproperty short y\r\nproperty float64 z\r\nproperty uchar "
               "confidence\r\n"
               "element tag 2\r\nproperty list int int values\r\n"
               "element face 2\r\nproperty list ushort uint vertex_index\r\nproperty int flags\r\n"
               "element edge 1\r\nproperty int a\r\nproperty int b\r\n"
               "end_header\r\n"
               "7 2 0.5 0.25\r\n"
               "0 0 0 1\r\n1 0 0 1\r\n1 1 -2.5 1\r\n0 1 1e3 1\r\n"
               "3 1 2 3\r\n0\r\n"
               "3 0 1 2 9\r\n3 0 2 3 9\r\n"
               "0 1\r\n");
    test::Soup s = read_soup(dir / "t.ply");
    ASSERT_EQ(s.triangles(), 2u);
    EXPECT_EQ(s.xyz, (std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, -2.5f, 0, 0, 0, 1, 1, -2.5f, 0, 1, 1000}));
}

TEST(PlyReader, TriangleStripsWithRestartsKeepOneOrientation) {
    // A 3 x 2 grid of vertices as one strip (4 triangles), then -1 and a second strip that
    // repeats an index to stitch (a zero-area joint, dropped), in ASCII and binary big-endian.
    const std::string header_start = "ply\nformat ";
    const std::string header_end =
        " 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
        "element tristrips 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float v[6][3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}};
    const int32_t strip[] = {3, 0, 4, 1, 5, 2, -1, 0, 1, 1, 3};  // second: (0 1 1) joint, (1 1 3) joint
    TempDir dir;
    test::spit(dir / "a.ply", header_start + "ascii" + header_end + "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n" +
                                  "11 3 0 4 1 5 2 -1 0 1 1 3\n");
    std::string bin = header_start + "binary_big_endian" + header_end;
    auto put_be = [&](uint32_t x) {
        for (int s = 24; s >= 0; s -= 8) bin.push_back(static_cast<char>(x >> s));
    };
    for (const auto& p : v)
        for (float c : p) put_be(std::bit_cast<uint32_t>(c));
    bin.push_back(static_cast<char>(std::size(strip)));
    for (int32_t i : strip) put_be(static_cast<uint32_t>(i));
    test::spit(dir / "b.ply", bin);
    for (const char* file : {"a.ply", "b.ply"}) {
        SCOPED_TRACE(file);
        for (size_t capacity : {size_t{1}, size_t{3}, io::TriangleChunk::kDefaultCapacity}) {
            test::Soup s = read_soup(dir / file, capacity);
            ASSERT_EQ(s.triangles(), 4u);  // the second strip holds only joints
            EXPECT_EQ(s.ids, (std::vector<uint64_t>{3, 0, 4, 4, 0, 1, 4, 1, 5, 5, 1, 2}));
            for (size_t t = 0; t < 4; ++t) {  // all facing +z, as the first
                const float* a = &s.xyz[9 * t];
                const float nz = (a[3] - a[0]) * (a[7] - a[1]) - (a[4] - a[1]) * (a[6] - a[0]);
                EXPECT_GT(nz, 0) << t;
            }
            EXPECT_NE(std::find(s.header.notes.begin(), s.header.notes.end(),
                                std::pair<std::string, std::string>{"tristrips", "1"}),
                      s.header.notes.end());
        }
    }
}

TEST(PlyReader, ReadsSortedAxisComment) {
    TempDir dir;
    test::spit(dir / "s.ply",
               "ply\nformat ascii 1.0\ncomment meshstream sorted-axis=y\nelement vertex 3\nproperty float x\n"
               "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n"
               "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    test::Soup s = read_soup(dir / "s.ply");
    ASSERT_TRUE(s.header.sorted_axis.has_value());
    EXPECT_EQ(*s.header.sorted_axis, 1);
}

TEST(PlyRoundTrip, StlThroughEveryPlyEncodingAndObjBackToStlIsExact) {
    for (const char* file : {"gearwheel.bin.stl", "tetrahedronMinusZero.bin.stl", "sphereWithHole.stl"}) {
        SCOPED_TRACE(file);
        TempDir dir;
        test::Soup original = read_soup(fixture(file));
        ASSERT_GT(original.triangles(), 0u);
        test::convert(fixture(file), dir / "le.ply");
        test::convert(dir / "le.ply", dir / "ascii.ply.gz", "ply-ascii");
        test::spit(dir / "be.ply", to_big_endian(test::slurp(dir / "le.ply")));
        for (const char* ply : {"le.ply", "ascii.ply.gz", "be.ply"}) {
            SCOPED_TRACE(ply);
            std::string obj = dir / (std::string(ply) + ".obj");
            test::convert(dir / ply, obj);
            test::convert(obj, dir / "back.stl.gz");
            test::convert(obj, dir / "back.stl");
            for (const char* back : {"back.stl", "back.stl.gz"}) {
                test::Soup s = read_soup(dir / back);
                ASSERT_EQ(s.xyz.size(), original.xyz.size());
                for (size_t i = 0; i < s.xyz.size(); ++i) ASSERT_EQ(s.xyz[i], original.xyz[i]) << "float " << i;
            }
        }
        // Binary and ascii PLY decode to the same soup, and ids survive PLY -> PLY.
        test::Soup le = read_soup(dir / "le.ply"), ascii = read_soup(dir / "ascii.ply.gz"),
                   be = read_soup(dir / "be.ply");
        EXPECT_EQ(le.xyz, ascii.xyz);
        EXPECT_EQ(le.xyz, be.xyz);
        EXPECT_EQ(le.ids, ascii.ids);
    }
}

TEST(PlyWriter, ChunkCapacitiesGiveIdenticalFiles) {
    TempDir dir;
    for (const char* to : {"ply", "ply-ascii", "obj"}) {
        SCOPED_TRACE(to);
        test::convert(fixture("gearwheel.bin.stl"), dir / "whole", to);
        test::convert(fixture("ply/mpi_ngons.ascii.ply"), dir / "whole2", to);
        for (size_t capacity : {size_t{1}, size_t{7}}) {
            test::convert(fixture("gearwheel.bin.stl"), dir / "part", to, uint64_t{256} << 20, capacity);
            EXPECT_TRUE(test::slurp(dir / "part") == test::slurp(dir / "whole"));
            test::convert(fixture("ply/mpi_ngons.ascii.ply"), dir / "part2", to, uint64_t{256} << 20, capacity);
            EXPECT_TRUE(test::slurp(dir / "part2") == test::slurp(dir / "whole2"));
        }
    }
}

TEST(PlyWriter, WeldsExactPositionsWithMinusZeroEqualToPlusZero) {
    TempDir dir;
    test::convert(fixture("tetrahedronMinusZero.bin.stl"), dir / "t.ply");
    test::Soup s = read_soup(dir / "t.ply");
    EXPECT_EQ(*s.header.vertex_count, 4u);
    EXPECT_EQ(s.triangles(), 4u);
}

TEST(PlyWriter, KeepsTheVertexStructureOfIndexedInput) {
    TempDir dir;
    // cube_uv.ply has 24 corner vertices at 8 positions: the vertex ids keep them apart,
    // while the same triangles as STL (no ids) weld to 8.
    test::convert(fixture("ply/cube_uv.ply"), dir / "ids.ply");
    EXPECT_EQ(*read_soup(dir / "ids.ply").header.vertex_count, 24u);
    test::convert(fixture("ply/cube_uv.ply"), dir / "soup.stl");
    test::convert(dir / "soup.stl", dir / "welded.ply");
    EXPECT_EQ(*read_soup(dir / "welded.ply").header.vertex_count, 8u);
}

TEST(PlyWriter, WritesHeaderCommentsAndColour) {
    TempDir dir;
    io::ReadOptions ro;
    io::Input in = io::open_input(fixture("ply/cactus_vcolor.binary_le.ply"), {}, ro);
    io::WriteOptions wo;
    wo.sorted_axis = 2;
    wo.comment = "first\nsecond";
    wo.channels = in.reader->header().channels;
    io::Output out = io::open_output(dir / "c.ply", "ply-ascii", wo);
    io::TriangleChunk chunk(100, in.reader->header().channels);
    while (in.reader->next(chunk)) out.write(chunk);
    out.finish();
    std::string text = test::slurp(dir / "c.ply");
    EXPECT_EQ(text.rfind("ply\nformat ascii 1.0\ncomment generated by meshstream\n"
                         "comment meshstream sorted-axis=z\ncomment first\ncomment second\n",
                         0),
              0u);
    EXPECT_NE(text.find("property uchar red\nproperty uchar green\nproperty uchar blue\n"), std::string::npos);
    test::Soup original = read_soup(fixture("ply/cactus_vcolor.binary_le.ply"));
    test::Soup copy = read_soup(dir / "c.ply");
    EXPECT_EQ(copy.xyz, original.xyz);
    EXPECT_EQ(copy.rgb, original.rgb);
    EXPECT_EQ(copy.ids, original.ids);  // all 620 vertices are used, so numbering is kept
    ASSERT_TRUE(copy.header.sorted_axis.has_value());
    EXPECT_EQ(*copy.header.sorted_axis, 2);
}

// A few hundred thousand triangles with a 1 MiB budget: the welder takes the external-sort
// path and the reader's vertex table spills (ascii/big endian) or maps the file (little
// endian), yet every output byte equals the in-memory run's.
TEST(PlyMemory, TinyBudgetGivesTheSameOutputAsInMemory) {
    TempDir dir;
    std::vector<float> grid = test::grid_soup(350);  // 243602 triangles, 122500 vertices
    test::write_soup(dir / "grid.stl", grid, {}, {}, 16384);
    const uint64_t tiny = uint64_t{1} << 20;
    test::convert(dir / "grid.stl", dir / "mem.ply");
    test::convert(dir / "grid.stl", dir / "tiny.ply", {}, tiny);
    EXPECT_TRUE(test::slurp(dir / "mem.ply") == test::slurp(dir / "tiny.ply"));

    // PLY -> ascii PLY in 1 MiB: the reader maps the file's vertex block (dropping pages past
    // the budget) and the welder sorts by vertex id; reading the ascii file back in 1 MiB
    // spills its table to a mapped temp file.
    test::convert(dir / "mem.ply", dir / "tiny.ascii.ply", "ply-ascii", tiny);
    io::ReadOptions small;
    small.memory_budget_bytes = tiny;
    for (const char* file : {"mem.ply", "tiny.ascii.ply"}) {
        SCOPED_TRACE(file);
        test::Soup s = read_soup(dir / file, io::TriangleChunk::kDefaultCapacity, small);
        EXPECT_EQ(*s.header.vertex_count, 122500u);
        ASSERT_EQ(s.xyz.size(), grid.size());
        EXPECT_TRUE(s.xyz == grid);
    }
}

TEST(PlyReader, TruncationAtEveryByteThrows) {
    TempDir dir;
    std::string full = test::slurp(fixture("ply/cube_binary.ply"));
    for (size_t n = 0; n < full.size(); ++n) {
        test::spit(dir / "cut.ply", full.substr(0, n));
        EXPECT_THROW(read_soup(dir / "cut.ply", 7, {}, "ply"), io::Error) << "cut at " << n;
    }
    test::spit(dir / "cut.ply", full);
    EXPECT_EQ(read_soup(dir / "cut.ply").triangles(), 12u);
}

TEST(PlyReader, BadInputNamesFileElementItemAndOffset) {
    TempDir dir;
    const std::string head =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    struct Case {
        std::string bytes, message;
        uint64_t offset, line;
    };
    const Case cases[] = {
        {head + "3 0 1 2\n3 0 1 3\n", "element 'face' item 1: vertex index 3 out of range (3 vertices)",
         head.size() + 14, 14},
        {head + "3 0 -1 2\n", "element 'face' item 0: vertex index -1 out of range", head.size() + 4, 13},
        {head + "3 0 1 2\n", "element 'face' item 1: file ends early (header promises 2 face items)", head.size() + 8,
         14},
        {head + "3 0 1 x\n", "element 'face' item 0: expected a number, found 'x'", head.size() + 6, 13},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.message);
        test::spit(dir / "bad.ply", c.bytes);
        io::Error e = read_error(dir / "bad.ply");
        EXPECT_EQ(e.file(), dir / "bad.ply");
        EXPECT_NE(e.message().find(c.message), std::string::npos) << e.what();
        EXPECT_EQ(e.byte_offset(), c.offset) << e.what();
        EXPECT_EQ(e.line(), c.line) << e.what();
    }
    // Binary: a header promising more vertices than the file holds, and a negative index.
    std::string bin =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    test::spit(dir / "short.ply", bin + std::string(12, '\0'));
    io::Error e = read_error(dir / "short.ply");
    EXPECT_NE(e.message().find("element 'vertex' item 1: file ends early (header promises 2 vertex items)"),
              std::string::npos)
        << e.what();
    std::string body(24, '\0');
    body += '\3';
    const int32_t idx[3] = {0, 1, -5};
    body.append(reinterpret_cast<const char*>(idx), 12);
    test::spit(dir / "neg.ply", bin + body);
    e = read_error(dir / "neg.ply");
    EXPECT_NE(e.message().find("element 'face' item 0: vertex index -5 out of range (2 vertices)"), std::string::npos)
        << e.what();
    EXPECT_EQ(e.byte_offset(), bin.size() + 24 + 1 + 8);

    for (const auto& [bytes, message] : std::vector<std::pair<std::string, std::string>>{
             {"ply\nformat ascii 1.0\nelement vertex 1\n", "no end_header"},
             {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
              "vertex element has no property 'z'"},
             {"ply\nformat utf8 1.0\nend_header\n", "unknown format 'utf8'"},
             {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n", "unknown property type"},
             {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nelement vertex 3\n"
              "property float x\nproperty float y\nproperty float z\nend_header\n",
              "face element before the vertex element"},
             // Which x is meant? The last one used to win silently.
             {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
              "property float x\nend_header\n0 0 0 9\n",
              "property 'x' declared twice in element 'vertex'"}}) {
        test::spit(dir / "hdr.ply", bytes);
        EXPECT_NE(read_error(dir / "hdr.ply").message().find(message), std::string::npos) << message;
    }
}

TEST(PlyFormat, ProbesMagicWithLfOrCrlf) {
    auto probe = [](std::string_view s) {
        return io::probe_ply({reinterpret_cast<const std::byte*>(s.data()), s.size()}, std::nullopt);
    };
    EXPECT_TRUE(probe("ply\nformat ascii 1.0\n"));
    EXPECT_TRUE(probe("ply\r\nformat ascii 1.0\r\n"));
    EXPECT_FALSE(probe("plyx\n"));
    EXPECT_FALSE(probe("solid ply\n"));
    TempDir dir;
    test::spit(dir / "noext", test::slurp(fixture("ply/cube.ply")));
    EXPECT_EQ(io::open_input(dir / "noext").format->name, "ply");
}

// The command line: a bad index fails with exit 1, names the file and item, and leaves no
// output; a PLY written to stdout is complete.
TEST(PlyCli, BadInputLeavesNoOutputAndStdoutIsValid) {
    TempDir dir;
    test::spit(dir / "bad.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    std::string cmd = std::string(MESHSTREAM_BINARY) + " -q convert " + (dir / "bad.ply") + " " + (dir / "out.ply") +
                      " 2> " + (dir / "err.txt");
    int rc = std::system(cmd.c_str());
    EXPECT_EQ(WEXITSTATUS(rc), 1);
    std::string err = test::slurp(dir / "err.txt");
    EXPECT_NE(err.find("bad.ply:13: byte"), std::string::npos) << err;
    EXPECT_NE(err.find("element 'face' item 0: vertex index 7 out of range"), std::string::npos) << err;
    EXPECT_EQ(dir.entries().size(), 2u);
    for (const std::string& name : dir.entries()) EXPECT_TRUE(name == "bad.ply" || name == "err.txt") << name;

    cmd = std::string(MESHSTREAM_BINARY) + " -q convert " + fixture("gearwheel.bin.stl") + " - --to ply > " +
          (dir / "stdout.ply");
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_TRUE(read_soup(dir / "stdout.ply").xyz == read_soup(fixture("gearwheel.bin.stl")).xyz);
}

// ---- channels (issue 22) ----

TEST(PlyReader, ReadsEveryChannelOfTheCorpusFixtures) {
    // CGAL's colored_tetra.ply: double x y z nx ny nz, uchar red green blue, int id per vertex;
    // per face uchar red green blue and int label (face scalars); an 'edge' element not read.
    Full tetra = read_full(fixture("ply/cgal_colored_tetra.ply"));
    const io::Channels& ch = tetra.header.channels;
    EXPECT_TRUE(ch.normal);
    EXPECT_EQ(ch.color, (io::ColorFormat{io::ScalarType::kUInt8, false}));
    EXPECT_EQ(ch.uv_sets, 0);
    EXPECT_EQ(ch.vertex_scalars, (std::vector<io::ScalarChannel>{{"id", io::ScalarType::kInt32}}));
    EXPECT_EQ(ch.face_scalars, (std::vector<io::ScalarChannel>{{"red", io::ScalarType::kUInt8},
                                                               {"green", io::ScalarType::kUInt8},
                                                               {"blue", io::ScalarType::kUInt8},
                                                               {"label", io::ScalarType::kInt32}}));
    ASSERT_EQ(tetra.triangles(), 4u);
    // Face 1 is "3 0 3 1 0 255 0 1": vertices 0, 3, 1; green; label 1.
    EXPECT_EQ((std::vector<uint64_t>(tetra.ids.begin() + 3, tetra.ids.begin() + 6)), (std::vector<uint64_t>{0, 3, 1}));
    EXPECT_EQ(tetra.fscalars[0], (std::vector<double>{255, 0, 0, 255}));
    EXPECT_EQ(tetra.fscalars[1], (std::vector<double>{0, 255, 0, 0}));
    EXPECT_EQ(tetra.fscalars[3], (std::vector<double>{-1, 1, -1, 0}));
    // Vertex 3 is "1 0 0 0 -0.5 -0.5 255 128 0 3".
    EXPECT_EQ((std::vector<float>(tetra.normals.begin() + 9 + 3, tetra.normals.begin() + 9 + 6)),
              (std::vector<float>{0, -0.5f, -0.5f}));
    EXPECT_EQ((std::vector<float>(tetra.rgba.begin() + 12 + 4, tetra.rgba.begin() + 12 + 8)),
              (std::vector<float>{1, 128 / 255.0f, 0, 1}));
    EXPECT_EQ(tetra.vscalars[0][4], 3.0);
    const io::ReaderWarning edge = warning_of(tetra.header, "element 'edge' not read");
    EXPECT_EQ(edge.count, 6u);

    // Blender's cube_uv.ply: normals and s/t as uv set 0, 24 corner vertices.
    Full cube = read_full(fixture("ply/cube_uv.ply"));
    EXPECT_TRUE(cube.header.channels.normal);
    EXPECT_EQ(cube.header.channels.uv_sets, 1);
    EXPECT_TRUE(cube.header.channels.vertex_scalars.empty());
    ASSERT_EQ(cube.triangles(), 12u);
    // Face 0 is the quad "4 0 1 2 3", whose vertex 2 is "-1 -1 -1 0 0 -1 1 1".
    EXPECT_EQ(cube.ids[2], 2u);
    EXPECT_EQ((std::vector<float>(cube.uv[0].begin() + 4, cube.uv[0].begin() + 6)), (std::vector<float>{1, 1}));
    EXPECT_EQ((std::vector<float>(cube.normals.begin() + 6, cube.normals.begin() + 9)), (std::vector<float>{0, 0, -1}));

    // float-color.ply: float RGBA.
    Full fc = read_full(fixture("ply/float-color.ply"));
    EXPECT_EQ(fc.header.channels.color, (io::ColorFormat{io::ScalarType::kFloat32, true}));
    EXPECT_EQ(fc.rgba, (std::vector<float>{0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1}));

    // elephant_normals (big endian): unit normals at every corner.
    Full elephant = read_full(fixture("ply/elephant_normals.binary_be.ply"));
    ASSERT_EQ(elephant.normals.size(), 9 * elephant.triangles());
    for (size_t c = 0; c < elephant.normals.size(); c += 3) {
        const float* n = &elephant.normals[c];
        EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0f, 1e-4f) << c;
    }
    // points.ply: a point cloud with colour and normals has the channels but no triangles.
    Full points = read_full(fixture("ply/points.ply"));
    EXPECT_TRUE(points.header.channels.normal);
    EXPECT_TRUE(points.header.channels.color);
    EXPECT_EQ(points.triangles(), 0u);
}

// Round trips per channel: every fixture through meshstream's binary and ascii writers, plain
// and gzip, and through binary big and little endian encoded by this test from the ascii
// output, reads back value for value, with the same vertex numbering; the binary output is the
// test's encoding of the ascii one byte for byte, and writing a copy again changes nothing.
TEST(PlyRoundTrip, EveryChannelThroughEveryEncodingValueForValue) {
    for (const char* file : kChannelFixtures) {
        SCOPED_TRACE(file);
        TempDir dir;
        const Full original = read_full(fixture(file));
        ASSERT_GT(original.triangles(), 0u);
        convert_all(fixture(file), dir / "le.ply");
        convert_all(fixture(file), dir / "le.ply.gz");
        convert_all(fixture(file), dir / "ascii.ply", "ply-ascii");
        convert_all(fixture(file), dir / "ascii.ply.gz", "ply-ascii");
        const std::string ascii = test::slurp(dir / "ascii.ply");
        test::spit(dir / "be.ply", ascii_to_binary(ascii, true));
        EXPECT_TRUE(ascii_to_binary(ascii, false) == test::slurp(dir / "le.ply"));
        for (const char* copy : {"le.ply", "le.ply.gz", "ascii.ply", "ascii.ply.gz", "be.ply"}) {
            SCOPED_TRACE(copy);
            const Full back = read_full(dir / copy);
            expect_same(original, back);
            EXPECT_EQ(back.header.channels.normal, original.header.channels.normal);
            EXPECT_EQ(back.header.channels.uv_sets, original.header.channels.uv_sets);
            EXPECT_TRUE(back.header.warnings.empty());
        }
        convert_all(dir / "le.ply", dir / "again.ply");
        EXPECT_TRUE(test::slurp(dir / "again.ply") == test::slurp(dir / "le.ply"));
    }
}

TEST(PlyReader, ChannelsAreTheSameAtEveryChunkCapacity) {
    for (const char* file : kChannelFixtures) {
        SCOPED_TRACE(file);
        const Full whole = read_full(fixture(file));
        for (size_t capacity : {size_t{1}, size_t{7}}) expect_same(whole, read_full(fixture(file), capacity));
    }
}

TEST(PlyWriter, ChannelFilesAreTheSameAtEveryChunkCapacity) {
    TempDir dir;
    for (const char* file : kChannelFixtures) {
        SCOPED_TRACE(file);
        for (const char* to : {"ply", "ply-ascii"}) {
            convert_all(fixture(file), dir / "whole", to);
            for (size_t capacity : {size_t{1}, size_t{7}}) {
                convert_all(fixture(file), dir / "part", to, uint64_t{256} << 20, capacity);
                EXPECT_TRUE(test::slurp(dir / "part") == test::slurp(dir / "whole")) << to << " " << capacity;
            }
        }
    }
}

// A grid with a colour, a float and a uchar per vertex and an int per face, in 64 KiB: the
// reader's table spills its corner records and the welder sorts them out of core, yet the
// output is the in-memory run's, byte for byte, and reads back value for value.
TEST(PlyMemory, ChannelsThroughTinyBudgetGiveTheSameOutput) {
    TempDir dir;
    const int n = 120;
    std::string text = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n * n) +
                       "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
                       "property uchar green\nproperty uchar blue\nproperty float quality\nproperty uchar label\n"
                       "element face " +
                       std::to_string((n - 1) * (n - 1)) +
                       "\nproperty list uchar int vertex_indices\nproperty int region\nend_header\n";
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            text += std::to_string(i) + " " + std::to_string(j) + " " + std::to_string((i * j) % 7) + " " +
                    std::to_string(i % 256) + " " + std::to_string(j % 256) + " 9 " + std::to_string(0.25 * (i + j)) +
                    " " + std::to_string((i + j) % 3) + "\n";
    for (int i = 0; i + 1 < n; ++i)
        for (int j = 0; j + 1 < n; ++j) {
            const int v = i * n + j;
            text += "4 " + std::to_string(v) + " " + std::to_string(v + n) + " " + std::to_string(v + n + 1) + " " +
                    std::to_string(v + 1) + " " + std::to_string(i - j) + "\n";
        }
    test::spit(dir / "grid.ply", text);
    const uint64_t tiny = uint64_t{64} << 10;
    convert_all(dir / "grid.ply", dir / "mem.ply");
    convert_all(dir / "grid.ply", dir / "tiny.ply", {}, tiny);
    EXPECT_TRUE(test::slurp(dir / "mem.ply") == test::slurp(dir / "tiny.ply"));
    io::ReadOptions small;
    small.memory_budget_bytes = tiny;
    const Full original = read_full(dir / "grid.ply");
    EXPECT_EQ(original.triangles(), size_t(2 * (n - 1) * (n - 1)));
    expect_same(original, read_full(dir / "grid.ply", 7, small));
    expect_same(original, read_full(dir / "tiny.ply", io::TriangleChunk::kDefaultCapacity, small));
}

// ReadOptions::channels: a positions-only consumer gets the same positions, and a binary file
// in host byte order is then read in place whatever else its vertices hold; the header still
// lists the file's channels, and a chunk that has a channel not asked for gets its default.
TEST(PlyReader, ChannelsNotAskedForAreNotStored) {
    io::ReadOptions none;
    none.channels = io::ChannelKinds::none();
    const Full all = read_full(fixture("ply/cactus_vcolor.binary_le.ply"));
    const Full positions = read_full(fixture("ply/cactus_vcolor.binary_le.ply"), 7, none);
    EXPECT_EQ(positions.xyz, all.xyz);
    EXPECT_EQ(positions.ids, all.ids);
    EXPECT_TRUE(positions.header.channels.color);
    for (size_t c = 0; c < positions.rgba.size(); ++c) EXPECT_EQ(positions.rgba[c], c % 4 == 3 ? 1.0f : 0.0f);
    auto note = [](const Full& f) {
        for (const auto& [k, v] : f.header.notes)
            if (k == "vertex table") return v;
        return std::string();
    };
    EXPECT_EQ(note(positions), "input file, read in place");
    EXPECT_EQ(note(all), "in memory");
    // Kinds one at a time: colour without extras.
    io::ReadOptions colours = none;
    colours.channels.colors = true;
    const Full tetra = read_full(fixture("ply/cgal_colored_tetra.ply"), 3, colours);
    EXPECT_EQ(tetra.rgba, read_full(fixture("ply/cgal_colored_tetra.ply")).rgba);
    for (double v : tetra.vscalars[0]) EXPECT_EQ(v, 0.0);
    for (double v : tetra.fscalars[3]) EXPECT_EQ(v, 0.0);
    for (float v : tetra.normals) EXPECT_EQ(v, 0.0f);
}

// Which properties make which channel: normal_x (PCL), texture_u winning over s/t, further uv
// sets, colours of a type that is no colour type kept as scalars, incomplete normals and lists.
TEST(PlyReader, PropertyNamesMapToChannels) {
    TempDir dir;
    test::spit(dir / "p.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "property float normal_x\nproperty float normal_y\nproperty float normal_z\nproperty float s\n"
               "property float t\nproperty float texture_u\nproperty float texture_v\nproperty float texture_u1\n"
               "property float texture_v1\nproperty short red\nproperty short green\nproperty short blue\n"
               "property float nx\nproperty list uchar float history\nproperty double confidence\n"
               "element face 1\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\n"
               "end_header\n"
               "0 0 0 0 0 1 0.1 0.2 0.3 0.4 0.5 0.6 1 2 3 7 2 1 1 0.5\n"
               "1 0 0 0 0 1 1.1 1.2 1.3 1.4 1.5 1.6 4 5 6 8 0 0.25\n"
               "0 1 0 0 0 1 2.1 2.2 2.3 2.4 2.5 2.6 7 8 9 9 1 2 0.125\n"
               "3 0 1 2 6 0 0 1 0 0 1\n");
    const Full f = read_full(dir / "p.ply");
    const io::Channels& ch = f.header.channels;
    EXPECT_TRUE(ch.normal);
    EXPECT_EQ(ch.uv_sets, 2);
    EXPECT_FALSE(ch.color);  // short colours are no colour type: kept as named scalars
    EXPECT_EQ(ch.vertex_scalars, (std::vector<io::ScalarChannel>{{"s", io::ScalarType::kFloat32},
                                                                 {"t", io::ScalarType::kFloat32},
                                                                 {"red", io::ScalarType::kInt16},
                                                                 {"green", io::ScalarType::kInt16},
                                                                 {"blue", io::ScalarType::kInt16},
                                                                 {"nx", io::ScalarType::kFloat32},
                                                                 {"confidence", io::ScalarType::kFloat64}}));
    ASSERT_EQ(f.triangles(), 1u);
    EXPECT_EQ(f.uv[0], (std::vector<float>{0.3f, 0.4f, 1.3f, 1.4f, 2.3f, 2.4f}));  // texture_u/v
    EXPECT_EQ(f.uv[1], (std::vector<float>{0.5f, 0.6f, 1.5f, 1.6f, 2.5f, 2.6f}));  // texture_u1/v1
    EXPECT_EQ(f.vscalars[0], (std::vector<double>{double(0.1f), double(1.1f), double(2.1f)}));
    EXPECT_EQ(f.vscalars[2], (std::vector<double>{1, 4, 7}));
    EXPECT_EQ(f.vscalars[6], (std::vector<double>{0.5, 0.25, 0.125}));
    EXPECT_EQ(warning_of(f.header, "list property 'history' of element 'vertex' not read").count, 3u);
    EXPECT_EQ(warning_of(f.header, "list property 'texcoord' of element 'face' not read").count, 1u);
}

// The writer's names: uv sets as texture_u/texture_v (texture_u1, ...), scalars in their types,
// names made unique and free of blanks so the header reads back; materials are not kept (PLY
// has no material table).
TEST(PlyWriter, NamesAreUniqueAndReadBack) {
    TempDir dir;
    io::Channels ch;
    ch.uv_sets = 2;
    ch.vertex_scalars = {
        {"x", io::ScalarType::kFloat32}, {"my label", io::ScalarType::kUInt8}, {"texture_u", io::ScalarType::kInt16}};
    ch.face_scalars = {{"vertex_indices", io::ScalarType::kUInt32}, {"part", io::ScalarType::kInt8}};
    io::WriteOptions wo;
    wo.channels = ch;
    io::Output out = io::open_output(dir / "n.ply", "ply-ascii", wo);
    io::TriangleChunk chunk(1, ch);
    float* p = chunk.push_slot();
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::copy(tri, tri + 9, p);
    for (int k = 0; k < 3; ++k) {
        chunk.uv_at(0, 1)[2 * k] = 0.5f * float(k);
        chunk.vertex_scalar_at(0, 0)[k] = 1.5 * k;
        chunk.vertex_scalar_at(0, 1)[k] = 300;  // clamped to uchar
        chunk.vertex_scalar_at(0, 2)[k] = -2.4 * k;
    }
    *chunk.face_scalar_at(0, 0) = 7;
    *chunk.face_scalar_at(0, 1) = -3;
    out.write(chunk);
    out.finish();
    const std::string text = test::slurp(dir / "n.ply");
    EXPECT_NE(text.find("property float texture_u\nproperty float texture_v\nproperty float texture_u1\n"
                        "property float texture_v1\nproperty float x_2\nproperty uchar my_label\n"
                        "property short texture_u_2\nelement face 1\nproperty list uchar int vertex_indices\n"
                        "property uint vertex_indices_2\nproperty char part\nend_header\n"),
              std::string::npos)
        << text;
    const Full f = read_full(dir / "n.ply");
    EXPECT_EQ(f.header.channels.uv_sets, 2);
    EXPECT_EQ(f.uv[1], (std::vector<float>{0, 0, 0.5f, 0, 1, 0}));
    EXPECT_EQ(f.vscalars[0], (std::vector<double>{0, 1.5, 3}));
    EXPECT_EQ(f.vscalars[1], (std::vector<double>{255, 255, 255}));
    EXPECT_EQ(f.vscalars[2], (std::vector<double>{0, -2, -5}));
    EXPECT_EQ(f.fscalars, (std::vector<std::vector<double>>{{7}, {-3}}));

    io::Channels with_material = ch;
    with_material.material = true;
    const io::Channels kept = io::writable_channels(io::kPlyFormat, with_material, {});
    EXPECT_FALSE(kept.material);
    EXPECT_EQ(io::describe_missing(with_material, kept), "materials");
    EXPECT_EQ(io::writable_channels(io::kPlyFormat, ch, {}), ch);
}

// ---- lenient reading and bad counts (issue 21) ----

const std::string kTriangleBody = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
const std::string kTriangleElements =
    "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\n";

TEST(PlyReader, HeaderLinesThatAreNoKeywordAreSkippedWithOneWarning) {
    TempDir dir;
    // Old Blender exporters wrote a bare line like this one.
    const std::string head = "ply\nformat ascii 1.0\n";
    test::spit(dir / "b.ply", head + "Created by Blender3D 247 - www.blender.org\n" + kTriangleElements +
                                  "by hand\nend_header\n" + kTriangleBody);
    const Full f = read_full(dir / "b.ply");
    EXPECT_EQ(f.triangles(), 1u);
    ASSERT_EQ(f.header.warnings.size(), 1u);
    const io::ReaderWarning& w = f.header.warnings[0];
    EXPECT_EQ(w.text,
              "header lines that are no PLY keyword skipped like comments (the first: "
              "'Created by Blender3D 247 - www.blender.org')");
    EXPECT_EQ(w.count, 2u);
    EXPECT_EQ(w.first_line, 3u);
    EXPECT_EQ(w.first_byte_offset, head.size());
    io::ReadOptions strict;
    strict.strict = true;
    try {
        read_full(dir / "b.ply", 16, strict);
        ADD_FAILURE() << "no error under --strict";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.line(), 3u);
        EXPECT_EQ(e.byte_offset(), head.size());
        EXPECT_NE(e.message().find("unknown keyword 'Created' (strict mode)"), std::string::npos) << e.what();
    }
}

TEST(PlyReader, FacesOfFewerThanThreeVerticesAreCountedOrStrictErrors) {
    TempDir dir;
    const std::string head = "ply\nformat ascii 1.0\n" + kTriangleElements;
    std::string ascii = head;
    ascii.replace(ascii.find("face 1"), 6, "face 4");
    ascii += "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n0\n1 2\n";  // line 14: "2 0 1"
    test::spit(dir / "a.ply", ascii);
    std::string binary = head;
    binary.replace(binary.find("face 1"), 6, "face 3");
    binary.replace(binary.find("ascii"), 5, "binary_little_endian");
    binary += "end_header\n";
    const size_t body = binary.size();
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    binary.append(reinterpret_cast<const char*>(v), sizeof v);
    const int32_t tri[3] = {0, 1, 2};
    binary += '\3';
    binary.append(reinterpret_cast<const char*>(tri), 12);
    binary += '\1';
    binary.append(reinterpret_cast<const char*>(tri), 4);  // at body + 49: one index
    binary += '\0';
    test::spit(dir / "b.ply", binary);
    struct Case {
        const char* file;
        uint64_t count, line, offset;
    };
    for (const Case& c : {Case{"a.ply", 3, 14, ascii.find("2 0 1")}, Case{"b.ply", 2, 0, body + 49}}) {
        SCOPED_TRACE(c.file);
        for (size_t capacity : {size_t{1}, io::TriangleChunk::kDefaultCapacity}) {
            const Full f = read_full(dir / c.file, capacity);
            EXPECT_EQ(f.triangles(), 1u);
            const io::ReaderWarning w = warning_of(f.header, "faces with fewer than 3 vertices skipped");
            EXPECT_EQ(w.count, c.count);
            EXPECT_EQ(w.first_line, c.line);
            EXPECT_EQ(w.first_byte_offset, c.offset);
        }
        io::ReadOptions strict;
        strict.strict = true;
        try {
            read_full(dir / c.file, 16, strict);
            ADD_FAILURE() << "no error under --strict";
        } catch (const io::Error& e) {
            EXPECT_EQ(e.line(), c.line);
            EXPECT_EQ(e.byte_offset(), c.offset);
            EXPECT_NE(
                e.message().find("face with " + std::string(c.count == 3 ? "2" : "1") + " vertices (strict mode)"),
                std::string::npos)
                << e.what();
        }
    }
}

// Issue 21: a vertex count larger than the vertices present reads the faces' numbers as the
// last vertices and the faces from the wrong place. With an element after the faces (which
// ascii files do not have checked), that came out as a valid-looking mesh, exit 0. Ascii
// items are one a line, so the shift shows where it happens; a binary file's bytes must all
// be accounted for, the elements after the faces included.
TEST(PlyReader, VertexCountsThatDisagreeWithTheDataAreErrors) {
    TempDir dir;
    const std::string tail = "element edge 1\nproperty int a\nproperty int b\nend_header\n";
    const std::string vertex_props = "property float x\nproperty float y\nproperty float z\n";
    const std::string face_props = "element face 2\nproperty list uchar int vertex_indices\n";
    const std::string body = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 2 1 3\n0 1\n";
    struct Case {
        std::string text, message;
        uint64_t line;
    };
    const Case cases[] = {
        // One vertex too many: "vertex" 4 is "3 0 1" of the first face line.
        {"ply\nformat ascii 1.0\nelement vertex 5\n" + vertex_props + face_props + tail + body,
         "element 'face' item 0: begins on the line where the item before it ends", 17},
        // The same without an element after the faces.
        {"ply\nformat ascii 1.0\nelement vertex 5\n" + vertex_props + face_props + "end_header\n" + body.substr(0, 40),
         "element 'face' item 0: begins on the line where the item before it ends", 14},
        // One too few: vertex line 4 "1 1 0" is read as a face of 1 corner, then "1" of it as the next.
        {"ply\nformat ascii 1.0\nelement vertex 3\n" + vertex_props + face_props + tail + body,
         "element 'face' item 1: begins on the line where the item before it ends", 16},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.message);
        test::spit(dir / "lie.ply", c.text);
        io::Error e = read_error(dir / "lie.ply");
        EXPECT_NE(e.message().find(c.message), std::string::npos) << e.what();
        EXPECT_EQ(e.line(), c.line) << e.what();
    }
    // CR-only line ends are line ends.
    std::string cr = "ply\nformat ascii 1.0\n" + kTriangleElements + "end_header\n" + kTriangleBody;
    std::replace(cr.begin() + long(cr.find("end_header") + 11), cr.end(), '\n', '\r');
    test::spit(dir / "cr.ply", cr);
    EXPECT_EQ(read_soup(dir / "cr.ply").triangles(), 1u);

    // Binary, one vertex too many, an 8-byte element after the faces: the faces are read 12
    // bytes late, from the first face's last index byte, 0, so a face of no vertex comes first
    // and every later face is aligned again: everything adds up. That first face tells.
    std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 5\n" + vertex_props + face_props + tail;
    const float v[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    bin.append(reinterpret_cast<const char*>(v), sizeof v);
    const int32_t faces[2][3] = {{0, 1, 2}, {2, 1, 3}};
    for (const auto& f : faces) {
        bin += '\3';
        bin.append(reinterpret_cast<const char*>(f), 12);
    }
    const int32_t edge[2] = {0, 1};
    bin.append(reinterpret_cast<const char*>(edge), 8);
    test::spit(dir / "lie.bin.ply", bin);
    io::Error e = read_error(dir / "lie.bin.ply");
    EXPECT_NE(e.message().find("element 'face' item 0: the first face has 0 vertices: the header's vertex count (5) "
                               "is likely larger than the vertices present"),
              std::string::npos)
        << e.what();
    EXPECT_EQ(e.byte_offset(), bin.size() - 8 - 26 + 12);
    // With the right count it reads; cut short, the element after the faces runs past the end,
    // and a byte more after it is data nothing counts.
    bin.replace(bin.find("vertex 5"), 8, "vertex 4");
    test::spit(dir / "ok.bin.ply", bin);
    EXPECT_EQ(read_soup(dir / "ok.bin.ply").triangles(), 2u);
    test::spit(dir / "short.bin.ply", bin.substr(0, bin.size() - 1));
    e = read_error(dir / "short.bin.ply");
    EXPECT_NE(e.message().find("element 'edge' item 0: file ends early"), std::string::npos) << e.what();
    test::spit(dir / "extra.bin.ply", bin + "x");
    e = read_error(dir / "extra.bin.ply");
    EXPECT_NE(e.message().find("element 'edge' item 1: data after the last of the 1 'edge' items"), std::string::npos)
        << e.what();
    EXPECT_EQ(e.byte_offset(), bin.size());
}

// The same through the binary: warnings with the file, position and count on stderr and exit
// 0; --strict and bad counts exit 1 naming the file and line, leaving no output.
TEST(PlyCli, LenientCasesWarnAndBadCountsFail) {
    TempDir dir;
    test::spit(dir / "b.ply", "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org\n" +
                                  kTriangleElements + "end_header\n" + kTriangleBody);
    auto run = [&](const std::string& args) {
        const std::string cmd = std::string(MESHSTREAM_BINARY) + " -q " + args + " 2> " + (dir / "err.txt");
        const int rc = std::system(cmd.c_str());
        return std::make_pair(WEXITSTATUS(rc), test::slurp(dir / "err.txt"));
    };
    auto [code, err] = run("convert " + (dir / "b.ply") + " " + (dir / "out.ply"));
    EXPECT_EQ(code, 0) << err;
    EXPECT_NE(err.find("meshstream: warning: " + (dir / "b.ply") +
                       ": header lines that are no PLY keyword skipped like comments (the first: 'Created by "
                       "Blender3D 247 - www.blender.org') (at line 3, byte 21) (1)"),
              std::string::npos)
        << err;
    std::tie(code, err) = run("convert --strict " + (dir / "b.ply") + " " + (dir / "strict.ply"));
    EXPECT_EQ(code, 1);
    EXPECT_NE(err.find((dir / "b.ply") + ":3: byte 21: unknown keyword 'Created' (--strict)"), std::string::npos)
        << err;
    std::tie(code, err) = run("convert " + fixture("ply/cgal_colored_tetra.ply") + " " + (dir / "tetra.ply"));
    EXPECT_EQ(code, 0) << err;
    EXPECT_NE(err.find("cgal_colored_tetra.ply: element 'edge' not read: meshstream reads vertices and faces (6)"),
              std::string::npos)
        << err;
    test::spit(dir / "lie.ply",
               "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
               "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
               "element edge 1\nproperty int a\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n");
    std::tie(code, err) = run("convert " + (dir / "lie.ply") + " " + (dir / "lie.out.ply"));
    EXPECT_EQ(code, 1);
    EXPECT_NE(err.find((dir / "lie.ply") + ":15: byte"), std::string::npos) << err;
    EXPECT_NE(err.find("element 'face' item 0: begins on the line where the item before it ends"), std::string::npos)
        << err;
    for (const char* left : {"strict.ply", "lie.out.ply"}) EXPECT_FALSE(std::filesystem::exists(dir / left)) << left;
}
