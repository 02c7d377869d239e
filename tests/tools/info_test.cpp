// `meshstream info` through the binary: the channels a file carries (type and components; for
// PLY its properties by element), and the reader's counted warnings, in text and --json; and
// those warnings repeated by the commands that read (tools/common.cpp, note_input_changes).
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;

std::string fixture(const std::string& name) { return std::string(MESHSTREAM_FIXTURES_DIR) + "/" + name; }

// info's stdout for `args` (exit 0 expected).
std::string info(const TempDir& dir, const std::string& args) {
    auto r = run("info " + args + " > " + dir / "info.out");
    EXPECT_EQ(r.code, 0) << r.err;
    return slurp(dir / "info.out");
}

TEST(CliInfo, ListsPlyChannelsAndPropertiesInText) {
    TempDir dir;
    const std::string tetra = info(dir, fixture("ply/cgal_colored_tetra.ply"));
    for (const char* line :
         {"channels:    normal (3 × float), colour (uchar RGB), 1 vertex scalar, 4 face scalars\n",
          "vertex scalars: int id\n", "face scalars: uchar red, uchar green, uchar blue, int label\n",
          "element vertex: 4 × double x y z nx ny nz, uchar red green blue, int id\n",
          "element face: 4 × list uchar int vertex_indices, uchar red green blue, int label\n",
          "warning:     element 'edge' not read: meshstream reads vertices and faces (6)\n"})
        EXPECT_NE(tetra.find(line), std::string::npos) << line << "\n" << tetra;
    EXPECT_NE(info(dir, fixture("ply/cube_uv.ply"))
                  .find("channels:    normal (3 × float), texture coordinates (1 set of 2 × float)\n"),
              std::string::npos);
    EXPECT_NE(info(dir, fixture("ply/float-color.ply")).find("channels:    colour (float RGBA)\n"), std::string::npos);
    EXPECT_NE(info(dir, fixture("gearwheel.bin.stl")).find("channels:    positions only\n"), std::string::npos);
}

TEST(CliInfo, ListsChannelsAndWarningsInJson) {
    TempDir dir;
    nlohmann::json j = nlohmann::json::parse(info(dir, "--json " + fixture("ply/cgal_colored_tetra.ply")));
    const nlohmann::json& c = j["channels"];
    EXPECT_EQ(c["normal"], (nlohmann::json{{"type", "float"}, {"components", 3}}));
    EXPECT_EQ(c["color"], (nlohmann::json{{"type", "uchar"}, {"components", 3}}));
    EXPECT_FALSE(c.contains("uv"));
    EXPECT_EQ(c["vertex_scalars"], nlohmann::json::parse(R"([{"name": "id", "type": "int"}])"));
    EXPECT_EQ(c["face_scalars"].size(), 4u);
    EXPECT_EQ(c["face_scalars"][3], nlohmann::json::parse(R"({"name": "label", "type": "int"})"));
    EXPECT_EQ(c["vertex_id"], true);
    EXPECT_EQ(j["notes"]["element edge"], "6 × int vertex1 vertex2, float confidence");
    ASSERT_EQ(j["warnings"].size(), 1u);
    EXPECT_EQ(j["warnings"][0]["text"], "element 'edge' not read: meshstream reads vertices and faces");
    EXPECT_EQ(j["warnings"][0]["count"], 6);

    j = nlohmann::json::parse(info(dir, "--json " + fixture("ply/cube_uv.ply")));
    EXPECT_EQ(j["channels"]["uv"], (nlohmann::json{{"sets", 1}, {"type", "float"}, {"components", 2}}));
    j = nlohmann::json::parse(info(dir, "--json " + fixture("ply/float-color.ply")));
    EXPECT_EQ(j["channels"]["color"], (nlohmann::json{{"type", "float"}, {"components", 4}}));
    j = nlohmann::json::parse(info(dir, "--json " + fixture("gearwheel.bin.stl")));
    EXPECT_EQ(j["channels"], nlohmann::json::object());
    EXPECT_FALSE(j.contains("warnings"));
}

// The readers' findings name the settings they are about as the library's mentions; info shows
// them with the flag, in text and --json (the OBJ reader's are notes, "warning: ...").
TEST(CliInfo, NamesTheSettingsInTheReadersFindingsByTheirFlags) {
    TempDir dir;
    std::FILE* f = std::fopen((dir / "t.obj").c_str(), "w");
    std::fputs("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n", f);
    std::fclose(f);
    f = std::fopen((dir / "m.mtl").c_str(), "w");
    std::fputs("newmtl a\nKd 1 1 1\nmap_Kd big.png\n", f);
    std::fclose(f);
    f = std::fopen((dir / "big.png").c_str(), "w");
    for (int i = 0; i < 100000; ++i) std::fputc(i & 0xff, f);  // past a budget of 64K
    std::fclose(f);
    const std::string text = info(dir, "--memory 64K " + dir / "t.obj");
    EXPECT_NE(text.find("warning:     texture images past --memory not loaded, kept by name only: "), std::string::npos)
        << text;
    const nlohmann::json j = nlohmann::json::parse(info(dir, "--json --memory 64K " + dir / "t.obj"));
    EXPECT_EQ(j["notes"]["warning"].get<std::string>().rfind("texture images past --memory not loaded", 0), 0u)
        << j["notes"];
}

// A lenient read is reported by info as by the other commands: with the position of the first
// case and the count.
TEST(CliInfo, ShowsLenientReadsWithPositionAndCount) {
    TempDir dir;
    {
        std::FILE* f = std::fopen((dir / "quad.stl").c_str(), "wb");
        ASSERT_NE(f, nullptr);
        std::fputs(
            "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n"
            "endloop\nendfacet\n",
            f);
        std::fclose(f);
    }
    const std::string text = info(dir, dir / "quad.stl");
    EXPECT_NE(text.find("triangles:   2\n"), std::string::npos) << text;
    EXPECT_NE(text.find("warning:     facets with more than 3 vertices split into triangles (at line 2) (1)\n"),
              std::string::npos)
        << text;
    EXPECT_NE(
        text.find("warning:     no 'endsolid' at the end of the file (cut short between facets?) (at line 10) (1)\n"),
        std::string::npos)
        << text;
    nlohmann::json j = nlohmann::json::parse(info(dir, "--json " + dir / "quad.stl"));
    ASSERT_EQ(j["warnings"].size(), 2u);
    EXPECT_EQ(j["warnings"][0]["line"], 2);
    EXPECT_FALSE(j["warnings"][0].contains("byte"));
    // --strict: the first of them is the error, with the file and line.
    auto r = run("info --strict " + dir / "quad.stl");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find(dir / "quad.stl" + ":2: facet with 4 vertices (--strict)"), std::string::npos) << r.err;
}

// The commands that read repeat the reader's warnings once, with the file, position and count.
TEST(CliReaderWarnings, ConvertRepeatsThemWithPositionAndCount) {
    TempDir dir;
    {
        std::FILE* f = std::fopen((dir / "tri.stl").c_str(), "wb");
        ASSERT_NE(f, nullptr);
        std::fputs(
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n"
            "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
            "facet normal 0 0 1\nouter loop\nendloop\nendfacet\nendsolid t\n",
            f);
        std::fclose(f);
    }
    auto r = run("convert " + dir / "tri.stl" + " " + dir / "out.stl");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err, "meshstream: warning: " + dir / "tri.stl" +
                         ": facets with fewer than 3 vertices skipped (first at line 2) (2)\n");
    r = run("convert --strict " + dir / "tri.stl" + " " + dir / "strict.stl");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find(dir / "tri.stl" + ":2: facet with 2 vertices (--strict)"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "strict.stl"));
}

}  // namespace
