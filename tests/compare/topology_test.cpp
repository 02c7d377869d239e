// tools/topology: vertex, boundary and non-manifold edge counts against the corpus MANIFEST,
// identical with a budget small enough to spill, and through `meshstream info --topology`.
#include "compare/topology.hpp"

#include "io/format.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

using namespace meshstream;

namespace {

compare::TopologyReport count(const std::string& name, uint64_t budget = uint64_t{64} << 20) {
    io::Input in = io::open_input(std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name);
    compare::TopologyCounter counter(budget, {});
    io::TriangleChunk chunk(1000, in.reader->header().channels);
    while (in.reader->next(chunk)) counter.add(chunk);
    return counter.finish();
}

}  // namespace

TEST(Topology, MatchesTheCorpusManifest) {
    struct Case {
        const char* file;
        bool by_id;
        uint64_t vertices, boundary, non_manifold;
    };
    const Case cases[] = {
        {"ply/cube_uv.ply", true, 24, 24, 0},  // 24 unwelded corner vertices
        // One concave face, a ring: ear clipping covers it once, so the outline and the hole
        // are the 64 boundary edges (the fan it had before folded: 63 and 2 non-manifold).
        {"obj/concave_polygon.obj", true, 64, 64, 0},
        {"obj/WusonOBJ.obj", true, 2117, 412, 0},
        {"obj/regr_3429812.obj", true, 4, 0, 1},
        {"ply/elephant_normals.binary_be.ply", true, 2775, 0, 0},  // closed manifold
        {"bunny_from_draco.bin.stl", false, 34834, 223, 0},
        // Its 56 triangles with a repeated corner add no edges (they made 16 "non-manifold").
        {"Spider_binary.stl", false, 722, 72, 0},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.file);
        compare::TopologyReport r = count(c.file);
        EXPECT_EQ(r.by_vertex_id, c.by_id);
        EXPECT_EQ(r.vertices, c.vertices);
        EXPECT_EQ(r.boundary_edges, c.boundary);
        EXPECT_EQ(r.non_manifold_edges, c.non_manifold);
    }
    // Euler: a closed genus-0 bunny would have V - E + F = 2; the elephant is closed.
    compare::TopologyReport e = count("ply/elephant_normals.binary_be.ply");
    EXPECT_EQ(e.edges * 2, 5558u * 3);
}

TEST(Topology, SpillingGivesTheSameCounts) {
    compare::TopologyReport memory = count("bunny_from_draco.bin.stl");
    compare::TopologyReport spilled = count("bunny_from_draco.bin.stl", 256 << 10);
    EXPECT_EQ(spilled.vertices, memory.vertices);
    EXPECT_EQ(spilled.edges, memory.edges);
    EXPECT_EQ(spilled.boundary_edges, memory.boundary_edges);
    EXPECT_EQ(spilled.non_manifold_edges, memory.non_manifold_edges);
}

TEST(Topology, InfoPrintsIt) {
    std::string cmd =
        std::string(MESHSTREAM_BINARY) + " -q info --topology " + MESHSTREAM_FIXTURES_DIR + "/obj/WusonOBJ.obj.gz";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[256];
    while (fgets(buf, sizeof buf, p)) out += buf;
    EXPECT_EQ(pclose(p), 0);
    EXPECT_NE(out.find("topology:    2117 vertices (welded by vertex id), 5804 edges, 412 boundary, 0 non-manifold"),
              std::string::npos)
        << out;
}
