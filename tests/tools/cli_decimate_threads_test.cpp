// `meshstream decimate --threads N` through the binaries (MESHSTREAM_BINARY,
// MESHSTREAM_GEN_BINARY): the input cut into ranges decimated at once and joined by a seam pass
// (engine/ranges.hpp). A generated mesh with a --buffer small enough that it really is
// cut, checked for what one thread guarantees: exact counts, a closed mesh kept closed, the
// same bytes every time, errors that name the file and position, and an error close to one
// thread's.
#include "compare/metro.hpp"
#include "compare/topology.hpp"
#include "io/format.hpp"
#include "tools/cli_util.hpp"
#include "tools/mesh_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

namespace {

using cli_test::CliRun;
using cli_test::edges_of;
using cli_test::listing;
using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;
using cli_test::triangles_of;
using namespace meshstream;

double rms_error(const std::string& original, const std::string& decimated) {
    compare::CompareOptions co;
    return compare::compare_meshes(compare::file_source(original, {}, {}), compare::file_source(decimated, {}, {}), co)
        .rms();
}

// A closed generated mesh of about 200 k triangles.
const std::string& mesh() { return cli_test::generated_mesh(200000); }

}  // namespace

TEST(CliDecimateThreads, RangesAndSeamsLandOnTheTargetAndKeepAClosedMeshClosed) {
    TempDir dir;
    const compare::EdgeCounts in = edges_of(mesh());
    ASSERT_EQ(in.boundary_edges, 0u);
    // 200 k triangles through 20 000 a range: cut in 2 and 3 (every range ≥ --buffer).
    for (const char* options : {"--threads 2 -r 0.1", "--threads 2 -r 0.01", "--threads 3 -r 0.1",
                                "--threads 2 --target 5000", "--threads 3 --target 20001"}) {
        CliRun r = run("decimate --buffer 20000 " + std::string(options) + " " + mesh() + " " + dir / "out.stl");
        ASSERT_EQ(r.code, 0) << options << ": " << r.err;
        EXPECT_NE(r.err.find("ranges decimated at once"), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find("force-written"), std::string::npos) << options << ": " << r.err;
        const uint64_t n = triangles_of(dir / "out.stl");
        const char* target = std::strstr(options, "--target");
        // A closed mesh's count is even: an odd target ends one over, with a warning (as one thread).
        const uint64_t want = target ? std::stoull(target + 9) : 0;
        if (target && want % 2 == 1) {
            EXPECT_EQ(n, want + 1) << options;
            EXPECT_NE(r.err.find("a collapse removes two triangles"), std::string::npos) << r.err;
        } else if (target) {
            EXPECT_EQ(n, want) << options;
        } else {
            EXPECT_EQ(r.err.find("instead of the target"), std::string::npos) << options << ": " << r.err;
        }
        const compare::EdgeCounts out = edges_of(dir / "out.stl");
        EXPECT_EQ(out.boundary_edges, 0u) << options;
        EXPECT_LE(out.non_manifold_edges, in.non_manifold_edges) << options;
    }
}

TEST(CliDecimateThreads, TheSameThreadsGiveTheSameBytes) {
    TempDir dir;
    for (int i = 0; i < 2; ++i) {
        CliRun r =
            run("decimate -q --buffer 20000 --threads 3 -r 0.05 " + mesh() + " " + dir / (std::to_string(i) + ".ply"));
        ASSERT_EQ(r.code, 0) << r.err;
    }
    EXPECT_EQ(slurp(dir / "0.ply"), slurp(dir / "1.ply"));
}

TEST(CliDecimateThreads, AnInputOfFewerThanTwoBuffersIsDecimatedWhole) {
    // Cut into ranges smaller than a buffer, an input gains nothing: it is decimated as by
    // --threads 1, byte for byte.
    TempDir dir;
    const std::string bunny = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";
    ASSERT_EQ(run("decimate -q --threads 1 -r 0.1 " + bunny + " " + dir / "1.stl").code, 0);
    CliRun r = run("decimate --threads 4 -r 0.1 " + bunny + " " + dir / "4.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("ranges decimated at once"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(dir / "1.stl"), slurp(dir / "4.stl"));
}

TEST(CliDecimateThreads, TheErrorStaysCloseToOneThreads) {
    // The seams are decimated from full resolution in the seam pass: on this mesh the RMS error
    // was 0.97 times one thread's with 2 ranges at 10 % and 3 ranges at 1 %; the bound leaves room.
    TempDir dir;
    for (const auto& [ratio, threads] : {std::pair{"0.1", "2"}, std::pair{"0.01", "3"}}) {
        const std::string options = "decimate -q --buffer 20000 -r " + std::string(ratio) + " " + mesh();
        ASSERT_EQ(run(options + " --threads 1 " + dir / "1.stl").code, 0);
        const CliRun r = run(options + " --threads " + threads + " " + dir / "n.stl");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_LE(rms_error(mesh(), dir / "n.stl"), 1.05 * rms_error(mesh(), dir / "1.stl"))
            << ratio << ", " << threads << " threads";
    }
}

TEST(CliDecimateThreads, TheSeamsKeepOneThreadsHausdorffDistance) {
    // The generated 1 M-triangle mesh at 1 % through the default buffer: two ranges, joined along
    // one seam. The seam pass used to take what the joined seam strips lacked of the target from
    // whatever it held, rated by quadrics of the ranges' decimated triangles alone, and cut
    // features off there: a Hausdorff distance of 1.065 % of the diagonal against one thread's
    // 0.585 % (both measured with these samples; one thread's output is the same bytes before and
    // after). The ranges now decimate that part themselves, and the seam pass collapses along its
    // seams first: 0.570 %. (A 200 k mesh through a small buffer did not show the difference.)
    constexpr double kOneThreadHausdorffPercent = 0.585;
    TempDir dir;
    const std::string& input = cli_test::generated_mesh(1000000);
    const CliRun r = run("decimate -q --threads 2 -r 0.01 " + input + " " + dir / "two.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(triangles_of(dir / "two.stl"), 10070u);
    compare::CompareOptions co;
    co.samples = 1000000;
    co.edges = false;
    const compare::CompareResult c =
        compare::compare_meshes(compare::file_source(input, {}, {}), compare::file_source(dir / "two.stl", {}, {}), co);
    const double hausdorff_percent = 100 * c.hausdorff() / c.diagonal;
    EXPECT_GT(hausdorff_percent, 0.0);
    EXPECT_LE(hausdorff_percent, 1.1 * kOneThreadHausdorffPercent);
}

TEST(CliDecimateThreads, JsonSaysHowManyThreads) {
    TempDir dir;
    const std::string json_path = dir / "out.json";
    CliRun r =
        run("decimate --json --buffer 20000 --threads 2 -r 0.1 " + mesh() + " " + dir / "out.stl" + " > " + json_path);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(json_path));
    EXPECT_EQ(j["decimate"]["threads"], 2);
    r = run("decimate --json --threads 1 -r 0.1 " + mesh() + " " + dir / "out.stl" + " > " + json_path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(slurp(json_path))["decimate"]["threads"], 1);
}

TEST(CliDecimateThreads, BadInputInAnyRangeIsTheSameErrorAsOneThreads) {
    // A vertex index out of range in the second range of a binary PLY: the range that meets it
    // (and every later one, which reads past it) fails; the error reaches the command as one
    // thread's does, exit 1, and no output is left behind.
    TempDir dir;
    std::filesystem::create_directories(dir / "in");
    std::filesystem::create_directories(dir / "out");
    const std::string in = dir / "in/bad.ply", out = dir / "out/o.ply";
    const cli_test::BadPly bad_ply = cli_test::write_ply_with_bad_index(mesh(), in, 0.75);
    std::string ply = bad_ply.bytes;
    const uint64_t bad = bad_ply.bad_face;
    const CliRun one = run("decimate --threads 1 --buffer 20000 -r 0.1 " + in + " " + out);
    for (const char* threads : {"2", "3"}) {
        const CliRun r = run("decimate --threads " + std::string(threads) + " --buffer 20000 -r 0.1 " + in + " " + out);
        EXPECT_EQ(r.code, 1) << r.err;
        EXPECT_NE(r.err.find("bad.ply: byte "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("item " + std::to_string(bad)), std::string::npos) << r.err;
        EXPECT_EQ(r.err, one.err);
        EXPECT_TRUE(listing(dir / "out").empty());
    }

    // Truncated: only the last range reads to the end, and finds it.
    ply.resize(ply.size() - 7);
    std::ofstream(in, std::ios::binary | std::ios::trunc) << ply;
    const CliRun one_short = run("decimate --threads 1 --buffer 20000 -r 0.1 " + in + " " + out);
    const CliRun two_short = run("decimate --threads 2 --buffer 20000 -r 0.1 " + in + " " + out);
    EXPECT_EQ(two_short.code, 1) << two_short.err;
    EXPECT_NE(two_short.err.find("bad.ply"), std::string::npos) << two_short.err;
    EXPECT_EQ(two_short.err, one_short.err);
    EXPECT_TRUE(listing(dir / "out").empty());
}

TEST(CliDecimateThreads, ABadThreadCountIsACommandLineError) {
    TempDir dir;
    CliRun r = run("decimate --threads 0 -r 0.1 " + mesh() + " " + dir / "out.stl");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(listing(dir.path()).empty());
    r = run("decimate --help > " + dir / "help.txt");
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(slurp(dir / "help.txt").find("--threads"), std::string::npos);
}
