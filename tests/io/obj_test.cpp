// OBJ reader and writer: corpus fixtures with the MANIFEST's counts, concave polygons covered
// once, every face form, relative indices, continuations, chunk boundaries, round trips, a
// spilled vertex table, and bad input reported with file, line and offset; normals, texture
// coordinates, colours and materials value for value through OBJ and PLY, seams, what is
// skipped and counted, and the writer's .mtl and textures (all or nothing, never over
// another file).
#include "io/obj.hpp"

#include "indexed_test_util.hpp"
#include "io/text_number.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
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
        {"obj/WusonOBJ.obj", 3732},
        {"obj/WusonOBJ.obj.gz", 3732},
        {"obj/box.obj", 12},
        {"obj/box_negative_indices.obj", 12},
        {"obj/box_without_lineending.obj", 12},
        {"obj/concave_polygon.obj", 64},
        {"obj/cube_mtllib_after_g.obj", 12},
        {"obj/cube_usemtl.obj", 12},
        {"obj/cube_with_vertexcolors.obj", 12},
        {"obj/double_torus_normals.obj", 466},
        {"obj/multiple_spaces.obj", 1},
        {"obj/regr_3429812.obj", 4},
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
    test::spit(dir / "d.obj",
               "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 1 1 0\nv 0 1 0\n"
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
        {head + "f 1 2 3\nf 1 2 4\nv 1 1 1\n", "vertex index 4 refers past the 3 vertices defined so far", 5,
         head.size() + 8},
        {head + "f -4 1 2\n", "vertex index -4 refers past the 3 vertices defined so far", 4, head.size()},
        {head + "# note\nv 1 x 2\n", "expected a coordinate, found 'x'", 5, head.size() + 7},
        {head + "v 1 2\n", "'v' needs 3 coordinates, found 2", 4, head.size()},
        {head + "f 1 2 a/1\n", "expected a vertex index, found 'a/1'", 4, head.size()},
        {head + "f 1 \\\n 2 \\\n 9\n", "vertex index 9 refers past", 4, head.size()},
        // Anything after x y z but w and r g b: a lost line end used to drop the second vertex
        // (and shift every later index), junk was ignored.
        {head + "v 0 0 0 v 1 0 0\nf 1 2 3\n", "expected a number (w or colour) after 'v x y z', found 'v'", 4,
         head.size()},
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
    auto detected = [](const std::string& path) {
        return std::string(io::detect_input_format(*io::ByteSource::open(path)).name);
    };
    for (const char* name : {"mesh", "mesh.txt", "mesh.obj"}) {
        test::spit(dir / name, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        EXPECT_EQ(detected(dir / name), "obj") << name;
        EXPECT_EQ(read_soup(dir / name).triangles(), 1u) << name;
    }
    const std::pair<const char*, const char*> named[] = {
        {"g.glb", "glb"}, {"p.ply", "ply"}, {"s.stl", "stl"}, {"g", "obj"}};
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
                                             "obj (the input format obj)"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_EQ(read_soup(dir / "objtext.stl", io::TriangleChunk::kDefaultCapacity, {}, "obj").triangles(), 1u);
}

TEST(ObjFormat, GuessAcceptsObjTextAndRejectsBinaryAndStl) {
    auto probe = [](std::string_view s) {
        return io::guess_obj({reinterpret_cast<const std::byte*>(s.data()), s.size()});
    };
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

// ---------------------------------------------------------------- channels and materials

namespace {

// Everything a reader gives, per corner (normal, rgba, uv, id) and per triangle (material name).
struct Mesh {
    std::vector<float> xyz, normal, rgba, uv;
    std::vector<uint64_t> ids;
    std::vector<std::string> material;  // the name, per triangle
    io::MeshHeader header;              // as it stands at the end
    size_t triangles() const { return xyz.size() / 9; }
};

Mesh read_mesh(const std::string& path, size_t capacity = io::TriangleChunk::kDefaultCapacity,
               io::ReadOptions options = {}, const io::Channels* channels = nullptr) {
    io::Input in = io::open_input(path, {}, options);
    io::TriangleChunk chunk(capacity, channels ? *channels : in.reader->header().channels);
    Mesh m;
    while (in.reader->next(chunk)) {
        for (size_t i = 0; i < chunk.size(); ++i) {
            m.xyz.insert(m.xyz.end(), chunk.xyz().begin() + 9 * i, chunk.xyz().begin() + 9 * i + 9);
            if (const float* n = chunk.normal_at(i)) m.normal.insert(m.normal.end(), n, n + 9);
            if (const float* c = chunk.color_at(i)) m.rgba.insert(m.rgba.end(), c, c + 12);
            if (const float* t = chunk.uv_at(i, 0)) m.uv.insert(m.uv.end(), t, t + 6);
            if (const uint64_t* id = chunk.id_at(i)) m.ids.insert(m.ids.end(), id, id + 3);
            if (const uint32_t* mat = chunk.material_at(i)) {
                const auto& table = in.reader->header().materials;
                EXPECT_LT(*mat, table.size());
                m.material.push_back(*mat < table.size() ? table[*mat].name : "?");
            }
        }
    }
    m.header = in.reader->header();
    return m;
}

// The notes a reader gave under the key "warning", in one string.
std::string warnings_of(const io::MeshHeader& header) {
    std::string out;
    for (const auto& [key, text] : header.notes)
        if (key == "warning") out += text + "\n";
    return out;
}

// Converts as `meshstream convert` does: the channels the output keeps, the material table,
// its late additions.
void convert_all(const std::string& from, const std::string& to, std::string_view to_format = {},
                 uint64_t budget = uint64_t{256} << 20, size_t capacity = io::TriangleChunk::kDefaultCapacity,
                 std::vector<std::string>* writer_notes = nullptr) {
    io::ReadOptions ro;
    ro.memory_budget_bytes = budget;
    io::Input in = io::open_input(from, {}, ro);
    const io::MeshHeader& header = in.reader->header();
    io::WriteOptions wo;
    wo.memory_budget_bytes = budget;
    wo.channels = io::writable_channels(io::output_format(to, to_format), header.channels, wo);
    if (wo.channels.material) wo.materials = header.materials;
    io::Output out = io::open_output(to, to_format, wo);
    io::TriangleChunk chunk(capacity, wo.channels);
    while (in.reader->next(chunk)) out.write(chunk);
    if (wo.channels.material) out.writer->update_materials(in.reader->header().materials);
    out.finish();
    if (writer_notes) *writer_notes = out.writer->notes();
}

// An independent reading of a triangles-only OBJ: per corner, the values its v/vt/vn lines
// hold, for comparing with the reader's.
struct Reference {
    std::vector<float> xyz, normal, rgb, uv;
    std::vector<std::string> material;
};

Reference reference_of(const std::string& path) {
    std::vector<std::vector<float>> v, vt, vn;
    Reference r;
    std::istringstream file(test::slurp(path));
    std::string current;
    for (std::string line; std::getline(file, line);) {
        std::istringstream in(line);
        std::string key;
        in >> key;
        std::vector<float> values;
        if (key == "v" || key == "vt" || key == "vn")
            for (float f; in >> f;) values.push_back(f);
        if (key == "v") v.push_back(values);
        if (key == "vt") vt.push_back(values);
        if (key == "vn") vn.push_back(values);
        if (key == "usemtl") in >> current;
        if (key != "f") continue;
        int corners = 0;
        for (std::string corner; in >> corner; ++corners) {
            std::istringstream parts(corner);
            std::string a, b, c;
            std::getline(parts, a, '/');
            std::getline(parts, b, '/');
            std::getline(parts, c, '/');
            auto at = [](const std::vector<std::vector<float>>& table,
                         const std::string& index) -> const std::vector<float>& {
                const long i = std::stol(index);
                return table.at(i > 0 ? size_t(i - 1) : table.size() + size_t(i));
            };
            const std::vector<float>& p = at(v, a);
            r.xyz.insert(r.xyz.end(), p.begin(), p.begin() + 3);
            if (p.size() >= 6) r.rgb.insert(r.rgb.end(), p.end() - 3, p.end());
            if (!b.empty()) r.uv.insert(r.uv.end(), at(vt, b).begin(), at(vt, b).begin() + 2);
            if (!c.empty()) r.normal.insert(r.normal.end(), at(vn, c).begin(), at(vn, c).begin() + 3);
        }
        EXPECT_EQ(corners, 3) << "reference_of reads triangles only";
        r.material.push_back(current);
    }
    return r;
}

std::vector<float> rgb_of(const std::vector<float>& rgba) {
    std::vector<float> out;
    for (size_t i = 0; i < rgba.size(); ++i)
        if (i % 4 != 3) out.push_back(rgba[i]);
    return out;
}

}  // namespace

TEST(ObjChannels, CorpusNormalsTextureCoordinatesAndColoursAreReadValueForValue) {
    for (const char* file : {"obj/WusonOBJ.obj", "obj/double_torus_normals.obj", "obj/cube_with_vertexcolors.obj",
                             "obj/cube_usemtl.obj"}) {
        SCOPED_TRACE(file);
        Reference ref = reference_of(fixture(file));
        Mesh m = read_mesh(fixture(file));
        EXPECT_EQ(m.xyz, ref.xyz);
        EXPECT_EQ(m.normal, ref.normal);
        EXPECT_EQ(m.uv, ref.uv);
        EXPECT_EQ(rgb_of(m.rgba), ref.rgb);
        EXPECT_EQ(m.header.channels.normal, !ref.normal.empty());
        EXPECT_EQ(m.header.channels.uv_sets, ref.uv.empty() ? 0 : 1);
        EXPECT_EQ(m.header.channels.color.has_value(), !ref.rgb.empty());
        if (m.header.channels.color) {
            EXPECT_EQ(m.header.channels.color->type, io::ScalarType::kFloat32);
            EXPECT_FALSE(m.header.channels.color->alpha);
            for (size_t c = 3; c < m.rgba.size(); c += 4) EXPECT_EQ(m.rgba[c], 1.0f);
        }
    }
    // Wuson: one vt for all corners; 2076 vn for 2117 v.
    Mesh wuson = read_mesh(fixture("obj/WusonOBJ.obj"));
    ASSERT_EQ(wuson.uv.size(), 6u * 3732);
    EXPECT_EQ(wuson.uv[0], 0.0f);
    EXPECT_EQ(wuson.uv[1], 1.0f);
}

// Corners of one position with different vt or vn are different vertices; the same triple is
// the same vertex; read without those channels, the id is the OBJ vertex number.
TEST(ObjChannels, VertexIdsFollowTheWholeCornerSoSeamsSurvive) {
    TempDir dir;
    test::spit(dir / "seam.obj",
               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
               "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
               "vn 0 0 1\nvn 0 0 -1\n"
               "f 1/1/1 2/2/1 3/3/1\n"
               "f 1/1/1 3/3/1 4/4/1\n"     // shares two whole corners with the first face
               "f 1/5/1 3/-3/1 4/4/2\n");  // v 1 with another vt, v 3 the same (vt -3 is 3), v 4 another vn
    Mesh m = read_mesh(dir / "seam.obj");
    ASSERT_EQ(m.ids.size(), 9u);
    EXPECT_EQ(m.ids[3], m.ids[0]);  // 1/1/1
    EXPECT_EQ(m.ids[4], m.ids[2]);  // 3/3/1
    EXPECT_NE(m.ids[6], m.ids[0]);  // 1/5/1: a uv seam
    EXPECT_EQ(m.ids[7], m.ids[2]);  // 3/3/1 again
    EXPECT_NE(m.ids[8], m.ids[5]);  // 4/4/2: a normal seam
    std::vector<uint64_t> distinct(m.ids.begin(), m.ids.end());
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    EXPECT_EQ(distinct.size(), 6u);
    // Without texture coordinates and normals in the chunk, positions decide.
    const io::Channels ids_only = io::Channels::ids_only();
    Mesh plain = read_mesh(dir / "seam.obj", io::TriangleChunk::kDefaultCapacity, {}, &ids_only);
    EXPECT_EQ(plain.ids, (std::vector<uint64_t>{0, 1, 2, 0, 2, 3, 0, 2, 3}));
}

TEST(ObjMaterials, UsemtlGivesEachTriangleItsMaterialFromTheMtl) {
    Mesh m = read_mesh(fixture("obj/cube_usemtl.obj"));
    ASSERT_TRUE(m.header.channels.material);
    EXPECT_EQ(m.material, reference_of(fixture("obj/cube_usemtl.obj")).material);
    // The MTL's materials in its order, then the name it does not define.
    ASSERT_EQ(m.header.materials.size(), 3u);
    const io::Material& mtl = m.header.materials[0];
    EXPECT_EQ(mtl.name, "mtl");
    EXPECT_EQ(mtl.base_color, (std::array<float, 4>{0.8f, 0.125f, 0.1f, 1.0f}));
    ASSERT_TRUE(mtl.texture.has_value());
    EXPECT_EQ(mtl.texture->uri, "checker.png");  // "-s 1 1 1 -clamp on" are options
    EXPECT_EQ(mtl.texture->mime_type, "image/png");
    const std::string png = test::slurp(fixture("obj/checker.png"));
    ASSERT_EQ(mtl.texture->bytes.size(), png.size());
    EXPECT_EQ(std::memcmp(mtl.texture->bytes.data(), png.data(), png.size()), 0);
    EXPECT_EQ(m.header.materials[1].name, "mtl2");
    EXPECT_EQ(m.header.materials[1].base_color, (std::array<float, 4>{0.1f, 0.6f, 0.25f, 0.5f}));
    EXPECT_FALSE(m.header.materials[1].texture.has_value());
    EXPECT_EQ(m.header.materials[2].name, "mtl3");
    EXPECT_EQ(m.header.materials[2].base_color, (std::array<float, 4>{1, 1, 1, 1}));
    const std::string warnings = warnings_of(m.header);
    EXPECT_NE(warnings.find("materials used but defined in no material library, kept by name only: 'mtl3'"),
              std::string::npos)
        << warnings;
    EXPECT_NE(
        warnings.find("material statements not kept: Ka, Ks, Ns, illum (meshstream keeps Kd, d or Tr, and map_Kd)"),
        std::string::npos)
        << warnings;

    // Tr is 1 - alpha; a texture that is not there is kept by its name, with one warning.
    Mesh g = read_mesh(fixture("obj/cube_mtllib_after_g.obj"));
    ASSERT_EQ(g.header.materials.size(), 1u);
    EXPECT_EQ(g.header.materials[0].base_color, (std::array<float, 4>{0.25f, 0.5f, 0.75f, 0.75f}));
    ASSERT_TRUE(g.header.materials[0].texture.has_value());
    EXPECT_EQ(g.header.materials[0].texture->uri, "missing_texture.png");
    EXPECT_TRUE(g.header.materials[0].texture->bytes.empty());
    EXPECT_EQ(g.material, std::vector<std::string>(12, "MyMaterial"));
    EXPECT_EQ(warnings_of(g.header),
              "texture images not found, kept by name only: " + fixture("obj/missing_texture.png") + "\n");
}

TEST(ObjMaterials, MissingLibrariesAndUndefinedNamesKeepNamesWithOneWarning) {
    Mesh r = read_mesh(fixture("obj/regr_3429812.obj"));
    ASSERT_EQ(r.header.materials.size(), 1u);
    EXPECT_EQ(r.header.materials[0].name, "Trim");
    EXPECT_EQ(r.material, std::vector<std::string>(4, "Trim"));
    EXPECT_EQ(warnings_of(r.header),
              "material library " + fixture("obj/regr_3429812.mtl") + " not found: materials kept by name only\n");
    Mesh b = read_mesh(fixture("obj/box.obj"));
    EXPECT_EQ(b.material, std::vector<std::string>(12, "Default"));
    EXPECT_EQ(warnings_of(b.header),
              "materials used but defined in no material library, kept by name only: 'Default'\n");
}

// A library named first: faces before the first usemtl get "default", added only then. Names
// met after the first face join the table while reading. Without mtllib or usemtl before the
// first face, later ones are dropped with a warning.
TEST(ObjMaterials, DefaultMaterialLateNamesAndDroppedStatements) {
    TempDir dir;
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    test::spit(dir / "lib.mtl", "newmtl red\nKd 1 0 0\n");
    test::spit(dir / "first.obj", "mtllib lib.mtl\n" + v + "f 1 2 3\nusemtl red\nf 1 2 3\nusemtl blue\nf 3 2 1\n");
    {
        io::Input in = io::open_input(dir / "first.obj");
        ASSERT_EQ(in.reader->header().materials.size(), 2u);  // at open: red, default
        EXPECT_EQ(in.reader->header().materials[1].name, "default");
    }
    Mesh m = read_mesh(dir / "first.obj");
    EXPECT_EQ(m.material, (std::vector<std::string>{"default", "red", "blue"}));
    ASSERT_EQ(m.header.materials.size(), 3u);
    EXPECT_EQ(m.header.materials[0].base_color, (std::array<float, 4>{1, 0, 0, 1}));
    EXPECT_EQ(warnings_of(m.header), "materials used but defined in no material library, kept by name only: 'blue'\n");
    // The writer gets the table as it ended (convert's update_materials): 'blue' is in it.
    convert_all(dir / "first.obj", dir / "out.obj");
    EXPECT_EQ(read_mesh(dir / "out.obj").material, (std::vector<std::string>{"default", "red", "blue"}));
    EXPECT_NE(test::slurp(dir / "out.mtl").find("newmtl blue\nKd 1 1 1\n"), std::string::npos);

    test::spit(dir / "named.obj", "usemtl red\nmtllib lib.mtl\n" + v + "f 1 2 3\n");  // usemtl before its library
    Mesh named = read_mesh(dir / "named.obj");
    ASSERT_EQ(named.header.materials.size(), 1u);
    EXPECT_EQ(named.header.materials[0].base_color, (std::array<float, 4>{1, 0, 0, 1}));
    EXPECT_EQ(warnings_of(named.header), "");

    test::spit(dir / "late.obj", v + "f 1 2 3\nmtllib lib.mtl\nusemtl red\nf 1 2 3\n");
    Mesh late = read_mesh(dir / "late.obj");
    EXPECT_FALSE(late.header.channels.material);
    EXPECT_EQ(late.triangles(), 2u);
    EXPECT_EQ(warnings_of(late.header),
              "2 mtllib and usemtl statements after the first face dropped: materials are read "
              "when mtllib or usemtl comes before it\n");
}

// A usemtl without a name (some exporters write it for the default material) selects the
// material of faces before any usemtl, with a counted warning; --strict refuses it at its line.
TEST(ObjMaterials, UsemtlWithoutANameIsTheDefaultMaterial) {
    TempDir dir;
    const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    test::spit(dir / "lib.mtl", "newmtl red\nKd 1 0 0\n");
    test::spit(dir / "late.obj", "mtllib lib.mtl\n" + v + "f 1 2 3\nusemtl red\nf 1 2 3\nusemtl\nf 3 2 1\n");
    const std::string text =
        "usemtl statements without a material name read as material 'default', that of faces before any usemtl";
    const Mesh late = read_mesh(dir / "late.obj");
    EXPECT_EQ(late.material, (std::vector<std::string>{"default", "red", "default"}));
    ASSERT_EQ(late.header.materials.size(), 2u);  // red, default: the same entry twice
    EXPECT_EQ(late.header.warnings, (std::vector<io::ReaderWarning>{{text, 1, 8, 66}}));
    EXPECT_EQ(warnings_of(late.header), "");
    // Before the first face, blanks only: it is what announces materials.
    test::spit(dir / "first.obj", "usemtl \t\n" + v + "f 1 2 3\nusemtl red\nf 1 2 3\nusemtl\nf 1 2 3\n");
    const Mesh first = read_mesh(dir / "first.obj");
    EXPECT_TRUE(first.header.channels.material);
    EXPECT_EQ(first.material, (std::vector<std::string>{"default", "red", "default"}));
    EXPECT_EQ(first.header.warnings, (std::vector<io::ReaderWarning>{{text, 2, 1, 0}}));
    EXPECT_EQ(warnings_of(first.header),
              "materials used but defined in no material library, kept by name only: 'red'\n");
    io::ReadOptions strict;
    strict.strict = true;
    try {
        read_mesh(dir / "late.obj", io::TriangleChunk::kDefaultCapacity, strict);
        ADD_FAILURE() << "no error under --strict";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), dir / "late.obj");
        EXPECT_EQ(e.message(), "'usemtl' without a material name (strict mode)");
        EXPECT_EQ(e.line(), 8u);
        EXPECT_EQ(e.byte_offset(), 66u);
    }
}

TEST(ObjChannels, TheFirstFaceAndVertexDecideAndTheRestIsCounted) {
    TempDir dir;
    struct Case {
        std::string text, warning;
    };
    const Case cases[] = {
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 2 3\nf 1/1 2/1 3/1\n",
         "texture coordinates of 1 face dropped: the first face has none, and the first face decides\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 2/1 3\n",
         "2 face corners without a texture coordinate in a file whose first face has them: given (0, 0)\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1 2 3\nf 1//1 2//1 3//1\nf 1//1 2//1 3//1\n",
         "normals of 2 faces dropped: the first face has none, and the first face decides\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1 2 3\n",
         "3 face corners without a normal in a file whose first face has them: given (0, 0, 0)\n"},
        {"v 0 0 0\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n",
         "colours of 1 vertex dropped: the first vertex has none, and the first vertex decides\n"},
        {"v 0 0 0 1 0 0\nv 1 0 0 1 0.5 0.5 0.5\nv 0 1 0\nf 1 2 3\n",
         "1 vertex without a colour in a file whose first vertex has one: given white (1, 1, 1)\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1\nf 1 2 3\nf 3 1\n", "3 faces with fewer than 3 corners skipped\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\np 1\nf 1 2 3\n",
         "2 line and point statements ('l', 'p') skipped: meshstream reads faces\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\ncstype bspline\ndeg 3\ncurv 0 1 1 2 3\nend\nf 1 2 3\n",
         "4 free-form geometry statements (curv, surf, ...) skipped: meshstream reads polygon faces\n"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nfoo 1\nf 1 2 3\nbar\n",
         "2 unknown statements skipped (the first: 'foo' at line 4)\n"},
        {"g a\no b\ns 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nmg 1\nf 1 2 3\n", ""},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        test::spit(dir / "c.obj", c.text);
        Mesh m = read_mesh(dir / "c.obj");
        EXPECT_EQ(warnings_of(m.header), c.warning);
    }
    // A corner without vt in a file with texture coordinates: (0, 0); a vertex without colour: white.
    test::spit(dir / "c.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nvt 0.5 0.25\nf 1/1 2 3/1\n");
    Mesh m = read_mesh(dir / "c.obj");
    EXPECT_EQ(m.uv, (std::vector<float>{0.5f, 0.25f, 0, 0, 0.5f, 0.25f}));
    EXPECT_EQ(m.rgba, (std::vector<float>{1, 0, 0, 1, 1, 1, 1, 1, 0, 0, 1, 1}));
    // 7 numbers are x y z w r g b.
    test::spit(dir / "w.obj", "v 0 0 0 1 0.25 0.5 0.75\nv 1 0 0 1 0 0 0\nv 0 1 0 1 0 0 0\nf 1 2 3\n");
    const Mesh w = read_mesh(dir / "w.obj");
    EXPECT_EQ(std::vector<float>(w.rgba.begin(), w.rgba.begin() + 4), (std::vector<float>{0.25f, 0.5f, 0.75f, 1}));
}

TEST(ObjReader, BadAttributesAndMaterialStatementsNameFileLineAndOffset) {
    TempDir dir;
    const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n";
    struct Case {
        std::string bytes, message;
        uint64_t line, offset;
    };
    const Case cases[] = {
        {head + "f 1/2 2/1 3/1\n",
         "texture coordinate index 2 refers past the 1 texture coordinates (vt) defined so far", 6, head.size()},
        {head + "f 1/1 2/1 3/-2\n", "texture coordinate index -2 refers past the 1 texture coordinates (vt)", 6,
         head.size()},
        {head + "f 1//1 2//0 3//1\n", "normal index 0 is invalid (OBJ indices start at 1)", 6, head.size()},
        {head + "f 1//1 2//1 3//2\n", "normal index 2 refers past the 1 normals (vn) defined so far", 6, head.size()},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\nvt 0 0\n", "texture coordinate index 1 refers past the 0", 4, 24},
        {head + "f 1/x 2 3\n", "expected a texture coordinate index, found '1/x'", 6, head.size()},
        {head + "f 1//n 2 3\n", "expected a normal index, found '1//n'", 6, head.size()},
        {head + "f 1/1/1/1 2 3\n", "expected v, v/vt, v//vn or v/vt/vn, found '1/1/1/1'", 6, head.size()},
        {head + "vt 0 0 0 0\n", "'vt' with more than 3 numbers (u v w)", 6, head.size()},
        {head + "vt 0 a\n", "expected a texture coordinate, found 'a'", 6, head.size()},
        {head + "vt\n", "'vt' needs a texture coordinate (u, v), found none", 6, head.size()},
        {head + "vt # none\n", "'vt' needs a texture coordinate (u, v), found none", 6, head.size()},
        {head + "vn 0 0\n", "'vn' needs 3 numbers, found 2", 6, head.size()},
        {head + "vn 0 0 1 1\n", "'vn' with more than 3 numbers", 6, head.size()},
        {head + "vn 0 x 1\n", "expected a normal component, found 'x'", 6, head.size()},
        {head + "mtllib   \n", "'mtllib' without a file name", 6, head.size()},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.bytes);
        test::spit(dir / "bad.obj", c.bytes);
        io::Error e = read_error(dir / "bad.obj");
        EXPECT_EQ(e.file(), dir / "bad.obj");
        EXPECT_NE(e.message().find(c.message), std::string::npos) << e.what();
        EXPECT_EQ(e.line(), c.line) << e.what();
        EXPECT_EQ(e.byte_offset(), c.offset) << e.what();
    }
    // MTL errors name the MTL file and its line.
    const Case mtl_cases[] = {
        {"newmtl a\nKd 1 x 0\n", "expected a colour component after 'Kd', found 'x'", 2, 0},
        {"# lib\nKd 1 1 1\n", "'Kd' before any 'newmtl'", 2, 0},
        {"newmtl a\nd\n", "expected an alpha after 'd', found the end of the line", 2, 0},
        {"newmtl a\nTr 0.5 0.5\n", "'Tr' with more than one number", 2, 0},
        {"newmtl\n", "'newmtl' without a material name", 1, 0},
        {"newmtl a\n\nmap_Kd -s 1 1 1 -clamp on\n", "'map_Kd' without a file name", 3, 0},
        {"newmtl a\nKd 1 1 1 1\n", "'Kd' with more than 3 numbers", 2, 0},
        {"newmtl a\r\nKd 1 \\\r\n 1 z\r\n", "expected a colour component after 'Kd', found 'z'", 2, 0},
        {"newmtl a\n\x01\x02\x03", "is not text (a byte 1 in it): not an MTL file", 2, 0},
        {"newmtl a\n\xff\xfe Kd\n", "not an MTL statement: '\\xff\\xfe'", 2, 0},
    };
    for (const Case& c : mtl_cases) {
        SCOPED_TRACE(c.bytes);
        test::spit(dir / "bad.mtl", c.bytes);
        test::spit(dir / "m.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        io::Error e = read_error(dir / "m.obj");
        EXPECT_EQ(e.file(), dir / "bad.mtl");
        EXPECT_NE(e.message().find(c.message), std::string::npos) << e.what();
        EXPECT_EQ(e.line(), c.line) << e.what();
    }
}

namespace {

// Corners i and j share an id in `a` exactly when they do in `b`: the same vertices.
void expect_same_vertices(const std::vector<uint64_t>& a, const std::vector<uint64_t>& b) {
    ASSERT_EQ(a.size(), b.size());
    std::map<uint64_t, uint64_t> a_to_b, b_to_a;
    for (size_t c = 0; c < a.size(); ++c) {
        auto [i, new_a] = a_to_b.emplace(a[c], b[c]);
        auto [j, new_b] = b_to_a.emplace(b[c], a[c]);
        ASSERT_EQ(i->second, b[c]) << "corner " << c;
        ASSERT_EQ(j->second, a[c]) << "corner " << c;
    }
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
    EXPECT_TRUE(a.xyz == b.xyz);
    EXPECT_TRUE(a.normal == b.normal);
    EXPECT_TRUE(a.uv == b.uv);
    EXPECT_TRUE(a.rgba == b.rgba);
    EXPECT_EQ(a.material, b.material);
}

// An OBJ's text without its mtllib line (which names the file's own .mtl).
std::string without_mtllib(const std::string& path) {
    std::string text = test::slurp(path);
    if (size_t at = text.find("\nmtllib "); at != std::string::npos) text.erase(at + 1, text.find('\n', at + 1) - at);
    return text;
}

void expect_same_materials(const std::vector<io::Material>& a, const std::vector<io::Material>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        SCOPED_TRACE(a[i].name);
        EXPECT_EQ(a[i].name, b[i].name);
        EXPECT_EQ(a[i].base_color, b[i].base_color);
        ASSERT_EQ(a[i].texture.has_value(), b[i].texture.has_value());
        if (a[i].texture) {
            EXPECT_TRUE(a[i].texture->bytes == b[i].texture->bytes);
        }
    }
}

std::vector<std::string> sorted(std::vector<std::string> v) {
    std::sort(v.begin(), v.end());
    return v;
}

}  // namespace

// Every channel comes back value for value, the vertices (seams) stay as they were, chunk
// sizes do not change a byte, and writing the output again gives the same file.
TEST(ObjRoundTrip, EveryChannelSurvivesObjToObj) {
    for (const char* file :
         {"obj/WusonOBJ.obj", "obj/double_torus_normals.obj", "obj/cube_with_vertexcolors.obj", "obj/cube_usemtl.obj",
          "obj/cube_mtllib_after_g.obj", "obj/concave_polygon.obj", "obj/testmixed.obj"}) {
        SCOPED_TRACE(file);
        TempDir dir;
        Mesh original = read_mesh(fixture(file));
        convert_all(fixture(file), dir / "a.obj");
        Mesh a = read_mesh(dir / "a.obj");
        expect_same_mesh(original, a);
        expect_same_vertices(original.ids, a.ids);
        EXPECT_EQ(a.header.channels, original.header.channels);
        expect_same_materials(original.header.materials, a.header.materials);
        for (size_t capacity : {size_t{1}, size_t{7}}) {
            convert_all(fixture(file), dir / "c.obj", {}, uint64_t{256} << 20, capacity);
            EXPECT_TRUE(without_mtllib(dir / "c.obj") == without_mtllib(dir / "a.obj")) << capacity;
        }
        convert_all(dir / "a.obj", dir / "b.obj");
        EXPECT_TRUE(without_mtllib(dir / "b.obj") == without_mtllib(dir / "a.obj"));
    }
}

TEST(ObjWriter, WritesTheMtlAndCopiesTexturesByteForByte) {
    TempDir dir;
    std::vector<std::string> notes;
    convert_all(fixture("obj/cube_usemtl.obj"), dir / "out.obj", {}, uint64_t{256} << 20, 1000, &notes);
    EXPECT_EQ(sorted(dir.entries()), (std::vector<std::string>{"checker.png", "out.mtl", "out.obj"}));
    EXPECT_TRUE(test::slurp(dir / "checker.png") == test::slurp(fixture("obj/checker.png")));
    EXPECT_EQ(test::slurp(dir / "out.mtl"),
              "# generated by meshstream\n"
              "\nnewmtl mtl\nKd 0.8 0.125 0.1\nmap_Kd checker.png\n"
              "\nnewmtl mtl2\nKd 0.1 0.6 0.25\nd 0.5\n"
              "\nnewmtl mtl3\nKd 1 1 1\n");
    const std::string obj = test::slurp(dir / "out.obj");
    EXPECT_TRUE(obj.starts_with("# generated by meshstream\nmtllib out.mtl\nv ")) << obj;
    // Faces in input order, a usemtl where the material changes (12 statements in the input, 4 changes).
    size_t usemtl = 0;
    for (size_t at = obj.find("usemtl "); at != std::string::npos; at = obj.find("usemtl ", at + 1)) ++usemtl;
    EXPECT_EQ(usemtl, 4u);
    EXPECT_NE(obj.find("usemtl mtl3\nf 1//1 2//2 3//3\n"), std::string::npos) << obj;
    EXPECT_TRUE(notes.empty());

    // A texture that was not there when read: named as the input named it, with a note.
    convert_all(fixture("obj/cube_mtllib_after_g.obj"), dir / "g.obj", {}, uint64_t{256} << 20, 1000, &notes);
    EXPECT_NE(test::slurp(dir / "g.mtl").find("\nmap_Kd missing_texture.png\n"), std::string::npos);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], dir / "g.obj" +
                            ": texture 'missing_texture.png' of material 'MyMaterial' was not read with the "
                            "input: g.mtl names it as the input did, and it is not copied");
}

// The side files never replace a file that is not the output's own: an .mtl of that name is
// refused unless the OBJ being replaced uses it, and a texture name taken by other bytes gets
// a number. A file with the very same bytes (the input's texture, in the same directory) is
// used as it is, not written again.
TEST(ObjWriter, SideFilesNeverOverwriteOtherFiles) {
    TempDir dir;
    test::spit(dir / "out.mtl", "newmtl someone_elses\n");
    try {
        convert_all(fixture("obj/cube_usemtl.obj"), dir / "out.obj");
        ADD_FAILURE() << "wrote over out.mtl";
    } catch (const io::Error& e) {
        EXPECT_EQ(std::string(e.what()), dir / "out.obj" + ": its material library would replace " + dir / "out.mtl" +
                                             ", which exists but belongs to no earlier " + dir / "out.obj" +
                                             " (another model's materials?): move it or choose another name");
    }
    test::spit(dir / "out.obj", "# mtllib out.mtl\nv 0 0 0\n");  // an OBJ that does not use it
    EXPECT_THROW(convert_all(fixture("obj/cube_usemtl.obj"), dir / "out.obj"), io::Error);
    EXPECT_EQ(test::slurp(dir / "out.mtl"), "newmtl someone_elses\n");
    EXPECT_EQ(test::slurp(dir / "out.obj"), "# mtllib out.mtl\nv 0 0 0\n");
    EXPECT_EQ(sorted(dir.entries()), (std::vector<std::string>{"out.mtl", "out.obj"}));

    // An earlier output of the same name is replaced as a whole.
    TempDir d2;
    convert_all(fixture("obj/cube_usemtl.obj"), d2 / "out.obj");
    convert_all(fixture("obj/cube_mtllib_after_g.obj"), d2 / "out.obj");
    EXPECT_NE(test::slurp(d2 / "out.mtl").find("newmtl MyMaterial"), std::string::npos);

    // Other bytes under the texture's name: a numbered name.
    TempDir d3;
    test::spit(d3 / "checker.png", "not this one");
    test::spit(d3 / "checker_2.png", "nor this one");
    convert_all(fixture("obj/cube_usemtl.obj"), d3 / "out.obj");
    EXPECT_EQ(test::slurp(d3 / "checker.png"), "not this one");
    EXPECT_EQ(test::slurp(d3 / "checker_2.png"), "nor this one");
    EXPECT_TRUE(test::slurp(d3 / "checker_3.png") == test::slurp(fixture("obj/checker.png")));
    EXPECT_NE(test::slurp(d3 / "out.mtl").find("map_Kd checker_3.png\n"), std::string::npos);
    EXPECT_EQ(read_mesh(d3 / "out.obj").header.materials[0].texture->uri, "checker_3.png");

    // Written beside its input: the input's files stay as they are, the texture is shared.
    TempDir d4;
    for (const char* name : {"cube_usemtl.obj", "cube_usemtl.mtl", "checker.png"})
        test::spit(d4 / name, test::slurp(fixture(std::string("obj/") + name)));
    struct stat before;
    ASSERT_EQ(::stat((d4 / "checker.png").c_str(), &before), 0);
    convert_all(d4 / "cube_usemtl.obj", d4 / "copy.obj");
    struct stat after;
    ASSERT_EQ(::stat((d4 / "checker.png").c_str(), &after), 0);
    EXPECT_EQ(before.st_ino, after.st_ino);  // not written again
    EXPECT_EQ(sorted(d4.entries()),
              (std::vector<std::string>{"checker.png", "copy.mtl", "copy.obj", "cube_usemtl.mtl", "cube_usemtl.obj"}));
    EXPECT_TRUE(test::slurp(d4 / "cube_usemtl.mtl") == test::slurp(fixture("obj/cube_usemtl.mtl")));
    EXPECT_NE(test::slurp(d4 / "copy.mtl").find("map_Kd checker.png\n"), std::string::npos);
}

// Names from other formats may be empty, repeat, or hold line breaks; texture names may be
// paths, data URIs or nothing usable.
TEST(ObjWriter, MaterialAndTextureNamesAreMadeSafe) {
    TempDir dir;
    io::WriteOptions wo;
    wo.channels.material = true;
    std::vector<std::byte> png(8);
    std::memcpy(png.data(), "\x89PNG\r\n\x1a\n", 8);
    auto material = [&](std::string name, std::string uri) {
        io::Material m;
        m.name = std::move(name);
        if (!uri.empty()) m.texture = io::Texture{uri, "image/png", png};
        return m;
    };
    wo.materials = {material("", ""), material("a\nb", "../../etc/passwd"), material("a\nb", "data:image/png"),
                    material("  ", "C:\\textures\\wood grain.png")};
    io::Output out = io::open_output(dir / "m.obj", {}, wo);
    io::TriangleChunk chunk(4, wo.channels);
    for (uint32_t i = 0; i < 4; ++i) {
        const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, float(i)};
        chunk.push(tri);
        *chunk.material_at(i) = i;
    }
    out.write(chunk);
    out.finish();
    EXPECT_EQ(sorted(dir.entries()),
              (std::vector<std::string>{"m.mtl", "m.obj", "m_texture2.png", "passwd", "wood_grain.png"}));
    const std::string mtl = test::slurp(dir / "m.mtl");
    for (const char* line : {"newmtl material_0\n", "newmtl a_b\n", "newmtl a_b_2\n", "newmtl material_3\n",
                             "map_Kd passwd\n", "map_Kd m_texture2.png\n", "map_Kd wood_grain.png\n"})
        EXPECT_NE(mtl.find(line), std::string::npos) << line << mtl;
    Mesh m = read_mesh(dir / "m.obj");
    EXPECT_EQ(m.material, (std::vector<std::string>{"material_0", "a_b", "a_b_2", "material_3"}));
}

namespace {

struct CliRun {
    int code;
    std::string err;
};

CliRun run_cli(const std::string& args, const std::string& dir, const std::string& prefix = {}) {
    const std::string cmd = prefix + std::string(MESHSTREAM_BINARY) + " " + args + " 2> " + dir + "/err.txt";
    const int rc = std::system(cmd.c_str());
    CliRun r{WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, test::slurp(dir + "/err.txt")};
    std::filesystem::remove(dir + "/err.txt");
    return r;
}

std::vector<std::string> entries_of(const std::string& dir) {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(dir)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

// On stdout there is nothing beside the output: materials are usemtl names only, and the
// command says so.
TEST(ObjCli, StdoutHasNoSideFilesAndSaysWhatWasDropped) {
    TempDir dir;
    CliRun r = run_cli("convert " + fixture("obj/cube_usemtl.obj") + " - --to obj > " + dir / "out.txt", dir.path());
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: <stdout>: materials are written as 'usemtl' names only: their colours and textures "
                         "need an .mtl file beside the output, which a stream cannot have"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
    const std::string text = test::slurp(dir / "out.txt");
    EXPECT_EQ(text.find("mtllib"), std::string::npos);
    EXPECT_NE(text.find("usemtl mtl2\n"), std::string::npos);
    test::spit(dir / "out.obj", text);
    EXPECT_EQ(read_mesh(dir / "out.obj").material, reference_of(fixture("obj/cube_usemtl.obj")).material);
}

// A file-size limit fails a write as a full disk does. Whichever file fails (a large texture,
// or the OBJ after its texture and .mtl were written out), nothing is left: the side files are
// renamed only once every file is complete.
TEST(ObjCli, AFailedWriteLeavesNoSideFiles) {
    TempDir dir;
    std::string big(300 << 10, '\0');
    for (size_t i = 0; i < big.size(); ++i) big[i] = char((i * 7919) >> 3);
    test::spit(dir / "big.png", big);
    test::spit(dir / "small.png", test::slurp(fixture("obj/checker.png")));
    test::spit(dir / "big.mtl", "newmtl m\nmap_Kd big.png\n");
    test::spit(dir / "small.mtl", "newmtl m\nmap_Kd small.png\n");
    // 1200 separate triangles with long coordinates: about 170 KB of OBJ, while the welder's
    // temporary files (24 bytes a corner) stay under the limit.
    std::string soup;
    for (int t = 0; t < 1200; ++t) {
        for (int k = 0; k < 3; ++k) {
            soup += 'v';
            for (int a = 0; a < 3; ++a) {
                soup += ' ';
                io::append_number(soup, float(3 * t + k + a) * 1.3e-5f / 7.0f);
            }
            soup += '\n';
        }
        soup += "f -3 -2 -1\n";
    }
    test::spit(dir / "big_texture.obj", "mtllib big.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    test::spit(dir / "big_obj.obj", "mtllib small.mtl\nusemtl m\n" + soup);
    for (const char* input : {"big_texture.obj", "big_obj.obj"}) {
        SCOPED_TRACE(input);
        std::filesystem::create_directory(dir / "o");
        CliRun r =
            run_cli("convert " + dir / input + " " + dir / "o/out.obj", dir.path(), "ulimit -f 256; ");  // 128 KiB
        EXPECT_EQ(r.code, 1) << r.err;
        EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
        EXPECT_TRUE(std::filesystem::is_empty(dir / "o"));
        std::filesystem::remove_all(dir / "o");
    }
    // Without the limit both work.
    std::filesystem::create_directory(dir / "o");
    EXPECT_EQ(run_cli("convert " + dir / "big_obj.obj" + " " + dir / "o/out.obj", dir.path()).code, 0);
    EXPECT_EQ(entries_of(dir / "o"), (std::vector<std::string>{"out.mtl", "out.obj", "small.png"}));
    EXPECT_GT(std::filesystem::file_size(dir / "o/out.obj"), uint64_t{128} << 10);
}

TEST(ObjFormat, KeepsNormalsRgbColourOneUvSetAndMaterials) {
    io::Channels in;
    in.normal = true;
    in.color = io::ColorFormat{io::ScalarType::kUInt8, true};
    in.uv_sets = 2;
    in.material = true;
    in.vertex_id = true;
    in.vertex_scalars = {{"intensity", io::ScalarType::kFloat32}};
    io::Channels kept = io::writable_channels(io::kObjFormat, in, {});
    EXPECT_TRUE(kept.normal);
    ASSERT_TRUE(kept.color.has_value());
    EXPECT_EQ(*kept.color, (io::ColorFormat{io::ScalarType::kUInt8, false}));
    EXPECT_EQ(kept.uv_sets, 1);
    EXPECT_TRUE(kept.material);
    EXPECT_EQ(io::describe_missing(in, kept),
              "colour alpha, texture coordinate sets past 1, vertex property 'intensity'");
}

// Colours through PLY and back, value for value: OBJ's float colours as PLY float properties,
// PLY's uchar colours as OBJ floats (value / 255, which reads back to the same byte).
TEST(ObjRoundTrip, ColoursSurviveObjToPlyAndPlyToObj) {
    TempDir dir;
    // PLY keeps every channel an OBJ has (normals, texture coordinates, colour), and the seams.
    Mesh obj = read_mesh(fixture("obj/cube_with_vertexcolors.obj"));
    convert_all(fixture("obj/cube_with_vertexcolors.obj"), dir / "c.ply");
    convert_all(dir / "c.ply", dir / "c.obj");
    Mesh back = read_mesh(dir / "c.obj");
    expect_same_mesh(obj, back);
    expect_same_vertices(obj.ids, back.ids);

    Mesh ply = read_mesh(fixture("ply/cactus_vcolor.binary_le.ply"));
    ASSERT_EQ(ply.header.channels.color->type, io::ScalarType::kUInt8);
    convert_all(fixture("ply/cactus_vcolor.binary_le.ply"), dir / "cactus.obj");
    Mesh as_obj = read_mesh(dir / "cactus.obj");
    EXPECT_TRUE(as_obj.rgba == ply.rgba);
    expect_same_vertices(ply.ids, as_obj.ids);
    convert_all(dir / "cactus.obj", dir / "cactus.ply", "ply");
    EXPECT_TRUE(test::read_soup(dir / "cactus.ply").rgb ==
                test::read_soup(fixture("ply/cactus_vcolor.binary_le.ply")).rgb);
}

// With a budget this small the position, texture coordinate and normal tables all spill and
// the corner ids work in their smallest table: the same triangles, values and output.
TEST(ObjMemory, TinyBudgetSpillsEveryTableWithTheSameResult) {
    TempDir dir;
    const int n = 120;
    std::string text;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            text += "v ";
            io::append_number(text, float(i) * 0.1f);
            text += ' ';
            io::append_number(text, float(j) * 0.3f);
            text += ' ';
            io::append_number(text, float((i * 7919 + j * 104729) % 1000) * 0.001f);
            text += "\nvt ";
            io::append_number(text, float(i) / n);
            text += ' ';
            io::append_number(text, float(j) / n);
            text += '\n';
        }
    for (int q = 0; q < (n - 1) * (n - 1); ++q) {  // one normal per quad: every vertex is on seams
        text += "vn ";
        io::append_number(text, float(q % 17) / 17.0f);
        text += " 0 1\n";
    }
    int q = 0;
    for (int i = 0; i + 1 < n; ++i)
        for (int j = 0; j + 1 < n; ++j, ++q) {
            const int a = n * i + j + 1;
            for (int c : {a, a + n, a + n + 1, a + 1})
                text +=
                    (c == a ? "f " : " ") + std::to_string(c) + "/" + std::to_string(c) + "/" + std::to_string(q + 1);
            text += '\n';
        }
    test::spit(dir / "grid.obj", text);
    io::ReadOptions tiny;
    tiny.memory_budget_bytes = 128 << 10;
    Mesh memory = read_mesh(dir / "grid.obj");
    Mesh spilled = read_mesh(dir / "grid.obj", 1000, tiny);
    ASSERT_EQ(memory.triangles(), size_t{2} * (n - 1) * (n - 1));
    expect_same_mesh(memory, spilled);
    expect_same_vertices(memory.ids, spilled.ids);
    convert_all(dir / "grid.obj", dir / "memory.obj");
    convert_all(dir / "grid.obj", dir / "tiny.obj", {}, 128 << 10);
    EXPECT_TRUE(test::slurp(dir / "tiny.obj") == test::slurp(dir / "memory.obj"));
    expect_same_mesh(read_mesh(dir / "memory.obj"), memory);
}

// The reader lists the MTL files and images it read; an output whose .mtl would replace one
// of them is refused by the command before anything is written.
TEST(ObjCli, AnOutputLibraryOverAnInputsLibraryIsRefused) {
    EXPECT_EQ(read_mesh(fixture("obj/cube_usemtl.obj")).header.side_files,
              (std::vector<std::string>{fixture("obj/cube_usemtl.mtl"), fixture("obj/checker.png")}));
    TempDir dir;
    for (const char* name : {"cube_usemtl.obj", "cube_usemtl.mtl", "checker.png"})
        test::spit(dir / name, test::slurp(fixture(std::string("obj/") + name)));
    CliRun r = run_cli("convert " + dir / "cube_usemtl.obj" + " " + dir / "cube_usemtl.obj.gz", dir.path());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("its side file " + dir / "cube_usemtl.mtl" + " would overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(entries_of(dir.path()), (std::vector<std::string>{"checker.png", "cube_usemtl.mtl", "cube_usemtl.obj"}));
    EXPECT_TRUE(test::slurp(dir / "cube_usemtl.mtl") == test::slurp(fixture("obj/cube_usemtl.mtl")));
}
