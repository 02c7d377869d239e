// engine::input_bounds: a PLY's box from its used vertices (read in order) is the box of the
// triangles' corners, which every other input gets from its triangles; unused vertices, NaN
// coordinates and bad indices as the triangles would have them.
#include "engine/files.hpp"

#include "io/error.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <string>

namespace meshstream {
namespace {

// A square (a quad face) at z = 1 and a triangle, with an unused vertex far out between them.
constexpr const char* kPly =
    "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 1\n2 0 1\n2 3 1\n0 3 1\n"
    "100 -100 100\n"
    "-1 0.5 0\n1 0.5 0\n0 1 -2\n"
    "4 0 1 2 3\n3 5 6 7\n";

// The same triangles as an ASCII STL (read triangle by triangle).
constexpr const char* kStl =
    "solid s\n"
    "facet normal 0 0 1\nouter loop\nvertex 0 0 1\nvertex 2 0 1\nvertex 2 3 1\nendloop\nendfacet\n"
    "facet normal 0 0 1\nouter loop\nvertex 0 0 1\nvertex 2 3 1\nvertex 0 3 1\nendloop\nendfacet\n"
    "facet normal 0 0 1\nouter loop\nvertex -1 0.5 0\nvertex 1 0.5 0\nvertex 0 1 -2\nendloop\nendfacet\n"
    "endsolid s\n";

io::Bounds bounds(const std::string& path, uint64_t memory = io::kDefaultMemoryBudget) {
    io::ReadOptions options;
    options.memory_budget_bytes = memory;
    engine::QuietProgress progress;
    return engine::input_bounds(path, "", options, progress);
}

void expect_box(const io::Bounds& b, std::array<float, 3> min, std::array<float, 3> max) {
    for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(b.min[a], min[a]) << "axis " << a;
        EXPECT_EQ(b.max[a], max[a]) << "axis " << a;
    }
}

// The box of kPly's triangles, from the used vertices and (no room for the marks: budget 0)
// from the triangles.
void expect_the_triangles_box(const std::string& ply) {
    for (uint64_t memory : {io::kDefaultMemoryBudget, uint64_t{0}}) {
        SCOPED_TRACE("memory " + std::to_string(memory));
        expect_box(bounds(ply, memory), {-1, 0, -2}, {2, 3, 1});
    }
}

TEST(EngineFiles, APlysBoxIsItsTrianglesCornersNotItsUnusedVertices) {
    test::TempDir dir;
    test::spit(dir / "m.stl", kStl);
    expect_box(bounds(dir / "m.stl"), {-1, 0, -2}, {2, 3, 1});
    test::spit(dir / "m.ply", kPly);
    expect_the_triangles_box(dir / "m.ply");
}

// engine::input_box of kPly and kStl, written in `dir`, with the default options.
engine::InputBox box_of(const test::TempDir& dir, const char* name, bool vertices_will_do) {
    test::spit(dir / "m.ply", kPly);
    test::spit(dir / "m.stl", kStl);
    engine::QuietProgress progress;
    return engine::input_box(dir / name, "", io::ReadOptions{}, progress, vertices_will_do);
}

TEST(EngineFiles, AVertexTablesBytesAreSaidAndNoneForAnStl) {
    // The 8 vertices of kPly, 12 bytes each (x, y, z): what a reader of it needs to hold them.
    test::TempDir dir;
    for (bool vertices : {false, true}) {
        EXPECT_EQ(box_of(dir, "m.ply", vertices).vertex_table_bytes, 8u * 12u);
        EXPECT_EQ(box_of(dir, "m.stl", vertices).vertex_table_bytes, 0u);
    }
}

TEST(EngineFiles, WhereVerticesWillDoAPlysBoxIsAllItsVerticesAndAnStlsItsTriangles) {
    test::TempDir dir;
    const engine::InputBox ply = box_of(dir, "m.ply", true);
    EXPECT_TRUE(ply.of_vertices);
    expect_box(ply.box, {-1, -100, -2}, {100, 3, 100});  // the unused vertex (100, -100, 100) too
    const engine::InputBox stl = box_of(dir, "m.stl", true);
    EXPECT_FALSE(stl.of_vertices);
    expect_box(stl.box, {-1, 0, -2}, {2, 3, 1});
    EXPECT_FALSE(box_of(dir, "m.ply", false).of_vertices);
}

TEST(EngineFiles, APlysNonFiniteCoordinateDecidesNothing) {
    test::TempDir dir;
    std::string ply = kPly;
    ply.replace(ply.find("0 1 -2"), 6, "0 nan -2");
    test::spit(dir / "m.ply", ply);
    expect_the_triangles_box(dir / "m.ply");
}

TEST(EngineFiles, APlysIndexOutOfRangeIsNamedWithItsLine) {
    test::TempDir dir;
    std::string ply = kPly;
    ply.replace(ply.find("3 5 6 7"), 7, "3 5 6 9");
    test::spit(dir / "m.ply", ply);
    for (uint64_t memory : {io::kDefaultMemoryBudget, uint64_t{0}}) {
        try {
            bounds(dir / "m.ply", memory);
            ADD_FAILURE() << "no error with memory " << memory;
        } catch (const io::Error& e) {
            EXPECT_NE(std::string(e.what()).find("vertex index 9 out of range"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("m.ply:19:"), std::string::npos) << e.what();  // the face's line
        }
    }
}

}  // namespace
}  // namespace meshstream
