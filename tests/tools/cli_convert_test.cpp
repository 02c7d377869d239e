// `meshstream info` and `convert` through the built binary: the foundation issue's pipe
// acceptance (binary STL -> ASCII on stdout -> stdin -> gzip, then info agrees with the
// original), errors that name the file and position with exit 1 and no output left, exit 2 for
// a bad command line, --help on every command, and a reader's counted warning (OBJ's nameless
// usemtl) against its --strict error.
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

using cli_test::listing;
using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;

const std::string kBunny = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";

nlohmann::json info_json(const std::string& path) {
    std::string out_path = path + ".info.json";
    auto r = run("info --json " + path + " > " + out_path);
    EXPECT_EQ(r.code, 0) << r.err;
    nlohmann::json j = nlohmann::json::parse(slurp(out_path));
    std::remove(out_path.c_str());
    return j;
}

void write_file(const std::string& path, const std::string& bytes) {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
}

TEST(CliConvert, PipeThroughAsciiOnStdoutIntoGzipKeepsCountAndBox) {
    TempDir dir;
    const std::string gz = dir / "out.stl.gz";
    // The first command's stdout feeds the second's stdin, as in the README's pipe example.
    auto r = run("convert " + kBunny + " - --to stl-ascii | " + MESHSTREAM_BINARY + " -q convert - " + gz);
    ASSERT_EQ(r.code, 0) << r.err;
    nlohmann::json a = info_json(kBunny), b = info_json(gz);
    EXPECT_EQ(a["triangles"], 69451);
    EXPECT_EQ(b["triangles"], a["triangles"]);
    EXPECT_EQ(b["bbox_min"], a["bbox_min"]);
    EXPECT_EQ(b["bbox_max"], a["bbox_max"]);
    EXPECT_EQ(b["gzip"], true);
    EXPECT_EQ(b["decoded_bytes"], 84 + 50 * 69451);  // binary STL, by the extension
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"out.stl.gz"}));
}

TEST(CliInfo, ReportsDegenerateTrianglesAndFileSize) {
    // Spider_binary.stl has 56 facets with a repeated corner (corpus MANIFEST).
    nlohmann::json j = info_json(std::string(MESHSTREAM_FIXTURES_DIR) + "/Spider_binary.stl");
    EXPECT_EQ(j["format"], "stl");
    EXPECT_EQ(j["triangles"], 1368);
    EXPECT_EQ(j["degenerate_triangles"], 56);
    EXPECT_EQ(j["file_bytes"], 68484);
}

TEST(CliConvert, TruncatedBinaryStlNamesFileAndByteAndLeavesNothing) {
    TempDir dir;
    const std::string in = dir / "cut.stl";
    std::string bytes = slurp(kBunny);
    write_file(in, bytes.substr(0, 84 + 50 * 1000 + 17));
    auto r = run("convert " + in + " " + (dir / "out.ply"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("meshstream: error: " + in + ": byte 84: header promises 69451 triangles, file holds 1000"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"cut.stl"}));
}

TEST(CliConvert, AsciiStlMissingEndloopNamesLine) {
    TempDir dir;
    const std::string in = dir / "bad.stl";
    write_file(in,
               "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
               " endfacet\nendsolid t\n");
    auto r = run("convert " + in + " " + (dir / "out.stl"));
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find(in + ":7: expected 'endloop', found 'endfacet'"), std::string::npos) << r.err;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"bad.stl"}));
}

// An OBJ `usemtl` without a name reads as the default material with a warning; --strict
// refuses it at its line, with exit 1 and no output.
TEST(CliConvert, NamelessUsemtlIsTheDefaultMaterialOrAStrictError) {
    TempDir dir;
    const std::string in = dir / "in.obj";
    write_file(in, "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\nf 1 2 3\n");
    auto r = run("convert " + in + " " + (dir / "out.stl"));
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + in +
                         ": usemtl statements without a material name read as material 'default', that of faces "
                         "before any usemtl (at line 4, byte 24) (1)\n"),
              std::string::npos)
        << r.err;
    auto strict = run("convert --strict " + in + " " + (dir / "strict.stl"));
    EXPECT_EQ(strict.code, 1);
    EXPECT_NE(strict.err.find("meshstream: error: " + in + ":4: byte 24: 'usemtl' without a material name (--strict)"),
              std::string::npos)
        << strict.err;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"in.obj", "out.stl"}));
}

TEST(CliConvert, BadCommandLineExits2) {
    EXPECT_EQ(run("convert only-one-argument").code, 2);
    EXPECT_EQ(run("no-such-command").code, 2);
    EXPECT_EQ(run("convert " + kBunny + " out.stl --gzip-level 12").code, 2);
}

TEST(CliConvert, QuietWorksAfterTheCommandToo) {
    TempDir dir;
    for (const char* flag : {"-q", "--quiet"}) {
        cli_test::CliRun r = run("convert " + kBunny + " " + dir / "out.stl " + flag);
        EXPECT_EQ(r.code, 0) << flag << ": " << r.err;
        EXPECT_TRUE(std::filesystem::exists(dir / "out.stl")) << flag;
        std::filesystem::remove(dir / "out.stl");
    }
}

TEST(CliConvert, UnknownOutputExtensionIsAnErrorNamingTheFile) {
    TempDir dir;
    // A command line that cannot work: exit 2 before any work, for every writing command.
    for (const char* cmd : {"convert", "decimate", "sort"}) {
        auto r = run(std::string(cmd) + " " + kBunny + " " + (dir / "out.xyz"));
        EXPECT_EQ(r.code, 2) << cmd;
        EXPECT_NE(r.err.find("out.xyz: cannot tell the output format"), std::string::npos) << r.err;
        EXPECT_TRUE(listing(dir.path()).empty());
    }
    auto r = run("convert " + kBunny + " /dev/null");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("/dev/null: cannot tell the output format"), std::string::npos) << r.err;
}

TEST(CliConvert, EveryCommandHasHelp) {
    for (const char* cmd : {"", "info", "convert", "decimate", "sort", "compare"}) {
        auto r = run(std::string(cmd) + " --help > /dev/null");
        EXPECT_EQ(r.code, 0) << cmd << ": " << r.err;
    }
}

}  // namespace

TEST(CliConvert, DroppedVertexColoursAreSaid) {
    TempDir dir;
    const std::string coloured = std::string(MESHSTREAM_FIXTURES_DIR) + "/ply/cactus_vcolor.binary_le.ply";
    cli_test::CliRun stl = run("convert " + coloured + " " + dir / "c.stl");
    EXPECT_EQ(stl.code, 0) << stl.err;
    EXPECT_NE(stl.err.find("warning: colours dropped: stl output carries positions only"), std::string::npos)
        << stl.err;
    // OBJ keeps RGB, not alpha.
    cli_test::CliRun obj =
        run("convert " + std::string(MESHSTREAM_FIXTURES_DIR) + "/ply/float-color.ply " + dir / "c.obj");
    EXPECT_EQ(obj.code, 0) << obj.err;
    EXPECT_NE(obj.err.find("warning: colour alpha dropped: obj output does not carry it"), std::string::npos)
        << obj.err;
    cli_test::CliRun ply = run("convert " + coloured + " " + dir / "c.ply");
    EXPECT_EQ(ply.code, 0) << ply.err;
    EXPECT_EQ(ply.err.find("colours"), std::string::npos) << ply.err;
    // sort and decimate carry the channels the output keeps, and name the others.
    cli_test::CliRun sorted = run("sort " + coloured + " " + dir / "s.ply");
    EXPECT_EQ(sorted.code, 0) << sorted.err;
    EXPECT_EQ(sorted.err.find("colours"), std::string::npos) << sorted.err;
    EXPECT_NE(cli_test::slurp(dir / "s.ply").find("property uchar red\nproperty uchar green\nproperty uchar blue\n"),
              std::string::npos);
    cli_test::CliRun sorted_stl = run("sort " + coloured + " " + dir / "s.stl");
    EXPECT_NE(sorted_stl.err.find("warning: colours dropped: stl output carries positions only"), std::string::npos)
        << sorted_stl.err;
    cli_test::CliRun decimated = run("decimate " + coloured + " " + dir / "d.ply -r 0.5");
    EXPECT_EQ(decimated.code, 0) << decimated.err;
    EXPECT_EQ(decimated.err.find("colours"), std::string::npos) << decimated.err;
    EXPECT_NE(cli_test::slurp(dir / "d.ply").find("property uchar red\nproperty uchar green\nproperty uchar blue\n"),
              std::string::npos);
    cli_test::CliRun decimated_stl = run("decimate " + coloured + " " + dir / "d.stl -r 0.5");
    EXPECT_NE(decimated_stl.err.find("warning: colours dropped: stl output carries positions only"), std::string::npos)
        << decimated_stl.err;
}

TEST(CliConvert, AsciiStlNormalsHaveNoNegativeZeros) {
    // "facet normal 0 -0 1" is valid but reads like a bug: 98 of the bunny's normals had one.
    TempDir dir;
    ASSERT_EQ(run("convert --to stl-ascii " + kBunny + " " + dir / "b.stl").code, 0);
    const std::string text = cli_test::slurp(dir / "b.stl");
    size_t normals = 0;
    for (size_t at = 0; (at = text.find("facet normal ", at)) != std::string::npos; ++normals) {
        const size_t end = text.find('\n', at);
        const std::string line = text.substr(at, end - at) + " ";
        EXPECT_EQ(line.find(" -0 "), std::string::npos) << line;
        at = end;
    }
    EXPECT_EQ(normals, 69451u);
}

TEST(CliConvert, DracoOptionsForOtherOutputsAreSaidToDoNothing) {
    TempDir dir;
    const std::string cube = std::string(MESHSTREAM_FIXTURES_DIR) + "/cube.bin.stl";
    cli_test::CliRun ply = run("convert --normals --draco-qp 10 " + cube + " " + dir / "c.ply");
    EXPECT_EQ(ply.code, 0) << ply.err;
    EXPECT_NE(ply.err.find("warning: --normals, --draco-qp apply to Draco and glTF outputs only: ignored for ply"),
              std::string::npos)
        << ply.err;
    cli_test::CliRun one = run("convert --draco-qp 10 " + cube + " " + dir / "d.ply");
    EXPECT_NE(one.err.find("warning: --draco-qp applies to Draco and glTF outputs only: ignored for ply"),
              std::string::npos)
        << one.err;
    cli_test::CliRun glb = run("convert --normals --draco-qp 10 " + cube + " " + dir / "c.glb");
    EXPECT_EQ(glb.code, 0) << glb.err;
    EXPECT_EQ(glb.err.find("warning"), std::string::npos) << glb.err;
    cli_test::CliRun plain = run("convert --no-draco --draco-cl 9 " + cube + " " + dir / "p.glb");
    EXPECT_EQ(plain.code, 0) << plain.err;
    EXPECT_NE(plain.err.find("warning: --draco-cl applies to Draco compression: ignored with --compress none"),
              std::string::npos)
        << plain.err;
    cli_test::CliRun packed =
        run("convert --compress meshopt --draco-qp 12 --draco-qt 9 " + cube + " " + dir / "m.glb");
    EXPECT_EQ(packed.code, 0) << packed.err;
    EXPECT_NE(packed.err.find("warning: --draco-qp, --draco-qt apply to Draco compression: ignored with --compress "
                              "meshopt"),
              std::string::npos)
        << packed.err;
    cli_test::CliRun drc = run("convert --compress meshopt " + cube + " " + dir / "c.drc");
    EXPECT_EQ(drc.code, 0) << drc.err;
    EXPECT_NE(drc.err.find("warning: --compress applies to glTF outputs; a .drc is always Draco"), std::string::npos)
        << drc.err;
    cli_test::CliRun stl = run("convert --compress none " + cube + " " + dir / "c.stl");
    EXPECT_NE(stl.err.find("warning: --compress applies to Draco and glTF outputs only: ignored for stl"),
              std::string::npos)
        << stl.err;
    // A compression that does not exist, or two ways of saying one, are command-line errors.
    EXPECT_EQ(run("convert --compress zip " + cube + " " + dir / "z.glb").code, 2);
    EXPECT_EQ(run("convert --no-draco --compress meshopt " + cube + " " + dir / "z.glb").code, 2);
    EXPECT_FALSE(std::filesystem::exists(dir / "z.glb"));
}

// --to and --from take a format's extension as well as its name: "--to drc" was refused
// although .drc is the extension every Draco file has.
TEST(CliConvert, FormatsAreNamedByTheirExtensionToo) {
    TempDir dir;
    const std::string cube = std::string(MESHSTREAM_FIXTURES_DIR) + "/cube.bin.stl";
    cli_test::CliRun drc = run("convert --to drc " + cube + " " + dir / "cube.out");
    ASSERT_EQ(drc.code, 0) << drc.err;
    EXPECT_EQ(slurp(dir / "cube.out").substr(0, 5), "DRACO");
    cli_test::CliRun back = run("convert --from drc --to stl " + dir / "cube.out" + " " + dir / "back.stl");
    EXPECT_EQ(back.code, 0) << back.err;
}

// Double coordinates rounded to float are said when they moved, and only then.
TEST(CliConvert, RoundedDoubleCoordinatesAreAWarning) {
    TempDir dir;
    const std::string header =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
        "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    write_file(dir / "utm.ply", header + "500000 4000000.12 100\n500001 4000000 100\n500000 4000001 100.5\n3 0 1 2\n");
    write_file(dir / "exact.ply", header + "0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n");
    auto r = run("convert " + dir / "utm.ply" + " " + dir / "utm.stl");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: " + dir / "utm.ply" +
                         ": coordinates are double, rounded to float: moved by up to 0.12 (at 4000000.12); meshstream "
                         "works in float (32-bit)"),
              std::string::npos)
        << r.err;
    auto e = run("convert " + dir / "exact.ply" + " " + dir / "exact.stl");
    EXPECT_EQ(e.code, 0) << e.err;
    EXPECT_EQ(e.err.find("rounded to float"), std::string::npos) << e.err;
}

// issue 21 §6: on a pipe without --to, meshstream writes its triangle stream, which the next
// command reads as it comes: sort into decimate needs no spool file at all (TMPDIR names no
// directory, and the sort fits in --memory), and the sorted axis travels along.
TEST(CliPipe, SortIntoDecimateStreamsWithoutASpool) {
    TempDir dir;
    const std::string glb = dir / "out.glb";
    cli_test::CliRun r = run("sort --memory 64M " + kBunny + " - | TMPDIR=/nonexistent/tmp " + MESHSTREAM_BINARY +
                                 " decimate - " + glb + " -r 0.01",
                             "TMPDIR=/nonexistent/tmp");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("sorted along x (ascending)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("triangles in 69451, out 695"), std::string::npos) << r.err;
    nlohmann::json j = info_json(glb);
    EXPECT_EQ(j["triangles"], 695);
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"out.glb"}));
    // Into a file, stdout gets the format its --to says; without --to a file is refused.
    cli_test::CliRun to_file = run("convert " + kBunny + " - > " + dir / "x");
    EXPECT_EQ(to_file.code, 2) << to_file.err;
    // --to stl to a pipe still works: binary STL spools its body until it knows the count.
    cli_test::CliRun stl = run("convert --clean --to stl " + kBunny + " - | cat > " + dir / "piped.stl");
    ASSERT_EQ(stl.code, 0) << stl.err;
    ASSERT_EQ(run("convert " + kBunny + " " + dir / "direct.stl").code, 0);
    EXPECT_TRUE(slurp(dir / "piped.stl") == slurp(dir / "direct.stl"));
}

// The stream carries what STL cannot: a PLY's colours survive a pipe between two commands.
TEST(CliPipe, TheStreamCarriesEveryChannel) {
    TempDir dir;
    const std::string coloured = std::string(MESHSTREAM_FIXTURES_DIR) + "/ply/cactus_vcolor.binary_le.ply";
    cli_test::CliRun r = run("convert " + coloured + " - | " + MESHSTREAM_BINARY + " -q convert - " + dir / "c.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    cli_test::CliRun direct = run("convert " + coloured + " " + dir / "d.ply");
    ASSERT_EQ(direct.code, 0) << direct.err;
    EXPECT_EQ(slurp(dir / "c.ply"), slurp(dir / "d.ply"));
    EXPECT_NE(slurp(dir / "c.ply").find("property uchar red"), std::string::npos);
}

// --drop: the channels named are not read and their loss goes unsaid; the others are kept, and
// what the output cannot hold is still named.
TEST(CliConvert, DropIsSilentAndKeepsTheRest) {
    TempDir dir;
    const std::string in = dir / "nc.ply";
    {
        std::ofstream f(in);
        f << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "property float nx\nproperty float ny\nproperty float nz\n"
             "property uchar red\nproperty uchar green\nproperty uchar blue\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 0 255 0\n0 1 0 0 0 1 0 0 255\n3 0 1 2\n";
    }
    for (const char* cmd : {"convert", "sort"}) {
        SCOPED_TRACE(cmd);
        const std::string out = dir / (std::string(cmd) + ".ply");
        const cli_test::CliRun kept = run(std::string(cmd) + " --drop colors " + in + " " + out);
        EXPECT_EQ(kept.code, 0) << kept.err;
        EXPECT_EQ(kept.err, "");
        const std::string text = slurp(out);
        EXPECT_NE(text.find("property float nx\nproperty float ny\nproperty float nz\n"), std::string::npos) << text;
        EXPECT_EQ(text.find("red"), std::string::npos) << text;

        // Without --drop, STL names what it loses; with it, only what was not dropped.
        const cli_test::CliRun stl = run(std::string(cmd) + " " + in + " " + dir / "a.stl");
        EXPECT_EQ(stl.code, 0) << stl.err;
        EXPECT_NE(stl.err.find("warning: normals, colours dropped: stl output carries positions only"),
                  std::string::npos)
            << stl.err;
        const cli_test::CliRun some = run(std::string(cmd) + " --drop colors " + in + " " + dir / "b.stl");
        EXPECT_NE(some.err.find("warning: normals dropped: stl output carries positions only"), std::string::npos)
            << some.err;
        const cli_test::CliRun none = run(std::string(cmd) + " --drop normals,colors " + in + " " + dir / "c.stl");
        EXPECT_EQ(none.code, 0) << none.err;
        EXPECT_EQ(none.err, "");

        const cli_test::CliRun bad = run(std::string(cmd) + " --drop normals,colours " + in + " " + dir / "d.stl");
        EXPECT_EQ(bad.code, 2);
        EXPECT_NE(bad.err.find("unknown channel 'colours'"), std::string::npos) << bad.err;
        EXPECT_FALSE(std::filesystem::exists(dir / "d.stl"));
    }
}

TEST(CliConvert, GltfAndDracoKeepTheirChannelsAndSayWhatTheyDrop) {
    TempDir dir;
    const std::string fixtures = MESHSTREAM_FIXTURES_DIR;
    const std::string box = fixtures + "/gltf/BoxTextured.glb";
    // glTF holds normals, texture coordinates and the textured material: nothing to say.
    for (const char* compress : {"draco", "meshopt", "none"}) {
        cli_test::CliRun glb = run("convert " + box + " " + dir / "b.glb --compress " + compress);
        EXPECT_EQ(glb.code, 0) << glb.err;
        EXPECT_EQ(glb.err.find("dropped"), std::string::npos) << compress << ": " << glb.err;
    }
    cli_test::CliRun stl = run("convert " + box + " " + dir / "b.stl");
    EXPECT_NE(
        stl.err.find("warning: normals, texture coordinates, materials dropped: stl output carries positions only"),
        std::string::npos)
        << stl.err;
    // Draco keeps the normals and texture coordinates, not the material.
    cli_test::CliRun drc = run("convert " + box + " " + dir / "b.drc");
    EXPECT_EQ(drc.code, 0) << drc.err;
    EXPECT_NE(drc.err.find("warning: materials dropped: draco output"), std::string::npos) << drc.err;
    EXPECT_EQ(drc.err.find("normals"), std::string::npos) << drc.err;
    cli_test::CliRun dropped = run("convert " + box + " " + dir / "c.drc --drop materials");
    EXPECT_EQ(dropped.code, 0) << dropped.err;
    EXPECT_EQ(dropped.err.find("dropped"), std::string::npos) << dropped.err;
    // Named vertex scalars are Draco generic attributes, which glTF does not carry.
    const std::string tetra = fixtures + "/ply/cgal_colored_tetra.ply";
    cli_test::CliRun tetra_drc = run("convert " + tetra + " " + dir / "t.drc");
    EXPECT_EQ(tetra_drc.code, 0) << tetra_drc.err;
    EXPECT_EQ(tetra_drc.err.find("vertex property 'id'"), std::string::npos) << tetra_drc.err;
    EXPECT_NE(tetra_drc.err.find("face property 'label'"), std::string::npos) << tetra_drc.err;
    cli_test::CliRun tetra_glb = run("convert " + tetra + " " + dir / "t.glb");
    EXPECT_NE(tetra_glb.err.find("vertex property 'id'"), std::string::npos) << tetra_glb.err;
    EXPECT_EQ(tetra_glb.err.find("colour"), std::string::npos) << tetra_glb.err;
}

// The progress bar, on a terminal (script(1) gives the command one): percent and ETA from the
// bytes read of the file, so also for a gzip-compressed ASCII STL, which states no count; the
// line is cleared at the end; -q draws nothing.
TEST(CliProgress, PercentFromTheFilesBytesAndClearedAtTheEnd) {
    TempDir dir;
    const std::string gz = std::string(MESHSTREAM_FIXTURES_DIR) + "/gearwheel.ascii.stl.gz";
    const auto on_terminal = [&](const std::string& args) {
        const std::string out = dir / "tty.txt";
        const std::string cmd =
            "TERM=xterm script -qec \"" + std::string(MESHSTREAM_BINARY) + " " + args + "\" /dev/null > " + out;
        EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
        return slurp(out);
    };
    for (const std::string cmd : {"convert", "decimate -r 0.5", "sort --axis z"}) {
        SCOPED_TRACE(cmd);
        const std::string tty = on_terminal(cmd + " " + gz + " " + dir / "out.stl");
        EXPECT_NE(tty.find("100.0% 2444 triangles"), std::string::npos) << tty;
        EXPECT_NE(tty.find("ETA"), std::string::npos) << tty;
        // Every frame is cleared: nothing of a bar after the last clear.
        const size_t cleared = tty.rfind("\r\x1b[K");
        ASSERT_NE(cleared, std::string::npos) << tty;
        EXPECT_EQ(tty.find("ETA", cleared), std::string::npos) << tty;
        const std::string quiet = on_terminal("-q " + cmd + " " + gz + " " + dir / "out.stl");
        EXPECT_EQ(quiet.find("\x1b[K"), std::string::npos) << quiet;
    }
}

// -q silences summaries, not warnings.
TEST(CliProgress, QuietKeepsWarnings) {
    TempDir dir;
    const std::string coloured = std::string(MESHSTREAM_FIXTURES_DIR) + "/ply/cactus_vcolor.binary_le.ply";
    const cli_test::CliRun loud = run("decimate -r 0.5 " + coloured + " " + dir / "d.stl");
    EXPECT_NE(loud.err.find("triangles in 1236, out 618"), std::string::npos) << loud.err;
    for (const std::string q : {"-q decimate", "decimate -q"}) {
        const cli_test::CliRun quiet = run(q + " -r 0.5 " + coloured + " " + dir / "d.stl");
        EXPECT_EQ(quiet.code, 0);
        EXPECT_EQ(quiet.err, "meshstream: warning: colours dropped: stl output carries positions only\n");
    }
}
