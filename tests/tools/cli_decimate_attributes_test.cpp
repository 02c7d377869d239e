// `meshstream decimate` with channels: colours, normals and uvs carried through to the output,
// what is said when the output cannot hold them, --weights and --drop, and the paths that decimate
// positions only (ranges, a spooled stream).
#include "io/format.hpp"
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace {

using cli_test::CliRun;
using cli_test::run;
using cli_test::TempDir;
using namespace meshstream;

// A coloured generated mesh of about `n` triangles (meshstream-gen --color: colour a function of
// position).
std::string coloured_mesh(const TempDir& dir, int n) {
    const std::string path = dir / "coloured.ply";
    const std::string cmd = std::string(MESHSTREAM_GEN_BINARY) + " -q --color -n " + std::to_string(n) + " " + path;
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    return path;
}

struct Read {
    io::Channels channels;
    uint64_t triangles = 0;
    double colour_min = 1, colour_max = 0;
};

Read read_back(const std::string& path) {
    io::Input in = io::open_input(path);
    Read r;
    r.channels = in.reader->header().channels;
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, r.channels);
    while (in.reader->next(chunk)) {
        r.triangles += chunk.size();
        if (!r.channels.color) continue;
        for (size_t i = 0; i < chunk.size(); ++i)
            for (int k = 0; k < 12; ++k)
                if (k % 4 != 3) {
                    r.colour_min = std::min<double>(r.colour_min, chunk.color_at(i)[k]);
                    r.colour_max = std::max<double>(r.colour_max, chunk.color_at(i)[k]);
                }
    }
    return r;
}

}  // namespace

TEST(CliDecimateChannels, ColoursAreKeptAndSaidNothingAbout) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 20000);
    const Read before = read_back(in);
    CliRun r = run("decimate -r 0.1 --threads 1 " + in + " " + dir / "out.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    const Read after = read_back(dir / "out.ply");
    ASSERT_TRUE(after.channels.color.has_value());
    EXPECT_EQ(after.triangles, uint64_t(std::llround(0.1 * double(before.triangles))));
    // The colours stay within the input's range (interpolated, not invented).
    EXPECT_GE(after.colour_min, before.colour_min - 1.0 / 255);
    EXPECT_LE(after.colour_max, before.colour_max + 1.0 / 255);
    EXPECT_GT(after.colour_max - after.colour_min, 0.5 * (before.colour_max - before.colour_min));
}

TEST(CliDecimateChannels, AnOutputThatCannotHoldThemSaysWhatWasDropped) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 20000);
    CliRun r = run("decimate -r 0.1 " + in + " " + dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: colours dropped: stl output carries positions only"), std::string::npos) << r.err;
    // Asked for with --drop: dropped, and nothing said.
    r = run("decimate -r 0.1 --drop colors " + in + " " + dir / "plain.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    EXPECT_FALSE(read_back(dir / "plain.ply").channels.color.has_value());
}

TEST(CliDecimateChannels, BadWeightsAreUsageErrors) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 2000);
    CliRun r = run("decimate --weights color=lots " + in + " " + dir / "out.ply");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--weights"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'lots'"), std::string::npos) << r.err;
    r = run("decimate --weights intensity=1 " + in + " " + dir / "out.ply");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("no vertex scalar 'intensity' to weigh"), std::string::npos) << r.err;
    r = run("decimate --weights color " + in + " " + dir / "out.ply");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("NAME=WEIGHT"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.ply"));
    // Weights that parse change the run, not its count.
    r = run("decimate -r 0.2 --threads 1 --weights color=4,normal=0.5 " + in + " " + dir / "out.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(read_back(dir / "out.ply").channels.color.has_value());
}

TEST(CliDecimateChannels, RangesCarryTheColoursThroughTheirSpoolsAndTheSeamPass) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 60000);
    const Read before = read_back(in);
    const std::string common = "decimate -r 0.1 --buffer 16384 --json " + in + " ";
    CliRun r = run(common + "--threads 2 " + dir / "two.ply > " + dir / "two.json");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(cli_test::slurp(dir / "two.json").find("\"threads\":2"), std::string::npos);
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    const Read after = read_back(dir / "two.ply");
    ASSERT_TRUE(after.channels.color.has_value());
    EXPECT_EQ(after.triangles, uint64_t(std::llround(0.1 * double(before.triangles))));
    EXPECT_GE(after.colour_min, before.colour_min - 1.0 / 255);
    EXPECT_LE(after.colour_max, before.colour_max + 1.0 / 255);
    // The same run again: the same bytes.
    ASSERT_EQ(run(common + "--threads 2 " + dir / "again.ply > /dev/null").code, 0);
    EXPECT_EQ(cli_test::slurp(dir / "two.ply"), cli_test::slurp(dir / "again.ply"));
}

TEST(CliDecimateChannels, AStreamWithColoursIsNotSortedFirst) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 2000);
    CliRun r = run("decimate --sort always - " + dir / "out.ply" + " --from ply < " + in);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--sort always spools a stream as positions only"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.ply"));
    // Sorted from a file, the colours come through the sort.
    r = run("decimate --sort always -r 0.1 " + in + " " + dir / "sorted.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(read_back(dir / "sorted.ply").channels.color.has_value());
    // Decimated as read from the stream, they come through too.
    r = run("decimate -r 0.1 - " + dir / "read.ply" + " --from ply < " + in);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(read_back(dir / "read.ply").channels.color.has_value());
}
