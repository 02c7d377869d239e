// OBJ reader and writer: corpus fixtures with the MANIFEST's counts, concave polygons covered
// once, every face form, relative indices, continuations, chunk boundaries, round trips, a
// spilled vertex table, and bad input reported with file, line and offset.
#include "io/obj.hpp"

#include "indexed_test_util.hpp"
#include "io/text_number.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

using namespace meshstream;
using test::fixture;
using test::read_error;
using test::read_soup;
using test::TempDir;

TEST(ObjReader, ReadsCorpusFixturesWithManifestCounts) {
    const std::pair<const char*, size_t> cases[] = {
        {"obj/WusonOBJ.obj", 3732},          {"obj/WusonOBJ.obj.gz", 3732},
        {"obj/box.obj", 12},                 {"obj/box_negative_indices.obj", 12},
        {"obj/box_without_lineending.obj", 12}, {"obj/concave_polygon.obj", 64},
        {"obj/cube_mtllib_after_g.obj", 12}, {"obj/cube_usemtl.obj", 12},
        {"obj/cube_with_vertexcolors.obj", 12}, {"obj/double_torus_normals.obj", 466},
        {"obj/multiple_spaces.obj", 1},      {"obj/regr_3429812.obj", 4},
        {"obj/testmixed.obj", 12},
    };
    for (const auto& [file, triangles] : cases) {
        SCOPED_TRACE(file);
        io::Input in = io::open_input(fixture(file));
        EXPECT_EQ(in.format->name, "obj");  // detected by content (and extension)
        test::Soup s = read_soup(fixture(file));
        EXPECT_EQ(s.triangles(), triangles);
        EXPECT_EQ(s.ids.size(), 3 * triangles);
    }
}

TEST(ObjReader, NegativeIndicesMatchPositiveOnes) {
    test::Soup pos = read_soup(fixture("obj/box.obj"));
    test::Soup neg = read_soup(fixture("obj/box_negative_indices.obj"));
    EXPECT_EQ(pos.xyz, neg.xyz);
    EXPECT_EQ(pos.ids, neg.ids);
}

TEST(ObjReader, ChunkCapacitiesGiveIdenticalTriangles) {
    for (const char* file : {"obj/concave_polygon.obj", "obj/WusonOBJ.obj.gz", "obj/regr_3429812.obj"}) {
        SCOPED_TRACE(file);
        test::Soup whole = read_soup(fixture(file));
        for (size_t capacity : {size_t{1}, size_t{7}}) {
            test::Soup part = read_soup(fixture(file), capacity);
            EXPECT_EQ(part.xyz, whole.xyz);
            EXPECT_EQ(part.ids, whole.ids);
        }
    }
}

// concave_polygon.obj is one face of 66 corners in the plane x = -1.146: a ring whose hole is
// joined to the outline by an edge walked both ways (vertices 31 and 32 come twice). The fan
// from corner 0 folded it over itself: 13 times its area and 2 non-manifold edges.
TEST(ObjReader, ConcavePolygonFixtureIsCoveredOnce) {
    std::vector<std::array<float, 3>> v;
    std::vector<std::array<double, 2>> yz;  // the face's corners in its plane
    std::istringstream file(test::slurp(fixture("obj/concave_polygon.obj")));
    for (std::string line; std::getline(file, line);) {
        std::istringstream in(line);
        std::string key;
        in >> key;
        if (key == "v") {
            std::array<float, 3> p;
            in >> p[0] >> p[1] >> p[2];
            v.push_back(p);
        } else if (key == "f") {
            for (std::string corner; in >> corner;) {
                const std::array<float, 3>& p = v.at(std::stoul(corner) - 1);  // "27//1": stoul stops at '/'
                EXPECT_EQ(p[0], v[0][0]);
                yz.push_back({p[1], p[2]});
            }
        }
    }
    ASSERT_EQ(yz.size(), 66u);
    double area = 0;  // the shoelace formula, positive when the face looks along +x
    for (size_t i = 0; i < yz.size(); ++i) {
        const auto& q = yz[(i + 1) % yz.size()];
        area += (yz[i][0] * q[1] - q[0] * yz[i][1]) / 2;
    }
    EXPECT_NEAR(std::abs(area), 0.2455, 5e-4);
    test::Soup s = read_soup(fixture("obj/concave_polygon.obj"));
    ASSERT_EQ(s.triangles(), 64u);
    test::expect_covers_once(s.xyz, std::abs(area), {area > 0 ? 1.0 : -1.0, 0, 0}, 1e-4);
}

// An E (12 corners) and a star (10) on a tilted plane, the star also clockwise, then a convex
// hexagon: the concave ones are covered once whatever the chunk size, the hexagon is the fan.
TEST(ObjReader, ConcavePolygonsAreCoveredOnceAndConvexOnesFanned) {
    std::vector<std::array<double, 2>> star = test::star_shape(5, 0.4);
    const std::vector<test::PlacedPolygon> polygons = {
        test::place_polygon(test::e_shape()), test::place_polygon(star),
        test::place_polygon({star.rbegin(), star.rend()}),
        test::place_polygon({{2, 0}, {1, 1.7}, {-1, 1.7}, {-2, 0}, {-1, -1.7}, {1, -1.7}})};
    std::string text;
    uint64_t first = 1;
    for (const test::PlacedPolygon& p : polygons) {
        for (size_t k = 0; k < p.corners(); ++k) {
            text += 'v';
            for (int a = 0; a < 3; ++a) {
                text += ' ';
                io::append_number(text, p.xyz[3 * k + a]);
            }
            text += '\n';
        }
        text += 'f';
        for (size_t k = 0; k < p.corners(); ++k) {
            text += ' ';
            io::append_number(text, first + k);
        }
        text += '\n';
        first += p.corners();
    }
    TempDir dir;
    test::spit(dir / "p.obj", text);
    for (size_t capacity : {size_t{1}, size_t{7}, io::TriangleChunk::kDefaultCapacity}) {
        SCOPED_TRACE(capacity);
        test::Soup s = read_soup(dir / "p.obj", capacity);
        test::expect_polygons(s, polygons);
        ASSERT_EQ(s.triangles(), 10u + 8 + 8 + 4);
        EXPECT_EQ(std::vector<uint64_t>(s.ids.end() - 12, s.ids.end()),
                  (std::vector<uint64_t>{32, 33, 34, 32, 34, 35, 32, 35, 36, 32, 36, 37}));
    }
}

// Collinear corners doubling back, a repeated corner and a bow-tie have no honest
// triangulation, but each still gives n - 2 triangles.
TEST(ObjReader, DegeneratePolygonsStillGiveNMinus2Triangles) {
    TempDir dir;
    test::spit(dir / "d.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 1 1 0\nv 0 1 0\n"
                              "f 1 2 3 4 2\nf 1 2 2 5 6\nf 1 5 2 6\n");
    EXPECT_EQ(read_soup(dir / "d.obj").triangles(), 3u + 3 + 2);
}

TEST(ObjReader, EveryFaceFormContinuationsCrlfAndSkippedStatements) {
    TempDir dir;
    test::spit(dir / "forms.obj",
               "# comment\r\nmtllib x.mtl\r\no thing\r\nv 0 0 0\r\nv 1 0 0 1.0\r\nv 1 1 0 0.5 0.5 0.5\r\n"
               "v 0 1 0\r\nvt 0 0\r\nvn 0 0 1\r\ng group\r\ns off\r\nusemtl m\r\n"
               "f 1 2 3\r\nf 1/1 3/1 4/1\r\nf 1//1 2//1 4//1\r\nf 1/1/1 \\\r\n  2/1/1 -2/1/1\r\n"
               "l 1 2\r\np 3\r\nv 5 5 5\r\nf -1 1 2 3\n");
    test::Soup s = read_soup(dir / "forms.obj");
    EXPECT_EQ(s.ids, (std::vector<uint64_t>{0, 1, 2, 0, 2, 3, 0, 1, 3, 0, 1, 2, 4, 0, 1, 4, 1, 2}));
    EXPECT_EQ(std::vector<float>(s.xyz.end() - 3, s.xyz.end()), (std::vector<float>{1, 1, 0}));
}

TEST(ObjReader, CommentsMayEndVertexAndFaceLines) {
    TempDir dir;
    test::spit(dir / "c.obj", "v 0 0 0 # origin\nv 1 0 0#x\nv 0 1 0#y\nf 1 2 3 # the face\nf 3 2 1#back\n");
    test::Soup s = read_soup(dir / "c.obj");
    EXPECT_EQ(s.ids, (std::vector<uint64_t>{0, 1, 2, 2, 1, 0}));
    // The comment ends the line: "v 1 0 # x" has two coordinates.
    test::spit(dir / "short.obj", "v 1 0 # x\n");
    EXPECT_THROW(read_soup(dir / "short.obj"), io::Error);
}

TEST(ObjReader, BadInputNamesFileLineAndOffset) {
    TempDir dir;
    const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    struct Case {
        std::string bytes, message;
        uint64_t line, offset;
    };
    const Case cases[] = {
        {head + "f 1 2 0\n", "vertex index 0 is invalid (OBJ indices start at 1)", 4, head.size()},
        {head + "f 1 2 3\nf 1 2 4\nv 1 1 1\n", "vertex index 4 refers past the 3 vertices defined so far", 5, head.size() + 8},
        {head + "f -4 1 2\n", "vertex index -4 refers past the 3 vertices defined so far", 4, head.size()},
        {head + "# note\nv 1 x 2\n", "expected a coordinate, found 'x'", 5, head.size() + 7},
        {head + "v 1 2\n", "'v' needs 3 coordinates, found 2", 4, head.size()},
        {head + "f 1 2 a/1\n", "expected a vertex index, found 'a/1'", 4, head.size()},
        {head + "f 1 \\\n 2 \\\n 9\n", "vertex index 9 refers past", 4, head.size()},
        // Anything after x y z but w and r g b: a lost line end used to drop the second vertex
        // (and shift every later index), junk was ignored.
        {head + "v 0 0 0 v 1 0 0\nf 1 2 3\n", "expected a number (w or colour) after 'v x y z', found 'v'", 4, head.size()},
        {head + "v 0 0 0 foo\n", "found 'foo'", 4, head.size()},
        {head + "v 1 2 3 4 5\n", "'v' with 5 numbers (x y z, then w and/or r g b)", 4, head.size()},
        {head + "v 1 2 3 4 5 6 7 8\n", "'v' with 8 numbers", 4, head.size()},
        // Lines ending in CR alone read as one line: they used to give its first vertex only.
        {"v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", "lines ending in CR alone", 1, 0},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.message);
        test::spit(dir / "bad.obj", c.bytes);
        io::Error e = read_error(dir / "bad.obj");
        EXPECT_EQ(e.file(), dir / "bad.obj");
        EXPECT_NE(e.message().find(c.message), std::string::npos) << e.what();
        EXPECT_EQ(e.line(), c.line) << e.what();
        EXPECT_EQ(e.byte_offset(), c.offset) << e.what();
    }
}

TEST(ObjRoundTrip, PlyAndStlThroughObjAreExact) {
    for (const char* file : {"gearwheel.ascii.stl", "ply/cactus_vcolor.binary_le.ply", "obj/WusonOBJ.obj.gz"}) {
        SCOPED_TRACE(file);
        TempDir dir;
        test::Soup original = read_soup(fixture(file));
        test::convert(fixture(file), dir / "a.obj.gz");
        test::convert(dir / "a.obj.gz", dir / "b.obj");
        test::Soup a = read_soup(dir / "a.obj.gz"), b = read_soup(dir / "b.obj");
        EXPECT_TRUE(a.xyz == original.xyz);
        EXPECT_TRUE(b.xyz == original.xyz);
        EXPECT_EQ(a.ids, b.ids);  // OBJ -> OBJ keeps the numbering
        EXPECT_TRUE(test::slurp(dir / "b.obj").starts_with("# generated by meshstream\nv "));
    }
}

TEST(ObjWriter, RecordsSortedAxisAndWeldsPositions) {
    TempDir dir;
    io::WriteOptions wo;
    wo.sorted_axis = 0;
    // Two triangles sharing an edge, one corner written as -0.0.
    test::write_soup(dir / "s.obj", {0, 0, 0, 1, 0, 0, 0, 1, 0, -0.0f, 1, 0, 1, 0, 0, 1, 1, 0}, {}, wo);
    EXPECT_EQ(test::slurp(dir / "s.obj"),
              "# generated by meshstream\n# meshstream sorted-axis=x\n"
              "v 0 0 0\nv 0 1 0\nv 1 0 0\nv 1 1 0\nf 1 3 2\nf 2 3 4\n");
    auto axis = read_soup(dir / "s.obj").header.sorted_axis;
    ASSERT_TRUE(axis.has_value());
    EXPECT_EQ(*axis, 0);
}

TEST(ObjMemory, TinyBudgetSpillsTheVertexTableWithTheSameResult) {
    TempDir dir;
    std::vector<float> grid = test::grid_soup(200);  // 79202 triangles, 40000 vertices
    test::write_soup(dir / "grid.obj", grid);
    io::ReadOptions tiny;
    tiny.memory_budget_bytes = 128 << 10;
    test::Soup spilled = read_soup(dir / "grid.obj", io::TriangleChunk::kDefaultCapacity, tiny);
    test::Soup memory = read_soup(dir / "grid.obj");
    EXPECT_TRUE(spilled.xyz == grid);
    EXPECT_TRUE(memory.xyz == grid);
    EXPECT_EQ(spilled.ids, memory.ids);
    test::convert(dir / "grid.obj", dir / "tiny.obj", {}, 128 << 10);
    EXPECT_TRUE(test::slurp(dir / "tiny.obj") == test::slurp(dir / "grid.obj"));
}

TEST(ObjFormat, TextIsGuessedObjWhenTheNameSaysNothingElse) {
    // Without an extension, or with one no format claims, OBJ text is still read as OBJ; a name
    // that claims a format wins over the guess ("g" is OBJ's group statement and a GLB's first
    // byte).
    TempDir dir;
    auto detected = [](const std::string& path) { return std::string(io::detect_input_format(*io::ByteSource::open(path)).name); };
    for (const char* name : {"mesh", "mesh.txt", "mesh.obj"}) {
        test::spit(dir / name, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        EXPECT_EQ(detected(dir / name), "obj") << name;
        EXPECT_EQ(read_soup(dir / name).triangles(), 1u) << name;
    }
    const std::pair<const char*, const char*> named[] = {{"g.glb", "glb"}, {"p.ply", "ply"}, {"s.stl", "stl"}, {"g", "obj"}};
    for (const auto& [name, format] : named) {
        test::spit(dir / name, std::string_view(name, 1));
        EXPECT_EQ(detected(dir / name), format) << name;
    }
    // OBJ text named .stl fails as STL, and the error says what it reads as.
    test::spit(dir / "objtext.stl", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    try {
        io::open_input(dir / "objtext.stl", {}, {});
        ADD_FAILURE() << "read as STL";
    } catch (const io::Error& e) {
        EXPECT_NE(std::string(e.what()).find("binary STL header (neither binary nor ASCII STL); its content reads as "
                                             "obj (--from obj)"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(read_soup(dir / "objtext.stl", io::TriangleChunk::kDefaultCapacity, {}, "obj").triangles(), 1u);
}

TEST(ObjFormat, GuessAcceptsObjTextAndRejectsBinaryAndStl) {
    auto probe = [](std::string_view s) { return io::guess_obj({reinterpret_cast<const std::byte*>(s.data()), s.size()}); };
    EXPECT_TRUE(probe("# Blender\nmtllib a.mtl\no Cube\nv 1 2 3\n"));
    EXPECT_TRUE(probe("\r\n  v 1 2 3\r\n"));
    EXPECT_TRUE(probe("# only a comment\n"));
    EXPECT_FALSE(probe("solid cube\n facet normal 0 0 1\n"));
    EXPECT_FALSE(probe(std::string_view("# binary STL header\0\0\0\x01", 23)));
    EXPECT_FALSE(probe("ply\nformat ascii 1.0\n"));
    EXPECT_FALSE(probe(""));
    EXPECT_TRUE(probe("\xEF\xBB\xBFv 1 2 3\n"));
    TempDir dir;
    test::spit(dir / "bom.obj", "\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_EQ(read_soup(dir / "bom.obj").triangles(), 1u);
}
