// `meshstream decimate` with channels: colours, normals and uvs carried through to the output,
// what is said when the output cannot hold them, --weights and --drop, and the paths that decimate
// positions only (ranges, a spooled stream).
#include "io/format.hpp"
#include "tools/cli_util.hpp"
#ifdef MESHSTREAM_RENDER_GLTF
#include "io/render_util.hpp"
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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

// `out`, decimated from `in` at 10 %: coloured, the exact count, and colours within the input's
// range (interpolated, not invented).
void expect_coloured_tenth(const Read& in, const std::string& out) {
    const Read after = read_back(out);
    ASSERT_TRUE(after.channels.color.has_value());
    EXPECT_EQ(after.triangles, uint64_t(std::llround(0.1 * double(in.triangles))));
    EXPECT_GE(after.colour_min, in.colour_min - 1.0 / 255);
    EXPECT_LE(after.colour_max, in.colour_max + 1.0 / 255);
    EXPECT_GT(after.colour_max - after.colour_min, 0.5 * (in.colour_max - in.colour_min));
}

}  // namespace

TEST(CliDecimateChannels, ColoursAreKeptAndSaidNothingAbout) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 20000);
    const Read before = read_back(in);
    CliRun r = run("decimate -r 0.1 --threads 1 " + in + " " + dir / "out.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    expect_coloured_tenth(before, dir / "out.ply");
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
    expect_coloured_tenth(before, dir / "two.ply");
    // The same run again: the same bytes.
    ASSERT_EQ(run(common + "--threads 2 " + dir / "again.ply > /dev/null").code, 0);
    EXPECT_EQ(cli_test::slurp(dir / "two.ply"), cli_test::slurp(dir / "again.ply"));
}

TEST(CliDecimateChannels, AStreamWithColoursIsSpooledAndSortedWithThem) {
    TempDir dir;
    const std::string in = coloured_mesh(dir, 20000);
    const Read before = read_back(in);
    // A shuffled copy: in no streaming order, so --sort auto sorts it (from the spool of stdin).
    ASSERT_EQ(std::system((std::string(MESHSTREAM_GEN_BINARY) + " -q --color --shuffle -n 20000 --tmpdir " +
                           dir.path().string() + " " + dir / "shuffled.ply")
                              .c_str()),
              0);
    for (const std::string sort : {"always", "auto"}) {
        SCOPED_TRACE(sort);
        const CliRun r = run("decimate --sort " + sort + " --buffer 2000 -r 0.1 --json - " + dir / "out.ply" +
                             " --from ply < " + dir / "shuffled.ply" + " > " + dir / "out.json");
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_NE(cli_test::slurp(dir / "out.json").find("\"sorted_first\""), std::string::npos)
            << cli_test::slurp(dir / "out.json");
        expect_coloured_tenth(before, dir / "out.ply");
    }
    // Sorted from a file, the colours come through the sort too.
    const CliRun r = run("decimate --sort always -r 0.1 " + in + " " + dir / "sorted.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    expect_coloured_tenth(before, dir / "sorted.ply");
}

#ifdef MESHSTREAM_RENDER_GLTF
namespace {

// A textured UV sphere (OBJ with a material whose map_Kd is BoxTextured's logo): `n` × n/2 quads,
// u = longitude / 2π, v = latitude / π. The meridian u = 0 ≡ 1 is a UV seam (its corners have u 0
// on one side, 1 on the other), and each pole's corners differ in u.
std::string textured_sphere(const TempDir& dir, int n) {
    const int rows = n / 2;
    std::ofstream obj(dir / "sphere.obj"), mtl(dir / "sphere.mtl");
    mtl << "newmtl logo\nKd 1 1 1\nmap_Kd CesiumLogoFlat.png\n";
    std::filesystem::copy_file(std::string(MESHSTREAM_FIXTURES_DIR) + "/gltf/BoxTextured_external/CesiumLogoFlat.png",
                               dir / "CesiumLogoFlat.png");
    obj << "mtllib sphere.mtl\nusemtl logo\n";
    const double pi = 3.14159265358979323846;
    // Positions: the two poles, then rows 1 .. rows-1 of n each.
    obj << "v 0 1 0\nv 0 -1 0\n";
    for (int j = 1; j < rows; ++j)
        for (int i = 0; i < n; ++i) {
            const double t = pi * j / rows, f = 2 * pi * i / n;
            obj << "v " << std::sin(t) * std::cos(f) << ' ' << std::cos(t) << ' ' << std::sin(t) * std::sin(f) << '\n';
        }
    for (int j = 0; j <= rows; ++j)
        for (int i = 0; i <= n; ++i) obj << "vt " << double(i) / n << ' ' << 1 - double(j) / rows << '\n';
    auto v = [&](int i, int j) { return j == 0 ? 1 : j == rows ? 2 : 3 + (j - 1) * n + i % n; };
    auto vt = [&](int i, int j) { return 1 + j * (n + 1) + i; };
    auto corner = [&](int i, int j) { return std::to_string(v(i, j)) + "/" + std::to_string(vt(i, j)); };
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < n; ++i) {
            if (j > 0) obj << "f " << corner(i, j) << ' ' << corner(i + 1, j) << ' ' << corner(i + 1, j + 1) << '\n';
            if (j < rows - 1)
                obj << "f " << corner(i, j) << ' ' << corner(i + 1, j + 1) << ' ' << corner(i, j + 1) << '\n';
        }
    return dir / "sphere.obj";
}

// Per triangle: the extent of u and the ratio of UV area to surface area.
struct UvShape {
    double widest_u = 0, largest_ratio = 0;
    uint64_t triangles = 0;
    bool has_uv = false, has_material = false;
};

UvShape uv_shape(const std::string& path) {
    io::Input in = io::open_input(path);
    const io::Channels channels = in.reader->header().channels;
    UvShape s;
    s.has_uv = channels.uv_sets > 0;
    s.has_material = channels.material;
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    while (in.reader->next(chunk))
        for (size_t t = 0; t < chunk.size(); ++t, ++s.triangles) {
            if (!s.has_uv) continue;
            const float* p = &chunk.xyz()[9 * t];
            const float* uv = chunk.uv_at(t, 0);
            double e1[3], e2[3];
            for (int a = 0; a < 3; ++a) e1[a] = p[3 + a] - p[a], e2[a] = p[6 + a] - p[a];
            const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
                         cz = e1[0] * e2[1] - e1[1] * e2[0];
            const double area = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
            const double uv_area =
                0.5 * std::fabs((uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[4] - uv[0]) * (uv[3] - uv[1]));
            s.widest_u =
                std::max({s.widest_u, double(std::max({uv[0], uv[2], uv[4]}) - std::min({uv[0], uv[2], uv[4]}))});
            if (area > 0) s.largest_ratio = std::max(s.largest_ratio, uv_area / area);
        }
    return s;
}

}  // namespace

TEST(CliDecimateChannels, ATexturedSphereKeepsItsSeamAndRendersTextured) {
    TempDir dir;
    const std::string sphere = textured_sphere(dir, 96);
    ASSERT_EQ(run("convert " + sphere + " " + dir / "sphere.glb").code, 0);
    CliRun r = run("decimate -r 0.25 " + sphere + " " + dir / "quarter.glb");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    const UvShape in = uv_shape(dir / "sphere.glb"), out = uv_shape(dir / "quarter.glb");
    ASSERT_TRUE(out.has_uv && out.has_material);
    EXPECT_EQ(out.triangles, uint64_t(std::llround(0.25 * double(in.triangles))));
    // No triangle spans the seam (one that did would reach across u, 0 to 1), and none stretches
    // the texture past what the input's own triangles do.
    EXPECT_LT(in.widest_u, 0.1);
    EXPECT_LT(out.widest_u, 0.5);
    EXPECT_LE(out.largest_ratio, 1.25 * in.largest_ratio);
    // three.js shows the decimated sphere with its texture as it shows the input.
    const nlohmann::json report = web_test::render(dir, {dir / "sphere.glb", dir / "quarter.glb"});
    ASSERT_EQ(report.size(), 2u);
    const nlohmann::json &a = report[0], &b = report[1];
    EXPECT_GT(a["saturated"].get<double>(), 0.2) << a.dump();
    EXPECT_NEAR(b["covered"].get<double>(), a["covered"].get<double>(), 0.02) << b.dump();
    EXPECT_NEAR(b["saturated"].get<double>(), a["saturated"].get<double>(), 0.05) << b.dump();
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(b["mean"][c].get<double>(), a["mean"][c].get<double>(), 8.0) << c;
}
#endif

TEST(CliDecimateChannels, MaterialsStayOnTheirSideThroughRanges) {
    // A flat 130 × 130 grid, material "left" where x < 0.5 and "right" beyond; named in an OBJ
    // whose second material first appears half-way through the faces.
    TempDir dir;
    const int n = 130;
    {
        std::ofstream mtl(dir / "two.mtl");
        mtl << "newmtl left\nKd 1 0 0\nnewmtl right\nKd 0 0 1\n";
        std::ofstream obj(dir / "two.obj");
        obj << "mtllib two.mtl\n";
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) obj << "v " << double(i) / n << ' ' << double(j) / n << " 0\n";
        auto v = [&](int i, int j) { return 1 + j * (n + 1) + i; };
        for (const bool left : {true, false}) {
            obj << "usemtl " << (left ? "left" : "right") << '\n';
            for (int j = 0; j < n; ++j)
                for (int i = left ? 0 : n / 2; i < (left ? n / 2 : n); ++i)
                    obj << "f " << v(i, j) << ' ' << v(i + 1, j) << ' ' << v(i + 1, j + 1) << "\nf " << v(i, j) << ' '
                        << v(i + 1, j + 1) << ' ' << v(i, j + 1) << '\n';
        }
    }
    const CliRun r = run("decimate -r 0.1 --threads 2 --buffer 16384 " + dir / "two.obj" + " " + dir / "out.glb");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    io::Input in = io::open_input(dir / "out.glb");
    const io::MeshHeader header = in.reader->header();
    ASSERT_TRUE(header.channels.material);
    ASSERT_EQ(header.materials.size(), 2u);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, header.channels);
    uint64_t triangles = 0, wrong_side = 0;
    while (in.reader->next(chunk))
        for (size_t t = 0; t < chunk.size(); ++t, ++triangles) {
            const float* p = &chunk.xyz()[9 * t];
            const double x = (double(p[0]) + p[3] + p[6]) / 3;
            const std::string& name = header.materials[*chunk.material_at(t)].name;
            wrong_side += (x < 0.5) != (name == "left");
        }
    EXPECT_EQ(triangles, uint64_t(std::llround(0.1 * 2 * n * n)));
    EXPECT_EQ(wrong_side, 0u);
}

TEST(CliDecimateChannels, NonFiniteColourValuesAreReadAsZeroAndCounted) {
    TempDir dir;
    std::ofstream(dir / "nan.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                      "property float z\nproperty float red\nproperty float green\nproperty float "
                                      "blue\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                                      "0 0 0 1 0 0\n1 0 0 nan 0 0\n1 1 0 0 1 0\n0 1 0 0 0 1\n3 0 1 2\n3 0 2 3\n";
    const CliRun r = run("decimate -r 1 " + dir / "nan.ply" + " " + dir / "out.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: non-finite normal, colour, texture or scalar values read as 0 (1)"),
              std::string::npos)
        << r.err;
    const Read out = read_back(dir / "out.ply");
    EXPECT_EQ(out.triangles, 2u);
    EXPECT_GE(out.colour_min, 0.0);  // the NaN came out as 0, not as garbage
}

TEST(CliDecimateChannels, VertexAndFaceScalarsComeThrough) {
    // A flat 40 × 40 grid: vertex "intensity" = x, a linear field, and face "label" 1 left of
    // x = 0.5, 2 right of it.
    TempDir dir;
    const int n = 40;
    {
        std::ofstream ply(dir / "scalars.ply");
        ply << "ply\nformat ascii 1.0\nelement vertex " << (n + 1) * (n + 1)
            << "\nproperty float x\nproperty float y\nproperty float z\nproperty float intensity\nelement face "
            << 2 * n * n << "\nproperty list uchar int vertex_indices\nproperty int label\nend_header\n";
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) ply << double(i) / n << ' ' << double(j) / n << " 0 " << double(i) / n << '\n';
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const int a = j * (n + 1) + i, label = i < n / 2 ? 1 : 2;
                ply << "3 " << a << ' ' << a + 1 << ' ' << a + n + 2 << ' ' << label << "\n3 " << a << ' ' << a + n + 2
                    << ' ' << a + n + 1 << ' ' << label << '\n';
            }
    }
    const CliRun r = run("decimate -r 0.1 --weights intensity=1 " + dir / "scalars.ply" + " " + dir / "out.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    io::Input in = io::open_input(dir / "out.ply");
    const io::Channels channels = in.reader->header().channels;
    ASSERT_EQ(channels.vertex_scalars.size(), 1u);
    ASSERT_EQ(channels.face_scalars.size(), 1u);
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, channels);
    uint64_t triangles = 0, on_their_side = 0;
    double worst = 0;
    while (in.reader->next(chunk))
        for (size_t t = 0; t < chunk.size(); ++t, ++triangles) {
            for (int k = 0; k < 3; ++k)  // the field is linear: exact wherever a vertex went
                worst = std::max(worst, std::fabs(chunk.vertex_scalar_at(t, 0)[k] - chunk.xyz()[9 * t + 3 * k]));
            const double x = (double(chunk.xyz()[9 * t]) + chunk.xyz()[9 * t + 3] + chunk.xyz()[9 * t + 6]) / 3;
            // A face scalar travels with its triangle (it is no border, as a material is): most
            // triangles still lie on their label's side.
            const double label = *chunk.face_scalar_at(t, 0);
            EXPECT_TRUE(label == 1 || label == 2) << label;
            on_their_side += (x < 0.5) == (label == 1);
        }
    EXPECT_EQ(triangles, uint64_t(0.1 * 2 * n * n));
    EXPECT_GT(on_their_side, 0.9 * double(triangles));
    EXPECT_LT(worst, 1e-4);
}

TEST(CliDecimateChannels, DoubleVertexScalarsAreSaidToBeRoundedToFloat) {
    TempDir dir;
    std::ofstream(dir / "d.ply") << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                                    "property float z\nproperty double t\nelement face 2\nproperty list uchar int "
                                    "vertex_indices\nend_header\n0 0 0 0.1\n1 0 0 0.2\n1 1 0 0.3\n0 1 0 0.4\n"
                                    "3 0 1 2\n3 0 2 3\n";
    const CliRun r = run("decimate -r 1 " + dir / "d.ply" + " " + dir / "out.ply");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: vertex scalars 't' (double) carried through decimation as float"), std::string::npos)
        << r.err;
}
