// --memory for the outputs that hold the whole mesh (Draco, glTF), through the `meshstream`
// binary: past the budget the error says how much would do ("give --memory NM or more") for
// every input, STL and PLY (whose faces stand in for its count) up front, and an input of no
// stated count once it is counted; the figure given does (for sort too, whose writer gets a
// quarter of --memory); without --memory the budget is half
// of the memory available (MESHSTREAM_MEMINFO stands in for /proc/meminfo), and --memory wins.
#include "cli_util.hpp"
#include "mesh_files.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <regex>
#include <string>
#include <vector>

namespace {

using namespace cli_test;
using meshstream::test::spit;

// ASCII STL: no count up front.
std::string ascii_stl(const std::vector<float>& tris) {
    std::string s = "solid grid\n";
    for (size_t t = 0; t < tris.size() / 9; ++t) {
        s += "facet normal 0 0 1\nouter loop\n";
        for (int v = 0; v < 3; ++v) {
            s += "vertex";
            for (int a = 0; a < 3; ++a) {
                s += ' ';
                s += std::to_string(tris[9 * t + 3 * v + a]);
            }
            s += "\n";
        }
        s += "endloop\nendfacet\n";
    }
    return s + "endsolid grid\n";
}

// ASCII PLY, every triangle with its own three vertices; `faces` in the header may say more
// than the body holds (the body is never read when the budget is refused up front).
std::string ascii_ply(const std::vector<float>& tris, uint64_t faces) {
    const size_t n = tris.size() / 9;
    std::string s = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(3 * n) +
                    "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
    for (size_t i = 0; i < 3 * n; ++i) {
        for (int a = 0; a < 3; ++a) {
            s += std::to_string(tris[3 * i + a]);
            s += a < 2 ? ' ' : '\n';
        }
    }
    for (size_t t = 0; t < n; ++t) {
        s += '3';
        for (size_t v = 0; v < 3; ++v) {
            s += ' ';
            s += std::to_string(3 * t + v);
        }
        s += '\n';
    }
    return s;
}

// The N of "give --memory NM or more" (0 when the text has none).
uint64_t figure(const std::string& err) {
    std::smatch m;
    return std::regex_search(err, m, std::regex("give --memory ([0-9]+)M or more")) ? std::stoull(m[1]) : 0;
}

TEST(CliMemory, PastTheBudgetTheErrorSaysHowMuchWouldDoForEveryInput) {
    TempDir dir;
    const std::vector<float> tris = grid(24);  // 1152 triangles
    spit(dir / "in.stl", binary_stl(tris));
    spit(dir / "in.ply", ascii_ply(tris, 1152));
    spit(dir / "in_ascii.stl", ascii_stl(tris));
    for (const std::string& in : {std::string("in.stl"), std::string("in.ply"), std::string("in_ascii.stl")})
        for (const std::string cmd : {"convert", "decimate -r 1"})
            for (const char* out : {"out.drc", "out.glb"}) {
                SCOPED_TRACE(cmd + " " + in + " " + out);
                CliRun r = run(cmd + " --memory 64K " + dir / in + " " + dir / out);
                EXPECT_EQ(r.code, 1) << r.err;
                EXPECT_EQ(r.err.rfind("meshstream: error: " + dir / out + ": ", 0), 0u) << r.err;
                // STL and PLY (its 1152 faces) are refused before any triangle is read; the
                // ASCII STL, which states no count, once it is counted.
                EXPECT_NE(r.err.find(in == "in_ascii.stl" ? "the 1152 triangles given need about "
                                                          : "the 1152 triangles to be written need at least "),
                          std::string::npos)
                    << r.err;
                EXPECT_NE(r.err.find("over the memory budget of 64 KiB; give --memory "), std::string::npos) << r.err;
                const uint64_t mib = figure(r.err);
                EXPECT_GE(mib, 1u) << r.err;
                EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"in.ply", "in.stl", "in_ascii.stl"}));
                // The figure given does.
                CliRun again = run(cmd + " -q --memory " + std::to_string(mib) + "M " + dir / in + " " + dir / out);
                EXPECT_EQ(again.code, 0) << again.err;
                fs::remove(dir / out);
            }
}

// Past the budget in the middle of a long input of no stated count: the writer stops holding
// triangles and counts the rest, and the figure is for all of them.
TEST(CliMemory, AnInputOfNoStatedCountGetsTheFigureForAllItsTriangles) {
    TempDir dir;
    spit(dir / "in.stl", ascii_stl(grid(100)));  // 20000 triangles, two chunks and more
    CliRun small = run("convert --memory 1M " + dir / "in.stl" + " " + dir / "out.glb");
    EXPECT_EQ(small.code, 1) << small.err;
    EXPECT_NE(small.err.find("the 20000 triangles given need about "), std::string::npos) << small.err;
    EXPECT_NE(small.err.find("(the first 16384 took "), std::string::npos) << small.err;
    const uint64_t mib = figure(small.err);
    EXPECT_GE(mib, 2u) << small.err;
    EXPECT_FALSE(fs::exists(dir / "out.glb"));
    CliRun enough = run("convert --memory " + std::to_string(mib) + "M " + dir / "in.stl" + " " + dir / "out.glb");
    EXPECT_EQ(enough.code, 0) << enough.err;
}

// Without --memory a whole-mesh writer gets half of the memory available (here a fake
// /proc/meminfo saying 3 GiB), and --memory still wins. The PLY's header promises more faces
// than any budget holds: the check up front names the budget before any face is read.
TEST(CliMemory, TheWholeMeshDefaultIsHalfTheAvailableMemoryAndMemoryWins) {
    TempDir dir;
    spit(dir / "huge.ply", ascii_ply(grid(1), 1000000000));
    spit(dir / "meminfo", "MemTotal:       16000000 kB\nMemFree:         1000000 kB\nMemAvailable:    3145728 kB\n");
    const std::string env = "MESHSTREAM_MEMINFO=" + dir / "meminfo";
    for (const char* out : {"out.drc", "out.glb"}) {
        SCOPED_TRACE(out);
        CliRun r = run("convert " + dir / "huge.ply" + " " + dir / out, env);
        EXPECT_EQ(r.code, 1) << r.err;
        EXPECT_NE(r.err.find("the 1000000000 triangles to be written need at least "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("over the memory budget of 1.5 GiB; give --memory "), std::string::npos) << r.err;
        CliRun given = run("convert --memory 300M " + dir / "huge.ply" + " " + dir / out, env);
        EXPECT_EQ(given.code, 1) << given.err;
        EXPECT_NE(given.err.find("over the memory budget of 300 MiB; give --memory "), std::string::npos) << given.err;
        EXPECT_EQ(figure(r.err), figure(given.err));
    }
    // A meminfo of less than 512 MiB available: the default is never below 256 MiB.
    spit(dir / "meminfo", "MemAvailable:     100000 kB\n");
    CliRun floor = run("decimate -r 0.5 " + dir / "huge.ply" + " " + dir / "out.glb", env);
    EXPECT_EQ(floor.code, 1) << floor.err;
    EXPECT_NE(floor.err.find("over the memory budget of 256 MiB"), std::string::npos) << floor.err;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"huge.ply", "meminfo"}));
}

// sort gives its writer a quarter of --memory: the figure is for --memory, and it does.
TEST(CliMemory, SortsFigureIsForTheMemoryItsWriterGetsAQuarterOf) {
    TempDir dir;
    spit(dir / "in.stl", binary_stl(grid(100)));  // 20000 triangles
    CliRun r = run("sort --axis x --memory 1M --compress none " + dir / "in.stl" + " " + dir / "out.glb");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("the 20000 triangles to be written need at least "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("over the memory budget of 256 KiB (1/4 of --memory); give --memory "), std::string::npos)
        << r.err;
    const uint64_t mib = figure(r.err);
    EXPECT_GE(mib, 4u) << r.err;
    CliRun again = run("sort -q --axis x --memory " + std::to_string(mib) + "M --compress none " + dir / "in.stl" +
                       " " + dir / "out.glb");
    EXPECT_EQ(again.code, 0) << again.err;
}

}  // namespace
