// `meshstream decimate --part k/K` through the binaries (MESHSTREAM_BINARY,
// MESHSTREAM_GEN_BINARY): the ranges of `--threads K` as K separate jobs, parts 1 .. K-1 into
// part files and the merge K/K (engine/part_files.hpp). The merge writes the bytes --threads K
// writes; a part file that is missing, cut short, damaged or made from another input or with
// other options is refused with the file and what is wrong, and nothing is written.
#include "tools/cli_util.hpp"
#include "tools/mesh_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using cli_test::CliRun;
using cli_test::listing;
using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;

// A closed generated mesh of about 200 k triangles: 3 ranges through --buffer 20000 and more.
const std::string& mesh() { return cli_test::generated_mesh(200000); }

// Runs parts 1 .. K-1 of `options` on `in` into dir/part<k>, each expected to succeed; their
// paths, last part first (the merge takes them in any order).
std::vector<std::string> make_parts(const TempDir& dir, const std::string& in, unsigned parts,
                                    const std::string& options) {
    std::vector<std::string> paths;
    for (unsigned k = 1; k < parts; ++k) {
        const std::string path = dir / ("part" + std::to_string(k));
        const CliRun r = run("decimate -q " + options + " --part " + std::to_string(k) + "/" + std::to_string(parts) +
                             " " + in + " " + path);
        EXPECT_EQ(r.code, 0) << options << ", part " << k << ": " << r.err;
        paths.insert(paths.begin(), path);
    }
    return paths;
}

std::string merge_args(const std::vector<std::string>& parts) {
    std::string args;
    for (const std::string& p : parts) args += " --merge " + p;
    return args;
}

void write_file(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace

TEST(CliDecimateParts, PartsAndTheirMergeWriteWhatThreadsWrite) {
    TempDir dir;
    for (const auto& [parts, options] :
         {std::pair{2u, "--buffer 20000 -r 0.05"}, std::pair{3u, "--buffer 20000 -r 0.05"},
          std::pair{3u, "--buffer 16384 --target 5000"}}) {
        const std::vector<std::string> files = make_parts(dir, mesh(), parts, options);
        const std::string k = std::to_string(parts);
        const CliRun merge = run("decimate " + std::string(options) + " --part " + k + "/" + k + merge_args(files) +
                                 " " + mesh() + " " + dir / "merged.stl");
        ASSERT_EQ(merge.code, 0) << options << ": " << merge.err;
        EXPECT_NE(merge.err.find("parts " + k + ": ranges 1 to " + std::to_string(parts - 1) + " read from part files"),
                  std::string::npos)
            << merge.err;
        EXPECT_EQ(merge.err.find("force-written"), std::string::npos) << merge.err;
        ASSERT_EQ(
            run("decimate -q " + std::string(options) + " --threads " + k + " " + mesh() + " " + dir / "threads.stl")
                .code,
            0);
        const std::string merged = slurp(dir / "merged.stl");
        EXPECT_GT(merged.size(), 84u);
        EXPECT_EQ(merged, slurp(dir / "threads.stl")) << parts << " parts, " << options;
    }
}

TEST(CliDecimateParts, PartsCarryTheColoursTheMergeWrites) {
    TempDir dir;
    const std::string coloured = dir / "coloured.ply";
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q --color -n 60000 " + coloured).c_str()), 0);
    for (const unsigned parts : {2u, 3u}) {
        const std::string options = "--buffer 16384 -r 0.1", k = std::to_string(parts);
        const std::vector<std::string> files = make_parts(dir, coloured, parts, options);
        const CliRun merge = run("decimate " + options + " --part " + k + "/" + k + merge_args(files) + " " + coloured +
                                 " " + dir / "merged.ply");
        ASSERT_EQ(merge.code, 0) << merge.err;
        EXPECT_EQ(merge.err.find("warning"), std::string::npos) << merge.err;
        ASSERT_EQ(run("decimate -q " + options + " --threads " + k + " " + coloured + " " + dir / "threads.ply").code,
                  0);
        const std::string merged = slurp(dir / "merged.ply");
        EXPECT_NE(merged.find("property uchar red"), std::string::npos);
        EXPECT_EQ(merged, slurp(dir / "threads.ply")) << parts << " parts";
    }

    // Parts carry every channel of the input unless --to names the merge's output format: a
    // merge to STL (positions only) refuses them and says how to make them, then takes parts
    // made with --to stl.
    const std::vector<std::string> coloured_parts = make_parts(dir, coloured, 2, "--buffer 16384 -r 0.1");
    CliRun r = run("decimate --buffer 16384 -r 0.1 --part 2/2" + merge_args(coloured_parts) + " " + coloured + " " +
                   dir / "out.stl");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("part1: part 1/2 carries other channels than this job: it carries colours"), std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("--to naming its output format"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.stl"));
    const std::vector<std::string> stl_parts = make_parts(dir, coloured, 2, "--buffer 16384 -r 0.1 --to stl");
    r = run("decimate -q --buffer 16384 -r 0.1 --part 2/2" + merge_args(stl_parts) + " " + coloured + " " +
            dir / "out.stl");
    ASSERT_EQ(r.code, 0) << r.err;
    ASSERT_EQ(run("decimate -q --buffer 16384 -r 0.1 --threads 2 " + coloured + " " + dir / "threads.stl").code, 0);
    EXPECT_EQ(slurp(dir / "out.stl"), slurp(dir / "threads.stl"));
}

TEST(CliDecimateParts, APartOfOtherOptionsOrAnotherInputIsRefused) {
    TempDir dir;
    std::filesystem::create_directories(dir / "out");
    const std::string out = dir / "out/merged.stl";
    const std::vector<std::string> parts = make_parts(dir, mesh(), 3, "--buffer 20000 -r 0.05");
    struct Case {
        std::string options, input, message;
    };
    // Another input of the same size: one byte of a triangle's normal (no matter to decimation)
    // changed in the first block the fingerprint reads.
    const std::string changed = dir / "changed.stl";
    std::string bytes = slurp(mesh());
    bytes[84 + 50 * 10] ^= 1;
    write_file(changed, bytes);
    const std::string other = cli_test::generated_mesh(100000);
    for (const Case& c :
         {Case{"--buffer 40000 -r 0.05", mesh(), "part 2/3 was made with --buffer 20000, this job has 40000"},
          Case{"--buffer 20000 -r 0.1", mesh(),
               "part 2/3 was made with the ranges decimating at ratio 0.05, this "
               "job's is 0.1 (--ratio or --target differ)"},
          Case{"--buffer 20000 -r 0.05 --seed 7", mesh(), "part 2/3 was made with --seed 1, this job has 7"},
          Case{"--buffer 20000 -r 0.05 --weld 0.001", mesh(),
               "part 2/3 was made welding on a grid of 0, this job's is 0.001 (--weld differs)"},
          Case{"--buffer 20000 -r 0.05 --sorted-axis z", mesh(),
               "part 2/3 was made with the input sorted along none, this job has z (--sorted-axis differs)"},
          Case{"--buffer 20000 -r 0.05", changed, "part 2/3 was made from another input of the same size"},
          Case{
              "--buffer 20000 -r 0.05", other,
              "part 2/3 was made from an input of " + std::to_string(std::filesystem::file_size(mesh())) + " bytes"}}) {
        const CliRun r = run("decimate " + c.options + " --part 3/3" + merge_args(parts) + " " + c.input + " " + out);
        EXPECT_EQ(r.code, 1) << c.options << ": " << r.err;
        EXPECT_NE(r.err.find("error: " + parts.front() + ": " + c.message), std::string::npos) << r.err;
        EXPECT_TRUE(listing(dir / "out").empty()) << c.options;
    }
    // A part of another K.
    const std::vector<std::string> halves = make_parts(dir, mesh(), 2, "--buffer 20000 -r 0.05");
    const CliRun r = run("decimate --buffer 20000 -r 0.05 --part 3/3 --merge " + halves.front() + " --merge " +
                         parts.front() + " " + mesh() + " " + out);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("part 1/2 is not one of parts 1/3 to 2/3 of this job"), std::string::npos) << r.err;
    EXPECT_TRUE(listing(dir / "out").empty());
}

TEST(CliDecimateParts, AMissingCutShortOrDamagedPartIsRefused) {
    TempDir dir;
    std::filesystem::create_directories(dir / "out");
    const std::string out = dir / "out/merged.stl", options = "--buffer 20000 -r 0.05";
    const std::vector<std::string> parts = make_parts(dir, mesh(), 3, options);  // part2, part1
    const std::string whole = slurp(parts.back());
    ASSERT_GT(whole.size(), 2000u);
    const std::string cut = dir / "cut", damaged = dir / "damaged", missing = dir / "missing";
    write_file(cut, whole.substr(0, whole.size() / 2));
    std::string flipped = whole;
    flipped[flipped.size() / 2] ^= 0x40;
    write_file(damaged, flipped);
    // A byte of the range's statistics in the file's end.
    const std::string damaged_end = dir / "damaged_end";
    std::string end_flipped = whole;
    end_flipped[end_flipped.size() - 60] ^= 0x01;
    write_file(damaged_end, end_flipped);
    for (const auto& [file, message] :
         {std::pair{cut, "not a complete part file: cut short"}, std::pair{damaged, "damaged part file"},
          std::pair{damaged_end, "damaged part file"}, std::pair{missing, "cannot open: No such file or directory"},
          std::pair{mesh(), "not a part file"}}) {
        const CliRun r = run("decimate " + options + " --part 3/3 --merge " + parts.front() + " --merge " + file + " " +
                             mesh() + " " + out);
        EXPECT_EQ(r.code, 1) << file << ": " << r.err;
        EXPECT_NE(r.err.find("error: " + file + ": " + message), std::string::npos) << r.err;
        EXPECT_TRUE(listing(dir / "out").empty()) << file;
    }
    // Part 1 given twice (part 2 not at all), and one part file too few: the command line.
    for (const std::string& merge :
         {" --merge " + parts.back() + " --merge " + parts.back(), " --merge " + parts.back()}) {
        const CliRun r = run("decimate " + options + " --part 3/3" + merge + " " + mesh() + " " + out);
        EXPECT_EQ(r.code, 2) << merge << ": " << r.err;
        EXPECT_TRUE(listing(dir / "out").empty()) << merge;
    }
    EXPECT_NE(run("decimate " + options + " --part 3/3 --merge " + parts.back() + " " + mesh() + " " + out)
                  .err.find("give --merge once for each of their 2 part files, found 1"),
              std::string::npos);
}

TEST(CliDecimateParts, APartThatFailsLeavesNoPartFile) {
    TempDir dir;
    std::filesystem::create_directories(dir / "in");
    std::filesystem::create_directories(dir / "out");
    const std::string in = dir / "in/bad.ply";
    const uint64_t bad = cli_test::write_ply_with_bad_index(mesh(), in, 0.2).bad_face;
    const CliRun r = run("decimate --buffer 20000 -r 0.05 --part 1/3 " + in + " " + dir / "out/part1");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("item " + std::to_string(bad)), std::string::npos) << r.err;
    EXPECT_TRUE(listing(dir / "out").empty());
}

TEST(CliDecimateParts, BadPartsAreCommandLineErrors) {
    TempDir dir;
    const std::string out = dir / "out.part";
    for (const char* part : {"0/3", "4/3", "1/1", "x", "1/", "/3", "2/3x"}) {
        const CliRun r = run("decimate --buffer 20000 --part " + std::string(part) + " " + mesh() + " " + out);
        EXPECT_EQ(r.code, 2) << part << ": " << r.err;
        EXPECT_NE(r.err.find("--part: must be k/K"), std::string::npos) << r.err;
    }
    for (const auto& [args, message] :
         {std::pair{"--part 1/3 --threads 2 " + mesh(), "--threads does not go with it"},
          std::pair{"--part 1/3 - < " + mesh(), "IN must be a file, not '-' or a pipe"},
          std::pair{"--part 1/3 --sort always " + mesh(), "--sort always decimates a sorted stream in one job"},
          std::pair{"--part 1/30 " + mesh(),
                    "make at most 9 ranges (each holds at least --buffer triangles), not 30: "
                    "use --part k/9"},
          std::pair{"--merge " + out + " " + mesh(), "give --part too"},
          std::pair{"--part 1/3 --merge " + out + " " + mesh(), "--merge goes with the merge job, --part 3/3"}}) {
        const CliRun r = run("decimate --buffer 20000 " + args + " " + out);
        EXPECT_EQ(r.code, 2) << args << ": " << r.err;
        EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    }
    EXPECT_TRUE(listing(dir.path()).empty());
    const CliRun help = run("decimate --help > " + dir / "help.txt");
    EXPECT_EQ(help.code, 0);
    const std::string text = slurp(dir / "help.txt");
    EXPECT_NE(text.find("--part"), std::string::npos) << text;
    EXPECT_NE(text.find("--merge"), std::string::npos) << text;
}

TEST(CliDecimateParts, JsonGivesThePartsCountsAndTheMergesParts) {
    TempDir dir;
    const std::string options = "--buffer 20000 -r 0.05";
    CliRun r =
        run("decimate --json " + options + " --part 1/2 " + mesh() + " " + dir / "part1" + " > " + dir / "part.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto part = nlohmann::json::parse(slurp(dir / "part.json"));
    EXPECT_EQ(part["decimate"]["part"], 1);
    EXPECT_EQ(part["decimate"]["parts"], 2);
    EXPECT_EQ(part["decimate"]["part_file_bytes"], std::filesystem::file_size(dir / "part1"));
    EXPECT_EQ(part["triangles_in"], part["decimate"]["range_end"]);
    r = run("decimate --json " + options + " --part 2/2 --merge " + dir / "part1" + " " + mesh() + " " +
            dir / "out.stl > " + dir / "merge.json");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto merge = nlohmann::json::parse(slurp(dir / "merge.json"));
    EXPECT_EQ(merge["decimate"]["parts"], 2);
    EXPECT_EQ(merge["decimate"]["threads"], 1);
    ASSERT_EQ(merge["decimate"]["part_files"].size(), 1u);
    EXPECT_EQ(merge["decimate"]["part_files"][0]["path"], dir / "part1");
    EXPECT_EQ(merge["decimate"]["part_files"][0]["triangles"], part["triangles_out"]);
    EXPECT_EQ(merge["triangles_out"], cli_test::triangles_of(dir / "out.stl"));
}
