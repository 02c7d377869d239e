// `convert --threads` and `sort --threads` through the binary: reading and writing on threads of
// their own (io/pipeline.hpp) give the same bytes as one thread for every pair of formats, with
// gzip, through pipes too; a read error in the middle of the input, a cut gzip stream and a
// writer that fails give exactly one thread's error and exit code, and leave no output.
#include "format_util.hpp"
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

namespace {

using cli_test::CliRun;
using cli_test::listing;
using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;
using meshstream::test::file_extension;
using meshstream::test::spit;
namespace fs = std::filesystem;
namespace io = meshstream::io;

const std::string kFixtures = MESHSTREAM_FIXTURES_DIR;
const std::string kBunny = kFixtures + "/bunny_from_draco.bin.stl";
// Normals, texture coordinates and materials.
const std::string kWuson = kFixtures + "/obj/WusonOBJ.obj";

// `meshstream -q ARGS` with --threads 1 and 2, {OUT} replaced by `out` in the directories
// `dir`/t1 and `dir`/t2: both succeed and write the same files, with the same bytes.
void expect_same_bytes(const std::string& args, const TempDir& dir, const std::string& out) {
    const auto with = [&](const std::string& threads) {
        fs::create_directory(dir / ("t" + threads));
        std::string a = args;
        a.replace(a.find("{OUT}"), 5, dir / ("t" + threads + "/" + out));
        return run("-q " + a + " --threads " + threads);
    };
    const CliRun one = with("1"), two = with("2");
    ASSERT_EQ(one.code, 0) << args << ": " << one.err;
    ASSERT_EQ(two.code, 0) << args << ": " << two.err;
    EXPECT_EQ(one.err, two.err) << args;
    const std::vector<std::string> files = listing(dir / "t1");
    EXPECT_EQ(files, listing(dir / "t2")) << args;
    for (const std::string& name : files)
        EXPECT_TRUE(slurp(dir / ("t1/" + name)) == slurp(dir / ("t2/" + name))) << args << ": " << name << " differs";
    fs::remove_all(dir / "t1");
    fs::remove_all(dir / "t2");
}

// The formats convert can write, each named by its first extension (gzipped too when `gzip`).
std::vector<std::pair<std::string, std::string>> outputs(bool gzip) {  // (--to, extension)
    std::vector<std::pair<std::string, std::string>> out;
    for (const io::Format* f : io::formats()) {
        if (f->open_writer == nullptr) continue;
        out.emplace_back(std::string(f->name), file_extension(*f));
        if (gzip) out.emplace_back(std::string(f->name), file_extension(*f) + ".gz");
    }
    return out;
}

// The input in every readable format (made with one thread), gzipped too when `gzip`.
std::vector<std::string> inputs_from(const std::string& mesh, const TempDir& dir, const std::string& stem, bool gzip) {
    std::vector<std::string> paths;
    for (const io::Format* f : io::formats()) {
        if (f->open_reader == nullptr || f->open_writer == nullptr) continue;
        for (const std::string suffix : {"", ".gz"}) {
            if (!suffix.empty() && !gzip) continue;
            // A directory each: a .gltf's buffer goes beside it.
            const std::string sub = dir / (stem + "_" + std::string(f->name) + suffix);
            fs::create_directory(sub);
            const std::string path = sub + "/in." + file_extension(*f) + suffix;
            CliRun r = run("-q convert --threads 1 --to " + std::string(f->name) + " " + mesh + " " + path);
            EXPECT_EQ(r.code, 0) << path << ": " << r.err;
            paths.push_back(path);
        }
    }
    return paths;
}

// The first 40 000 triangles of the bunny as binary STL in `dir`: three chunks, so the threads
// hand several over.
std::string bunny_part(const TempDir& dir) {
    std::string bytes = slurp(kBunny).substr(0, 84 + 50 * 40000);
    const uint32_t n = 40000;
    std::memcpy(&bytes[80], &n, 4);  // little-endian, as the files this runs on
    const std::string path = dir / "bunny40k.stl";
    spit(path, bytes);
    return path;
}

// Several chunks, from binary STL to every output format, gzipped or not; with channels
// (normals, texture coordinates, materials) from OBJ to every output format.
TEST(CliPipeline, ConvertWritesTheSameBytesWithThreadsForEveryOutputFormat) {
    TempDir dir;
    const std::string bunny = bunny_part(dir);
    for (const auto& [to, ext] : outputs(true))
        expect_same_bytes("convert --to " + to + " " + bunny + " {OUT}", dir, "out." + ext);
    for (const auto& [to, ext] : outputs(false))
        expect_same_bytes("convert --to " + to + " " + kWuson + " {OUT}", dir, "out." + ext);
}

// Several chunks, from every input format, gzipped or not, to gzipped PLY.
TEST(CliPipeline, ConvertWritesTheSameBytesWithThreadsForEveryInputFormat) {
    TempDir dir;
    for (const std::string& in : inputs_from(bunny_part(dir), dir, "bunny", true))
        expect_same_bytes("convert " + in + " {OUT}", dir, "out.ply.gz");
}

TEST(CliPipeline, SortWritesTheSameBytesWithThreads) {
    TempDir dir;
    const std::string bunny = bunny_part(dir);
    for (const std::string& in : inputs_from(bunny, dir, "bunny", false))
        expect_same_bytes("sort --axis y " + in + " {OUT}", dir, "out.stl");
    expect_same_bytes("sort --axis y " + bunny + " {OUT}", dir, "out.ply.gz");
    // Runs spilled and merged: a small --memory.
    expect_same_bytes("sort --memory 1M " + bunny + " {OUT}", dir, "out.ply");
}

TEST(CliPipeline, PipesGiveTheSameBytesWithThreads) {
    TempDir dir;
    for (const std::string threads : {"1", "2"}) {
        CliRun c = run("-q convert --threads " + threads + " - - --to ply-ascii < " + kBunny + " > " +
                       (dir / ("convert" + threads)));
        EXPECT_EQ(c.code, 0) << c.err;
        CliRun s = run("-q sort --threads " + threads + " --axis z - - --to stl < " + (dir / "convert1") + " > " +
                       (dir / ("sort" + threads)));
        EXPECT_EQ(s.code, 0) << s.err;
    }
    EXPECT_GT(slurp(dir / "convert1").size(), 69451u * 3 * 10);
    EXPECT_TRUE(slurp(dir / "convert1") == slurp(dir / "convert2"));
    EXPECT_EQ(slurp(dir / "sort1").size(), 84u + 50u * 69451u);
    EXPECT_TRUE(slurp(dir / "sort1") == slurp(dir / "sort2"));
}

// The same run with --threads 1 and 2: the same exit code 1 and stderr, and `dir/o` empty.
void expect_same_failure(const std::string& args, const TempDir& dir, const std::string& expected,
                         const std::string& prefix = "") {
    std::string first;
    for (const std::string threads : {"1", "2"}) {
        fs::create_directory(dir / "o");
        std::string a = args;
        a.replace(a.find("{OUT}"), 5, dir / "o");
        const CliRun r = run(a + " --threads " + threads, prefix);
        EXPECT_EQ(r.code, 1) << a << " --threads " << threads << ": " << r.err;
        EXPECT_NE(r.err.find(expected), std::string::npos) << a << " --threads " << threads << ": " << r.err;
        EXPECT_EQ(listing(dir / "o"), std::vector<std::string>{}) << a << " --threads " << threads;
        // Temporary files' names differ from run to run.
        const std::string err = std::regex_replace(r.err, std::regex("-[A-Za-z0-9]{6}:"), "-XXXXXX:");
        if (threads == "1")
            first = err;
        else
            EXPECT_EQ(err, first) << a;
        fs::remove_all(dir / "o");
    }
}

TEST(CliPipeline, BadInputMidFileGivesTheOneThreadErrorAndNoOutput) {
    TempDir dir;
    // ASCII STL of the bunny with facet 40 000 broken (its "endloop" misspelt): the reader
    // fails after two chunks were handed over and written.
    const std::string ascii = dir / "bunny.stl";
    ASSERT_EQ(run("-q convert --to stl-ascii " + kBunny + " " + ascii).code, 0);
    std::string text = slurp(ascii);
    size_t at = 0;
    for (int i = 0; i < 40000; ++i) at = text.find("endloop", at) + 1;
    text.replace(at - 1, 7, "endlop");
    const size_t line = 1 + size_t(std::count(text.begin(), text.begin() + long(at), '\n'));
    spit(ascii, text);
    const std::string where = ascii + ":" + std::to_string(line) + ": ";
    for (const char* cmd :
         {"convert {IN} {OUT}/out.ply.gz", "convert {IN} {OUT}/out.obj", "sort --axis x {IN} {OUT}/out.stl"}) {
        std::string args = cmd;
        args.replace(args.find("{IN}"), 4, ascii);
        expect_same_failure(args, dir, where);
    }
}

TEST(CliPipeline, CutGzipGivesTheOneThreadErrorAndNoOutput) {
    TempDir dir;
    const std::string gz = dir / "bunny.ply.gz";
    ASSERT_EQ(run("-q convert --to ply-ascii " + kBunny + " " + gz).code, 0);
    const std::string bytes = slurp(gz);
    const std::string cut = dir / "cut.ply.gz";
    spit(cut, bytes.substr(0, bytes.size() * 2 / 3));
    for (const char* cmd : {"convert {IN} {OUT}/out.stl", "sort --axis x {IN} {OUT}/out.stl.gz"}) {
        std::string args = cmd;
        args.replace(args.find("{IN}"), 4, cut);
        expect_same_failure(args, dir, "meshstream: error: " + cut + ": ");
    }
}

TEST(CliPipeline, FailingWriterGivesTheOneThreadErrorAndNoOutput) {
    TempDir dir;
    for (const char* cmd :
         {"convert {IN} {OUT}/out.ply", "convert {IN} {OUT}/out.stl.gz", "sort --axis x {IN} {OUT}/out.obj"}) {
        std::string args = cmd;
        args.replace(args.find("{IN}"), 4, kBunny);
        // 128 KiB (dash counts 512-byte blocks): the writer fails part way through.
        expect_same_failure(args, dir, "File too large", "ulimit -f 256;");
    }
}

}  // namespace
