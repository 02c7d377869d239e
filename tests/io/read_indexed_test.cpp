// Tests of io::read_indexed: a whole file as vertices + indices + channels, welded as the
// whole-mesh writers weld, seams kept, materials and counts from the file.
#include "io/read_indexed.hpp"

#include "io/error.hpp"
#include "io/format.hpp"

#include "indexed_test_util.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
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

}  // namespace

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
