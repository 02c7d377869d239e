// `meshstream compare --attributes` through the binary: colour and normal error in text and
// --json, only the channels both meshes have, exit 2 when they share neither, a coloured
// mesh from meshstream-gen read from stdin and compared with its OBJ copy; and the report
// without the flag left as it was.
#include "tools/cli_util.hpp"
#include "tools/mesh_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace {

using cli_test::run;
using cli_test::slurp;
using cli_test::TempDir;

// An ascii PLY of `tris` (9 floats each, one vertex per corner) with the given channels, the
// same for every corner: uchar red green blue when `rgb` is not null, float nx ny nz when
// `normal` is not null.
void write_ply(const std::string& path, const std::vector<float>& tris, const int* rgb, const float* normal) {
    std::ofstream ply(path);
    ply << "ply\nformat ascii 1.0\nelement vertex " << tris.size() / 3
        << "\nproperty float x\nproperty float y\nproperty float z\n";
    if (normal) ply << "property float nx\nproperty float ny\nproperty float nz\n";
    if (rgb) ply << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    ply << "element face " << tris.size() / 9 << "\nproperty list uchar int vertex_indices\nend_header\n";
    ply.precision(9);
    for (size_t i = 0; i < tris.size(); i += 3) {
        ply << tris[i] << ' ' << tris[i + 1] << ' ' << tris[i + 2];
        if (normal) ply << ' ' << normal[0] << ' ' << normal[1] << ' ' << normal[2];
        if (rgb) ply << ' ' << rgb[0] << ' ' << rgb[1] << ' ' << rgb[2];
        ply << '\n';
    }
    for (size_t t = 0; t < tris.size() / 9; ++t) ply << "3 " << 3 * t << ' ' << 3 * t + 1 << ' ' << 3 * t + 2 << '\n';
}

// compare's stdout for `args`, with the exit code expected.
std::string compare(const TempDir& dir, const std::string& args, int code = 0) {
    const auto r = run("compare -q " + args + " > " + dir / "compare.out");
    EXPECT_EQ(r.code, code) << args << "\n" << r.err;
    return slurp(dir / "compare.out");
}

const std::vector<float>& grid() {
    static const std::vector<float> g = cli_test::grid(20);  // 800 triangles
    return g;
}

TEST(CliCompare, AttributesReportColourAndNormalErrorInTextAndJson) {
    // B: red + 51 (0.2 in 0..1) and the normal turned 30 degrees about x, everywhere.
    TempDir dir;
    const int rgb_a[3] = {100, 50, 200}, rgb_b[3] = {151, 50, 200};
    const float up[3] = {0, 0, 1}, turned[3] = {0, -0.5f, float(std::sqrt(0.75))};
    write_ply(dir / "a.ply", grid(), rgb_a, up);
    write_ply(dir / "b.ply", grid(), rgb_b, turned);
    const std::string files = dir / "a.ply" + " " + dir / "b.ply";

    const std::string text = compare(dir, "--attributes --samples 4000 " + files);
    for (const char* line :
         {"\ncolour error (distance of RGB, each 0..1; alpha ignored):\nA -> B     max 0.2          rms 0.2",
          "\nB -> A     max 0.2          rms 0.2          ", "\nsymmetric  max 0.2          rms 0.2\n",
          "\nnormal error (degrees between the normals; skipped: a zero-length or non-finite "
          "normal):\nA -> B     max 30           rms 30           "})
        EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;

    const nlohmann::json j = nlohmann::json::parse(compare(dir, "--attributes --json --samples 4000 " + files));
    for (const char* direction : {"a_to_b", "b_to_a", "symmetric"}) {
        const nlohmann::json& d = j[direction];
        EXPECT_NEAR(d["color"]["rms"].get<double>(), 0.2, 1e-6) << direction;
        EXPECT_NEAR(d["color"]["max"].get<double>(), 0.2, 1e-6) << direction;
        EXPECT_NEAR(d["normal_degrees"]["rms"].get<double>(), 30, 1e-4) << direction;
        EXPECT_NEAR(d["normal_degrees"]["max"].get<double>(), 30, 1e-4) << direction;
        EXPECT_EQ(d["normal_degrees"]["skipped"], 0) << direction;
    }
    EXPECT_EQ(j["a_to_b"]["color"]["samples"], j["a_to_b"]["samples"]);
    EXPECT_EQ(j["b_to_a"]["normal_degrees"]["samples"], j["b_to_a"]["samples"]);
    EXPECT_EQ(j["symmetric"]["color"]["samples"],
              j["a_to_b"]["samples"].get<uint64_t>() + j["b_to_a"]["samples"].get<uint64_t>());

    // Without the flag the report is the one compare always gave: no attribute figures.
    const std::string plain = compare(dir, "--samples 4000 " + files);
    EXPECT_EQ(plain.find("colour"), std::string::npos) << plain;
    EXPECT_EQ(plain.find("normal"), std::string::npos) << plain;
    EXPECT_EQ(plain, text.substr(0, text.find("colour error")));
    const nlohmann::json p = nlohmann::json::parse(compare(dir, "--json --samples 4000 " + files));
    EXPECT_FALSE(p["a_to_b"].contains("color"));
    EXPECT_FALSE(p["symmetric"].contains("normal_degrees"));
    EXPECT_EQ(p["a_to_b"]["rms"], j["a_to_b"]["rms"]);
}

TEST(CliCompare, AttributesMeasureOnlyTheChannelsBothHave) {
    TempDir dir;
    const int rgb[3] = {10, 20, 30};
    const float up[3] = {0, 0, 1};
    write_ply(dir / "both.ply", grid(), rgb, up);
    write_ply(dir / "colours.ply", grid(), rgb, nullptr);
    write_ply(dir / "normals.ply", grid(), nullptr, up);
    std::ofstream(dir / "plain.stl", std::ios::binary) << cli_test::binary_stl(grid());

    const std::string text =
        compare(dir, "--attributes --samples 2000 " + dir / "both.ply" + " " + dir / "colours.ply");
    EXPECT_NE(text.find("\nsymmetric  max 0            rms 0\nnormal error: not measured (B has no normals)\n"),
              std::string::npos)
        << text;
    const nlohmann::json j = nlohmann::json::parse(
        compare(dir, "--attributes --json --samples 2000 " + dir / "both.ply" + " " + dir / "colours.ply"));
    EXPECT_TRUE(j["a_to_b"]["normal_degrees"].is_null());
    EXPECT_EQ(j["a_to_b"]["color"]["max"], 0.0);

    // Nothing in common: a usage error before any work, naming what each mesh has.
    for (const auto& [a, b, says] :
         {std::tuple<std::string, std::string, std::string>{
              "colours.ply", "normals.ply",
              "A (" + dir / "colours.ply" + ") has colours, B (" + dir / "normals.ply" + ") has normals"},
          {"plain.stl", "both.ply",
           "A (" + dir / "plain.stl" + ") has neither colours nor normals, B (" + dir / "both.ply" +
               ") has colours and normals"}}) {
        const auto r = run("compare --attributes " + dir / a + " " + dir / b + " > " + dir / "out.txt");
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_EQ(r.err,
                  "meshstream: compare: --attributes: no colours or normals in both meshes to compare: " + says + "\n");
        EXPECT_EQ(slurp(dir / "out.txt"), "");
    }
}

TEST(CliCompare, AttributesOfAGeneratedColouredMeshFromStdinAgainstItsObjCopy) {
    // meshstream-gen --color's 8-bit colours, read from stdin (the held mesh) and from an OBJ
    // copy (float colours in the text, 6 digits): the same colours, so ~0 error.
    TempDir dir;
    ASSERT_EQ(std::system(
                  (std::string(MESHSTREAM_GEN_BINARY) + " -q --threads 1 -n 20000 --color " + dir / "gen.ply").c_str()),
              0);
    ASSERT_EQ(run("convert -q " + dir / "gen.ply" + " " + dir / "gen.obj").code, 0);
    const nlohmann::json j = nlohmann::json::parse(
        compare(dir, "--attributes --json --samples 20000 - " + dir / "gen.obj" + " < " + dir / "gen.ply"));
    EXPECT_TRUE(j["a"]["held_in_memory"]);
    EXPECT_GT(j["a_to_b"]["color"]["samples"].get<uint64_t>(), 19'000u);
    EXPECT_GT(j["b_to_a"]["color"]["samples"].get<uint64_t>(), 19'000u);
    EXPECT_LT(j["symmetric"]["color"]["max"].get<double>(), 1e-5);
    EXPECT_TRUE(j["symmetric"]["normal_degrees"].is_null());
}

}  // namespace
