// Tests of io::read_indexed: a whole file as vertices + indices + channels, welded as the
// whole-mesh writers weld, seams kept, materials and counts from the file.
#include "io/read_indexed.hpp"

#include "io/error.hpp"
#include "io/format.hpp"
#include "io/mesh_index.hpp"

#include "indexed_test_util.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

using namespace meshstream;
using meshstream::test::fixture;
using meshstream::test::read_soup;
using meshstream::test::spit;
using meshstream::test::TempDir;

namespace {

// The mesh's triangles as a soup: 9 floats each, in file order.
std::vector<float> soup_of(const io::IndexedMesh& mesh) {
    std::vector<float> xyz;
    for (const uint32_t v : mesh.indices)
        for (int i = 0; i < 3; ++i) xyz.push_back(mesh.positions[3 * size_t{v} + i]);
    return xyz;
}

// What read_indexed gave before PLY files kept their own indices, and still gives for every
// other format: the file's soup welded by io::MeshIndexer on its vertex ids.
io::IndexedMesh welded_soup(const std::string& path) {
    io::Input in = io::open_input(path, {}, {});
    const io::Channels channels = io::ReadOptions{}.channels.of(in.reader->header().channels);
    io::MeshIndexer indexer(path, "an indexed mesh", channels, false);
    io::TriangleChunk chunk(1000, channels);
    while (in.reader->next(chunk)) indexer.add(chunk);
    return indexer.take();
}

}  // namespace

TEST(ReadIndexed, PlyFilesGiveTheTrianglesOfTheirSoupWithTheirOwnVerticesInFileOrder) {
    // Every PLY fixture (binary both ways, ASCII, gzipped, polygons, a point cloud, colours,
    // normals, uvs, scalars): corner for corner the same positions and attribute records as
    // the welded soup, as many vertices, and the vertices in the file's order.
    size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(fixture("ply"))) {
        const std::string path = entry.path().string();
        SCOPED_TRACE(path);
        ++files;
        const io::IndexedFile f = io::read_indexed(path);
        const io::IndexedMesh w = welded_soup(path);
        ASSERT_EQ(f.mesh.triangle_count(), w.triangle_count());
        EXPECT_EQ(f.mesh.vertex_count(), w.vertex_count());
        EXPECT_EQ(soup_of(f.mesh), soup_of(w));
        ASSERT_EQ(io::CornerLayout(f.mesh.channels).bytes(), io::CornerLayout(w.channels).bytes());
        const size_t rb = io::CornerLayout(f.mesh.channels).bytes();
        for (size_t c = 0; rb > 0 && c < f.mesh.indices.size(); ++c)
            ASSERT_EQ(std::memcmp(&f.mesh.attributes[rb * f.mesh.indices[c]], &w.attributes[rb * w.indices[c]], rb), 0)
                << "corner " << c;
        // The soup's vertex ids are the file's vertex numbers: the kept vertices are in their order.
        const test::Soup soup = read_soup(path);
        std::vector<uint64_t> id_of(f.mesh.vertex_count(), ~uint64_t{0});
        for (size_t c = 0; c < soup.ids.size(); ++c) id_of[f.mesh.indices[c]] = soup.ids[c];
        for (size_t v = 1; v < id_of.size(); ++v) ASSERT_LT(id_of[v - 1], id_of[v]) << "vertex " << v;
    }
    EXPECT_GE(files, 10u);
}

TEST(ReadIndexed, PlyVerticesNoTriangleUsesAreLeftOutAndTheIndicesFollow) {
    // 5 vertices: 1 is used by no face, 3 only by a face with a NaN coordinate (dropped, as is
    // its NaN vertex 4); a quad and a strip triangulated as the read loop does.
    TempDir dir;
    const std::string path = dir / "holes.ply";
    spit(path,
         "ply\nformat ascii 1.0\nelement vertex 7\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 3\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n9 9 9\n1 0 0\n5 5 5\nnan 0 0\n1 1 0\n0 1 0\n"
         "3 0 2 5\n3 3 4 0\n4 0 2 5 6\n");
    const io::IndexedFile f = io::read_indexed(path);
    EXPECT_EQ(f.non_finite_triangles, 1u);
    ASSERT_EQ(f.mesh.triangle_count(), 3u);
    EXPECT_EQ(f.mesh.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
    EXPECT_EQ(f.mesh.indices[0], 0u);
    EXPECT_EQ(f.mesh.indices[1], 1u);
    EXPECT_EQ(f.mesh.indices[2], 2u);
    std::vector<float> expected = read_soup(path).xyz;  // the NaN triangle (the second) left out
    expected.erase(expected.begin() + 9, expected.begin() + 18);
    EXPECT_EQ(soup_of(f.mesh), expected);
    io::ReadOptions strict;
    strict.strict = true;
    try {
        io::read_indexed(path, strict);
        FAIL() << "no io::Error";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), path);
        EXPECT_NE(e.message().find("triangle 1 has a NaN or infinite coordinate"), std::string::npos) << e.what();
    }
    // Triangle strips with a restart: the strip's triangles, joints left out.
    const std::string strips = dir / "strips.ply";
    spit(strips,
         "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
         "element tristrips 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n2 0 0\n0 1 0\n1 1 0\n2 1 0\n11 3 0 4 1 5 2 -1 0 1 1 3\n");
    const io::IndexedFile s = io::read_indexed(strips);
    EXPECT_EQ(s.mesh.indices, (std::vector<uint32_t>{3, 0, 4, 4, 0, 1, 4, 1, 5, 5, 1, 2}));
    EXPECT_EQ(s.mesh.vertex_count(), 6u);
    // An index past the vertices is the reader's error, with its position.
    const std::string bad = dir / "bad.ply";
    spit(bad,
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    try {
        io::read_indexed(bad);
        FAIL() << "no io::Error";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), bad);
        EXPECT_EQ(e.line(), 13u) << e.what();
        EXPECT_NE(e.message().find("vertex index 7 out of range (3 vertices)"), std::string::npos) << e.what();
    }
}

TEST(ReadIndexed, BinaryStlWeldsToItsVerticesAndKeepsEveryTriangleInOrder) {
    const io::IndexedFile f = io::read_indexed(fixture("cube.bin.stl"));
    EXPECT_EQ(f.format->name, "stl");
    EXPECT_EQ(f.mesh.triangle_count(), 12u);
    EXPECT_EQ(f.mesh.vertex_count(), 8u);
    EXPECT_FALSE(f.mesh.channels.normal);
    EXPECT_EQ(f.mesh.attributes.size(), 0u);
    EXPECT_EQ(soup_of(f.mesh), read_soup(fixture("cube.bin.stl")).xyz);
    EXPECT_EQ(f.non_finite_triangles, 0u);
}

TEST(ReadIndexed, PlyKeepsItsVerticesNormalsAndTextureCoordinatesApartAtSeams) {
    // 24 vertices: each cube corner three times, with the normal and UV of its face.
    const io::IndexedFile f = io::read_indexed(fixture("ply/cube_uv.ply"));
    EXPECT_EQ(f.mesh.triangle_count(), 12u);
    EXPECT_EQ(f.mesh.vertex_count(), 24u);
    EXPECT_TRUE(f.mesh.channels.normal);
    EXPECT_EQ(f.mesh.channels.uv_sets, 1);
    std::vector<uint32_t> all(f.mesh.vertex_count());
    for (uint32_t v = 0; v < all.size(); ++v) all[v] = v;
    const io::VertexValues values = f.mesh.values(all);
    ASSERT_EQ(values.normals.size(), 3 * all.size());
    ASSERT_EQ(values.uvs.size(), 1u);
    std::set<std::vector<float>> corners;  // position + normal + uv: all distinct
    for (const uint32_t v : all) {
        std::vector<float> key(f.mesh.positions.begin() + 3 * v, f.mesh.positions.begin() + 3 * v + 3);
        key.insert(key.end(), values.normals.begin() + 3 * v, values.normals.begin() + 3 * v + 3);
        key.insert(key.end(), values.uvs[0].begin() + 2 * v, values.uvs[0].begin() + 2 * v + 2);
        corners.insert(key);
        // Each normal is one of the six axis directions.
        EXPECT_NEAR(
            std::abs(values.normals[3 * v]) + std::abs(values.normals[3 * v + 1]) + std::abs(values.normals[3 * v + 2]),
            1.0f, 1e-5f);
    }
    EXPECT_EQ(corners.size(), 24u);
    // Asking for positions only drops the channels; the PLY's own vertices (its vertex ids)
    // stay the vertices.
    io::ReadOptions positions;
    positions.channels = io::ChannelKinds::none();
    const io::IndexedFile bare = io::read_indexed(fixture("ply/cube_uv.ply"), positions);
    EXPECT_FALSE(bare.mesh.channels.normal);
    EXPECT_EQ(bare.mesh.channels.uv_sets, 0);
    EXPECT_EQ(bare.mesh.triangle_count(), 12u);
    EXPECT_EQ(bare.mesh.vertex_count(), 24u);
    EXPECT_EQ(bare.mesh.attributes.size(), 0u);
}

TEST(ReadIndexed, ObjMaterialsIndexTheHeadersTable) {
    const io::IndexedFile f = io::read_indexed(fixture("obj/cube_usemtl.obj"));
    ASSERT_TRUE(f.mesh.channels.material);
    ASSERT_EQ(f.mesh.materials.size(), f.mesh.triangle_count());
    std::set<std::string> used;
    for (const uint32_t m : f.mesh.materials) {
        ASSERT_LT(m, f.header.materials.size());
        used.insert(f.header.materials[m].name);
    }
    EXPECT_TRUE(used.count("mtl"));
    EXPECT_TRUE(used.count("mtl3"));  // used without a definition: still in the table
    EXPECT_EQ(f.mesh.triangle_count(), 12u);
}

TEST(ReadIndexed, NonFiniteTrianglesAreDroppedAndCountedOrRefusedUnderStrict) {
    TempDir dir;
    const std::string path = dir / "nan.stl";
    spit(path,
         "solid t\n"
         "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
         "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
         "facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\n"
         "endsolid t\n");
    const io::IndexedFile f = io::read_indexed(path);
    EXPECT_EQ(f.mesh.triangle_count(), 2u);
    EXPECT_EQ(f.mesh.vertex_count(), 4u);
    EXPECT_EQ(f.non_finite_triangles, 1u);
    EXPECT_EQ(f.non_finite_attributes, 0u);
    // A NaN normal is kept as 0 and counted.
    const std::string normals = dir / "nan_normal.ply";
    spit(normals,
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
         "property float nx\nproperty float ny\nproperty float nz\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n"
         "0 0 0 0 0 1\n1 0 0 nan 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
    const io::IndexedFile n = io::read_indexed(normals);
    EXPECT_EQ(n.mesh.triangle_count(), 1u);
    EXPECT_EQ(n.non_finite_attributes, 1u);
    io::ReadOptions strict;
    strict.strict = true;
    try {
        io::read_indexed(path, strict);
        FAIL() << "no io::Error";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), path);
        EXPECT_NE(e.message().find("triangle 1 has a NaN or infinite coordinate"), std::string::npos) << e.what();
    }
}

TEST(ReadIndexed, ErrorsNameTheFileAndPosition) {
    TempDir dir;
    const std::string missing = dir / "missing.ply";
    EXPECT_THROW(io::read_indexed(missing), io::Error);
    const std::string cut = dir / "cut.stl";
    const std::string whole = meshstream::test::slurp(fixture("cube.bin.stl"));
    spit(cut, whole.substr(0, whole.size() - 10));
    try {
        io::read_indexed(cut);
        FAIL() << "no io::Error";
    } catch (const io::Error& e) {
        EXPECT_EQ(e.file(), cut);
        EXPECT_NE(e.byte_offset(), io::Error::kNoOffset) << e.what();
    }
}
