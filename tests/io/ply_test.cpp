// PLY reader and writer: corpus fixtures with the MANIFEST's counts, concave polygons covered
// once, chunk boundaries, round trips through every encoding (big endian made by a
// byte-swapping helper), bounded memory giving the same bytes as the in-memory path, and bad
// input with file + element + offset.
#include "io/ply.hpp"

#include "indexed_test_util.hpp"
#include "io/text_number.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>

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
    test::spit(dir / "p.ply", "ply\nformat ascii 1.0\nelement vertex 22\nproperty float x\nproperty float y\n"
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
    for (const char* file : {"ply/mpi_ngons.ascii.ply", "ply/cube_quads.binary_be.ply", "ply/cactus_vcolor.binary_le.ply",
                             "ply/elephant_normals.binary_be.ply.gz"}) {
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
    test::spit(dir / "c.ply",
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
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
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
    test::spit(dir / "float.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
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
               "element vertex 4\r\nproperty int16 x\r\nproperty short y\r\nproperty float64 z\r\nproperty uchar confidence\r\n"
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
        test::Soup le = read_soup(dir / "le.ply"), ascii = read_soup(dir / "ascii.ply.gz"), be = read_soup(dir / "be.ply");
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
                         "comment meshstream sorted-axis=z\ncomment first\ncomment second\n", 0), 0u);
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
        {head + "3 0 1 2\n3 0 1 3\n", "element 'face' item 1: vertex index 3 out of range (3 vertices)", head.size() + 14, 14},
        {head + "3 0 -1 2\n", "element 'face' item 0: vertex index -1 out of range", head.size() + 4, 13},
        {head + "3 0 1 2\n", "element 'face' item 1: file ends early (header promises 2 face items)", head.size() + 8, 14},
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
    std::string bin = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    test::spit(dir / "short.ply", bin + std::string(12, '\0'));
    io::Error e = read_error(dir / "short.ply");
    EXPECT_NE(e.message().find("element 'vertex' item 1: file ends early (header promises 2 vertex items)"),
              std::string::npos) << e.what();
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
