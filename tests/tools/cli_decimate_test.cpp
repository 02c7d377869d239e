// `meshstream decimate` on generated meshes through the binaries (MESHSTREAM_BINARY,
// MESHSTREAM_GEN_BINARY): properties that need a mesh larger and more twisted than the
// fixtures, such as the topology kept through small buffers.
#include "compare/metro.hpp"
#include "io/format.hpp"
#include "tools/cli_util.hpp"
#include "tools/mesh_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <set>
#include <string>

namespace {

using cli_test::CliRun;
using cli_test::edges_of;
using cli_test::run;
using cli_test::TempDir;
using namespace meshstream;

// Triangles whose three corners (as positions, in any order) another triangle also has.
size_t duplicate_triangles(const std::string& path) {
    io::Input in = io::open_input(path);
    io::TriangleChunk chunk;
    std::set<std::array<std::array<float, 3>, 3>> seen;
    size_t duplicates = 0;
    while (in.reader->next(chunk))
        for (size_t t = 0; t < chunk.size(); ++t) {
            std::array<std::array<float, 3>, 3> corners;
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a) corners[k][a] = chunk.xyz()[9 * t + 3 * k + a];
            std::sort(corners.begin(), corners.end());
            duplicates += !seen.insert(corners).second;
        }
    return duplicates;
}

}  // namespace

TEST(CliDecimate, ATetrahedronHangingFromANonManifoldVertexIsNotFlattened) {
    // The 200 k generated mesh has one vertex where two fans touch. The tetrahedron check
    // counted all of that vertex's faces, so a tetrahedron in one of its fans was collapsed
    // into two triangles back to back (one such pair at 1 %, 2 % and 5 %).
    TempDir dir;
    const std::string mesh = dir / "g.stl";
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q -n 200000 " + mesh).c_str()), 0);
    ASSERT_EQ(duplicate_triangles(mesh), 0u);
    for (const char* ratio : {"0.01", "0.05"}) {
        CliRun r = run("decimate -r " + std::string(ratio) + " " + mesh + " " + dir / "out.stl");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_EQ(r.err.find("force-written"), std::string::npos) << r.err;
        EXPECT_EQ(duplicate_triangles(dir / "out.stl"), 0u) << ratio;
    }
}

TEST(CliDecimate, SmallBuffersAddNoNonManifoldEdges) {
    // A collapse into a written (P_out) vertex q could give q an edge to another written
    // vertex that the written mesh already held: the output then had edges with four
    // triangles (53 on this mesh at 1 % through a 2 000-triangle buffer, where its input has
    // 4 non-manifold edges of its own, from marching-cubes vertices rounded onto one position).
    TempDir dir;
    const std::string mesh = dir / "g.stl";
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q -n 100000 " + mesh).c_str()), 0);
    const compare::EdgeCounts in = edges_of(mesh);
    // (--sort never: the buffer of 1 000 is too small for the mesh at 1 %, which --sort auto
    // would meet by sorting first, and it is the forced writes that are tested here.)
    for (const char* options :
         {"-r 0.01 --buffer 2000", "-r 0.1 --buffer 3000", "-r 0.01 --buffer 1000 --sort never"}) {
        CliRun r = run("decimate " + std::string(options) + " " + mesh + " " + dir / "out.stl");
        ASSERT_EQ(r.code, 0) << options << ": " << r.err;
        const compare::EdgeCounts out = edges_of(dir / "out.stl");
        // Closed input stays closed and gains no non-manifold edge, except where vertices were
        // evicted (the 1 000-triangle buffer is too small for this mesh at 1 %): a triangle read
        // later at an evicted vertex's position starts a second vertex there, which leaves
        // cracks and may put a triangle back to back with a written one. The warning says both.
        if (r.err.find("evicted") == std::string::npos) {
            EXPECT_LE(out.non_manifold_edges, in.non_manifold_edges) << options;
            EXPECT_EQ(out.boundary_edges, 0u) << options;
        } else {
            EXPECT_NE(r.err.find("back to back"), std::string::npos) << r.err;
            EXPECT_NE(r.err.find("the output has cracks there"), std::string::npos) << r.err;
        }
    }
}

TEST(CliDecimate, ATargetOfZeroTrianglesIsSaid) {
    TempDir dir;
    const std::string in = dir / "one.stl";
    std::ofstream(in) << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                         "endloop\nendfacet\nendsolid t\n";
    CliRun r = run("decimate -r 0.1 " + in + " " + dir / "out.stl");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: the target rounds to 0 triangles (1 in): the output is empty; give a larger --ratio "
                         "or --target"),
              std::string::npos)
        << r.err;
}

TEST(CliDecimate, ACadAssemblyReachesTheTarget) {
    // Hundreds of coarse CAD parts, where most collapses are refused: a stall rule that gave up
    // after a few refusals in a row stopped at 49 300 triangles of a target of 11 033, with a
    // warning that nothing more could be decimated.
    TempDir dir;
    const std::string in = std::string(MESHSTREAM_FIXTURES_DIR) + "/gltf/2CylinderEngine_draco/2CylinderEngine.gltf";
    // (The target is odd: one triangle over it is the documented outcome when no boundary edge
    // can be collapsed at the end, as with seed 2.)
    for (const char* seed : {"1", "2"}) {
        CliRun r = run("decimate -r 0.1 --seed " + std::string(seed) + " " + in + " " + dir / "out.stl");
        ASSERT_EQ(r.code, 0) << r.err;
        const uint64_t out = *io::open_input(dir / "out.stl").reader->triangle_count();
        EXPECT_TRUE(out == 11033u || out == 11034u) << "seed " << seed << ": " << out << " triangles; " << r.err;
        EXPECT_EQ(r.err.find("too little left that could be decimated"), std::string::npos) << r.err;
    }
}

// --target was turned into target / header count once: skipped input triangles (degenerate,
// non-finite) then left the output short even where they came first (6 266 of 8 000 for a grid
// after 40 000 degenerate triangles). The ratio now follows what the input can still hold;
// skipped triangles that come last still leave it short, and the warning says why.
TEST(CliDecimate, ATargetIsReachedWhateverSkippedTrianglesComeFirstOrBetween) {
    TempDir dir;
    std::ifstream file(std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(file)), {});
    const uint32_t n = 69451;
    ASSERT_EQ(bytes.size(), 84 + 50 * size_t{n});
    std::string degenerate(50, '\0');  // all corners at the origin
    auto write = [&](const std::string& name, auto&& place) {
        std::string body;
        uint32_t count = 0;
        for (uint32_t t = 0; t < n; ++t) {
            count += place(body, t);
            body += bytes.substr(84 + 50 * size_t{t}, 50);
            ++count;
        }
        count += place(body, n);
        std::string head = bytes.substr(0, 80);
        head.append(reinterpret_cast<const char*>(&count), 4);
        std::ofstream(dir / name, std::ios::binary) << head << body;
    };
    write("head.stl", [&](std::string& body, uint32_t t) -> uint32_t {
        if (t != 0) return 0;
        for (int i = 0; i < 30000; ++i) body += degenerate;
        return 30000;
    });
    write("between.stl", [&](std::string& body, uint32_t t) -> uint32_t {
        if (t % 2 == 0 || t == n) return 0;
        body += degenerate;
        return 1;
    });
    write("tail.stl", [&](std::string& body, uint32_t t) -> uint32_t {
        if (t != n) return 0;
        for (int i = 0; i < 30000; ++i) body += degenerate;
        return 30000;
    });
    CliRun clean = run("decimate --target 6945 --buffer 2000 " + std::string(MESHSTREAM_FIXTURES_DIR) +
                       "/bunny_from_draco.bin.stl " + dir / "clean.stl");
    ASSERT_EQ(clean.code, 0) << clean.err;
    const uint64_t landed = io::open_input(dir / "clean.stl").reader->triangle_count().value();
    for (const char* name : {"head.stl", "between.stl"}) {
        CliRun r = run("decimate --target 6945 --buffer 2000 " + dir / name + " " + dir / "out.stl");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_EQ(io::open_input(dir / "out.stl").reader->triangle_count(), landed) << name << ": " << r.err;
    }
    CliRun tail = run("decimate --target 6945 --buffer 2000 " + dir / "tail.stl" + " " + dir / "out.stl");
    ASSERT_EQ(tail.code, 0) << tail.err;
    EXPECT_LT(io::open_input(dir / "out.stl").reader->triangle_count().value(), 6945u);
    EXPECT_NE(tail.err.find("(30000 input triangles were skipped (above), most of them after the part before them had "
                            "been decimated for the larger input the header promised; `meshstream convert --clean` "
                            "drops them into a copy that lands on the target)"),
              std::string::npos)
        << tail.err;
}

TEST(CliDecimate, AnOddTargetMissedByOneSaysWhy) {
    // The bunny's holes shrink to three edges and close (collapse.hpp, closed_hole), so at 71
    // triangles it is closed: the output has one triangle over the odd target, and the warning
    // says why without claiming more. (Before holes of three edges closed, 15 boundary edges
    // were left at 70.)
    TempDir dir;
    const std::string in = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";
    CliRun r = run("decimate --target 71 " + in + " " + dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(io::open_input(dir / "out.stl").reader->triangle_count(), 72u);
    EXPECT_NE(r.err.find("output has 72 triangles instead of the target 71 (a collapse removes two triangles, and no "
                         "boundary edge could be collapsed to remove the odd one)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(edges_of(dir / "out.stl").boundary_edges, 0u);
}

TEST(CliDecimate, ATargetMissedBecauseNoCollapseIsAllowedSaysSo) {
    // A closed octahedron at 10 % (target 1) comes down to a tetrahedron, which no collapse may
    // reduce. The warning used to say "too little left that could be decimated".
    TempDir dir;
    const int corners[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    const char* points[6] = {"1 0 0", "-1 0 0", "0 1 0", "0 -1 0", "0 0 1", "0 0 -1"};
    std::string stl = "solid o\n";
    for (const auto& f : corners) {
        stl += "facet normal 0 0 0\nouter loop\n";
        for (const int c : f) stl += std::string("vertex ") + points[c] + "\n";
        stl += "endloop\nendfacet\n";
    }
    std::ofstream(dir / "oct.stl") << stl << "endsolid o\n";
    CliRun r = run("decimate -r 0.1 " + dir / "oct.stl" + " " + dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(*io::open_input(dir / "out.stl").reader->triangle_count(), 4u);
    EXPECT_NE(r.err.find("output has 4 triangles instead of the target 1 (no allowed collapse is left: each would fold "
                         "a face over or change the topology, or move a vertex that must stay, as on a non-manifold "
                         "edge)"),
              std::string::npos)
        << r.err;
}

TEST(CliDecimate, AClosedElephantLandsOnItsTargetAtOnePercent) {
    // The closed elephant (5 558 triangles) at 1 %: multiple-choice draws stopped at 58–74 of
    // 56 for some vertex orders and seeds; the cheapest-first order reaches it.
    TempDir dir;
    const std::string in = std::string(MESHSTREAM_FIXTURES_DIR) + "/drc/elephant_normals_sequential_cl0.drc";
    for (const char* seed : {"1", "2"}) {
        CliRun r = run("decimate -r 0.01 --seed " + std::string(seed) + " " + in + " " + dir / "out.stl");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_EQ(*io::open_input(dir / "out.stl").reader->triangle_count(), 56u) << r.err;
    }
}

TEST(CliDecimate, AStallInALargeBufferAtTheEndSaysSo) {
    // 2CylinderEngine (110 332 triangles in hundreds of CAD parts) cannot reach 1 % (1 103):
    // it stalls with several thousand faces left, too many to scan (5 608 with the
    // cheapest-first order; multiple-choice draws stopped at 6 788).
    TempDir dir;
    const std::string in = std::string(MESHSTREAM_FIXTURES_DIR) + "/gltf/2CylinderEngine_draco/2CylinderEngine.gltf";
    CliRun r = run("decimate -r 0.01 --seed 1 " + in + " " + dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    const uint64_t out = *io::open_input(dir / "out.stl").reader->triangle_count();
    EXPECT_LT(out, 7000u) << r.err;
    EXPECT_NE(r.err.find("instead of the target 1103"), std::string::npos) << r.err;
}

TEST(CliDecimate, ForcedWritesDegradeGracefully) {
    // The bunny sorted along y has width 933 and needs a buffer of about 1 100 at 1 %. Through
    // a buffer too small (1 174, when it needed 1 380), forced writes used to pick random faces:
    // written vertices (which never collapse) scattered over the buffer, every later round
    // stalled too, and 44 118 triangles were force-written, leaving 46 499 of a target of 695.
    // Forced writes now extend P_out: through 1 000, 540 forced writes leave 1 363.
    TempDir dir;
    const std::string in = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";
    ASSERT_EQ(run("sort --axis y " + in + " " + dir / "y.stl").code, 0);
    CliRun r = run("decimate -r 0.01 --buffer 1000 " + dir / "y.stl" + " " + dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("force-written"), std::string::npos) << r.err;  // still short of room
    const uint64_t out = *io::open_input(dir / "out.stl").reader->triangle_count();
    EXPECT_LT(out, 2 * 695u) << r.err;
    const compare::EdgeCounts e = edges_of(dir / "out.stl");
    EXPECT_EQ(e.non_manifold_edges, 0u);
    EXPECT_LE(e.boundary_edges, 223u);  // the input's own holes, no cracks
}

// The --memory a refused plain glTF output asks for is enough for a closed mesh (the case the
// up-front figure is computed for): the running estimate counted vectors' spare capacity and
// refused 200 k triangles at the 8M it had asked for. A .gltf on stdout counts its base64 copies.
TEST(CliDecimate, TheMemoryAskedForAPlainGltfSuffices) {
    TempDir dir;
    const std::string mesh = dir / "closed.stl";
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q -n 200000 " + mesh).c_str()), 0);
    for (const std::string& out : {dir / "out.glb", std::string("- --to gltf")}) {
        CliRun refused = run("convert --no-draco --memory 1M " + mesh + " " + out + " > " + dir / "stdout");
        ASSERT_EQ(refused.code, 1) << refused.err;
        const size_t at = refused.err.find("give --memory ");
        ASSERT_NE(at, std::string::npos) << refused.err;
        const std::string asked = refused.err.substr(at + 14, refused.err.find(' ', at + 14) - at - 14);
        CliRun ok = run("convert --no-draco --memory " + asked + " " + mesh + " " + out + " > " + dir / "stdout");
        EXPECT_EQ(ok.code, 0) << out << " at --memory " << asked << ": " << ok.err;
    }
    // Inline base64 costs: the .gltf on stdout asks for more than the .glb.
    auto asked_for = [&](const std::string& out) {
        CliRun r = run("convert --no-draco --memory 1M " + mesh + " " + out + " > " + dir / "stdout");
        return std::stoi(r.err.substr(r.err.find("give --memory ") + 14));
    };
    EXPECT_GT(asked_for("- --to gltf"), asked_for(dir / "out.glb"));
}

// --target with an input that states no count (ASCII STL, OBJ, PLY): a file is counted in a
// first pass, which the summary names, and comes out as the same mesh as from a binary STL
// copy, which states its count; a pipe is refused (above, CommandLinesThatCannotWork...).
TEST(CliDecimate, TargetCountsAFileThatStatesNoCount) {
    TempDir dir;
    const std::string ascii = std::string(MESHSTREAM_FIXTURES_DIR) + "/gearwheel.ascii.stl";
    const std::string binary = dir / "gear.stl";
    ASSERT_EQ(run("convert " + ascii + " " + binary).code, 0);
    const CliRun counted = run("decimate --target 1000 " + ascii + " " + dir / "a.stl");
    ASSERT_EQ(counted.code, 0) << counted.err;
    EXPECT_NE(counted.err.find("counted 2444 input triangles in a first pass for --target"), std::string::npos)
        << counted.err;
    EXPECT_NE(counted.err.find("triangles in 2444, out 1000 (target 1000"), std::string::npos) << counted.err;
    const CliRun stated = run("decimate --target 1000 " + binary + " " + dir / "b.stl");
    ASSERT_EQ(stated.code, 0) << stated.err;
    EXPECT_EQ(stated.err.find("first pass"), std::string::npos) << stated.err;
    EXPECT_EQ(cli_test::slurp(dir / "a.stl"), cli_test::slurp(dir / "b.stl"));
    // PLY (faces may be polygons, so no triangle count up front) and OBJ.
    const std::string ply = std::string(MESHSTREAM_FIXTURES_DIR) + "/ply/cactus_vcolor.binary_le.ply";
    const CliRun p = run("decimate --target 600 " + ply + " " + dir / "p.stl");
    ASSERT_EQ(p.code, 0) << p.err;
    EXPECT_NE(p.err.find("counted 1236 input triangles in a first pass"), std::string::npos) << p.err;
    EXPECT_NE(p.err.find("out 600 (target 600"), std::string::npos) << p.err;
    const std::string obj = dir / "gear.obj";
    ASSERT_EQ(run("convert " + binary + " " + obj).code, 0);
    const CliRun o = run("decimate --json --target 1000 " + obj + " " + dir / "o.stl > " + dir / "o.json");
    ASSERT_EQ(o.code, 0) << o.err;
    const std::string json = cli_test::slurp(dir / "o.json");
    EXPECT_NE(json.find("\"triangles_out\":1000"), std::string::npos) << json;
    EXPECT_NE(json.find("\"count_pass_seconds\":"), std::string::npos) << json;
    // More than the input holds: said with the counted figure.
    const CliRun over = run("decimate --target 3000 " + ascii + " " + dir / "c.stl");
    EXPECT_EQ(over.code, 2);
    EXPECT_NE(over.err.find("--target 3000 is more than the 2444 triangles of the input"), std::string::npos)
        << over.err;
}
