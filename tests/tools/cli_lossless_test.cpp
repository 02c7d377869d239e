// issue 21 §1: convert and sort are lossless. A generated soup with degenerate triangles (a
// repeated corner, three collinear corners) and repeated triangles goes through `convert` and
// `sort` between every pair of formats that can hold it (io::formats(), glTF also without
// Draco), and comes out as the exact multiset of triangles, bit for bit; convert keeps the
// order too. A format holds the soup when the library writes it and reads it back unchanged;
// STL, PLY, OBJ and the triangle stream must.
#include "io/format.hpp"
#include "io/gltf.hpp"
#include "tools/cli_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace meshstream;
using cli_test::run;
using cli_test::TempDir;

using Triangle = std::array<char, 36>;  // the position bits of one triangle

std::vector<Triangle> soup() {
    std::mt19937 rng(21);
    std::vector<std::array<float, 9>> tris;
    auto at = [](int x, int y) {
        return std::array<float, 3>{0.1f * float(x), 0.1f * float(y), 0.01f * float((x * y) % 7)};
    };
    auto tri = [](std::array<float, 3> a, std::array<float, 3> b, std::array<float, 3> c) {
        return std::array<float, 9>{a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]};
    };
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            tris.push_back(tri(at(x, y), at(x + 1, y), at(x + 1, y + 1)));
            tris.push_back(tri(at(x, y), at(x + 1, y + 1), at(x, y + 1)));
        }
    for (int i = 0; i < 20; ++i) {  // a repeated corner, in each of the three places
        const auto a = at(int(rng() % 9), int(rng() % 9)), b = at(int(rng() % 9), int(rng() % 9));
        tris.push_back(i % 3 == 0 ? tri(a, a, b) : i % 3 == 1 ? tri(a, b, b) : tri(b, a, b));
    }
    for (int i = 0; i < 10; ++i)  // zero area, three distinct corners
        tris.push_back(tri(at(i, 0), at(i + 1, 0), at(i + 3, 0)));
    tris.push_back(tri(at(2, 2), at(2, 2), at(2, 2)));               // one point
    for (int i = 0; i < 15; ++i) tris.push_back(tris[rng() % 128]);  // repeated triangles
    std::shuffle(tris.begin(), tris.end(), rng);
    std::vector<Triangle> out(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) std::memcpy(out[i].data(), tris[i].data(), 36);
    return out;
}

std::vector<Triangle> read_triangles(const std::string& path) {
    io::Input in = io::open_input(path);
    io::TriangleChunk chunk(100);
    std::vector<Triangle> out;
    while (in.reader->next(chunk))
        for (size_t i = 0; i < chunk.size(); ++i) {
            Triangle t;
            std::memcpy(t.data(), &chunk.xyz()[9 * i], 36);
            out.push_back(t);
        }
    return out;
}

std::vector<Triangle> sorted(std::vector<Triangle> tris) {
    std::sort(tris.begin(), tris.end());
    return tris;
}

// One way of writing: a format, with Draco off for glTF when `no_draco`.
struct Variant {
    const io::Format* format;
    bool no_draco;
    std::string label() const { return std::string(format->name) + (no_draco ? " --no-draco" : ""); }
    std::string flags() const { return "--to " + std::string(format->name) + (no_draco ? " --no-draco" : ""); }
    // A name of its own (a .gltf's .bin is named after it) with the format's extension.
    std::string file(const TempDir& dir, const std::string& stem) const {
        std::string ext(format->extensions.substr(0, format->extensions.find(' ')));
        if (ext.empty()) ext = std::string(format->name.substr(0, format->name.find('-')));  // ply-ascii: .ply
        return dir / (stem + "-" + std::string(format->name) + (no_draco ? "-plain" : "") + "." + ext);
    }
};

std::vector<Variant> variants() {
    std::vector<Variant> out;
    for (const io::Format* f : io::formats()) {
        if (f->open_writer == nullptr || f->open_reader == nullptr) continue;
        out.push_back({f, false});
        // --no-draco for the formats that take it (glTF).
        if (f->takes_options != nullptr && f->takes_options(typeid(io::GltfSettings), io::WriteOptions{}))
            out.push_back({f, true});
    }
    return out;
}

TEST(CliLossless, ConvertAndSortKeepEveryTriangleBitForBitBetweenEveryFormatThatHoldsThem) {
    TempDir dir;
    const std::vector<Triangle> tris = soup();
    ASSERT_EQ(tris.size(), 174u);
    // The source soup, written with the library as binary STL (which holds every float).
    const std::string source = dir / "soup.stl";
    {
        io::Output out = io::open_output(source, "stl", io::WriteOptions{});
        io::TriangleChunk chunk(tris.size());
        for (const Triangle& t : tris) std::memcpy(chunk.push_slot(), t.data(), 36);
        out.write(chunk);
        out.finish();
    }
    ASSERT_EQ(read_triangles(source), tris);

    // The formats that hold the soup: written by convert, read back unchanged.
    struct Holder {
        Variant variant;
        std::string path;
        bool keeps_order;
    };
    std::vector<Holder> holders;
    std::string held;
    for (const Variant& v : variants()) {
        const std::string path = v.file(dir, "src");
        cli_test::CliRun r = run("convert " + v.flags() + " " + source + " " + path);
        ASSERT_EQ(r.code, 0) << v.label() << ": " << r.err;
        const std::vector<Triangle> back = read_triangles(path);
        if (sorted(back) != sorted(tris)) continue;
        holders.push_back({v, path, back == tris});
        held += v.label() + " ";
    }
    for (const char* must : {"stl ", "stl-ascii ", "ply ", "ply-ascii ", "obj ", "stream "})
        EXPECT_NE((" " + held).find(std::string(" ") + must), std::string::npos) << must << "not among: " << held;

    for (const Holder& a : holders)
        for (const Holder& b : holders) {
            const std::string what = a.variant.label() + " -> " + b.variant.label();
            const std::string out = b.variant.file(dir, "out");
            cli_test::CliRun c = run("convert " + b.variant.flags() + " " + a.path + " " + out);
            ASSERT_EQ(c.code, 0) << what << ": " << c.err;
            const std::vector<Triangle> converted = read_triangles(out);
            EXPECT_TRUE(sorted(converted) == sorted(tris)) << "convert " << what;
            if (a.keeps_order && b.keeps_order) {
                EXPECT_TRUE(converted == tris) << "convert order " << what;
            }
            cli_test::CliRun s = run("sort " + b.variant.flags() + " " + a.path + " " + out);
            if (s.err.find("Draco compression reorders triangles") != std::string::npos) continue;  // refused, exit 2
            ASSERT_EQ(s.code, 0) << what << ": " << s.err;
            EXPECT_TRUE(sorted(read_triangles(out)) == sorted(tris)) << "sort " << what;
        }
}

// NaN payloads, both infinities and -0 survive binary STL and the triangle stream bit for bit,
// through convert and sort (a permutation: compared as a multiset).
TEST(CliLossless, NanPayloadsInfinitiesAndNegativeZeroSurviveStlAndTheStream) {
    TempDir dir;
    const uint32_t bits[][9] = {
        {0x7fc00000, 0, 0, 0x3f800000, 0, 0, 0, 0x3f800000, 0},           // quiet NaN
        {0xffc01234, 0, 0, 0x3f800000, 0, 0, 0, 0x3f800000, 0},           // negative NaN with a payload
        {0x7f800000, 0, 0, 0x3f800000, 0, 0, 0, 0x3f800000, 0},           // +inf
        {0xff800000, 0, 0, 0x3f800000, 0, 0, 0, 0x3f800000, 0},           // -inf
        {0x80000000, 0x80000000, 0x80000000, 0, 0, 0, 0x40a00000, 0, 0},  // -0 beside +0
    };
    std::vector<Triangle> tris;
    io::TriangleChunk chunk(8);
    for (const auto& t : bits) {
        Triangle tri;
        std::memcpy(tri.data(), t, 36);
        tris.push_back(tri);
        std::memcpy(chunk.push_slot(), t, 36);
    }
    {
        io::Output out = io::open_output(dir / "odd.stl", "stl", io::WriteOptions{});
        out.write(chunk);
        out.finish();
    }
    for (const char* to : {"stl", "stream"}) {
        for (const char* cmd : {"convert", "sort --axis x"}) {
            const std::string out = dir / (std::string("out.") + to);
            cli_test::CliRun r = run(std::string(cmd) + " --to " + to + " " + dir / "odd.stl" + " " + out);
            ASSERT_EQ(r.code, 0) << cmd << " " << to << ": " << r.err;
            const std::vector<Triangle> back = read_triangles(out);
            if (std::string(cmd) == "convert") {
                EXPECT_TRUE(back == tris) << to;
            }
            EXPECT_TRUE(sorted(back) == sorted(tris)) << cmd << " " << to;
        }
    }
}

}  // namespace
