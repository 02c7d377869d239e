// engine::tile_file and summarize_tileset: the leaves hold every input triangle, each tile's
// content lies in its bounding volume, geometric errors are 0 at the leaves and never grow from
// parent to child, a non-empty directory is refused and kept, a cancel leaves nothing behind.
#include "engine/tiles.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/triangle_input.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>

namespace meshstream {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using Json = nlohmann::json;

const std::string kBunny = std::string(MESHSTREAM_FIXTURES_DIR) + "/bunny_from_draco.bin.stl";  // 69 451 triangles

engine::TilesSettings bunny_settings(const std::string& outdir, engine::TileCompression c) {
    engine::TilesSettings s;
    s.input = kBunny;
    s.outdir = outdir;
    s.tile_triangles = 5000;
    s.compression = c;
    return s;
}

// Walks the tiles: content inside the box (positions turned back to z-up), errors ordered.
struct Walk {
    fs::path dir;
    uint64_t leaf_triangles = 0, tiles = 0, outside = 0;
    int bad_errors = 0;
    double pad = 0;  // beyond the box: none, the boxes are padded by the writer

    void tile(const Json& t, double parent_error) {
        const double e = t["geometricError"].get<double>();
        if (e > parent_error) ++bad_errors;
        const bool leaf = !t.contains("children");
        if (leaf && e != 0) ++bad_errors;
        const std::vector<double> box = t["boundingVolume"]["box"].get<std::vector<double>>();
        if (t.contains("content")) {
            ++tiles;
            io::TriangleInput in(io::open_input((dir / t["content"]["uri"].get<std::string>()).string()),
                                 io::BadTriangles::kKeep);
            io::TriangleChunk chunk;
            while (in.next(chunk)) {
                for (size_t i = 0; i < 3 * chunk.size(); ++i) {
                    const float* p = &chunk.xyz()[3 * i];
                    const double z_up[3] = {p[0], -double(p[2]), p[1]};
                    for (int a = 0; a < 3; ++a)
                        if (std::fabs(z_up[a] - box[size_t(a)]) > box[size_t(4 * a + 3)] + pad) ++outside;
                }
                if (leaf) leaf_triangles += chunk.size();
            }
        }
        if (!leaf)
            for (const Json& c : t["children"]) tile(c, e);
    }
};

class Tiles : public ::testing::TestWithParam<engine::TileCompression> {};

TEST_P(Tiles, LeavesHoldEveryTriangleInsideTheirBoxesWithOrderedErrors) {
    TempDir dir;
    engine::QuietProgress quiet;
    const engine::TilesResult r = engine::tile_file(bunny_settings(dir / "t", GetParam()), quiet);
    EXPECT_EQ(r.triangles_in, 69451u);
    ASSERT_GE(r.levels.size(), 2u);
    EXPECT_EQ(r.levels[0].tiles, 1u);

    std::ifstream f(dir / "t/tileset.json");
    const Json j = Json::parse(f);
    EXPECT_EQ(j["asset"]["version"], "1.1");
    EXPECT_EQ(j["root"]["refine"], "REPLACE");
    Walk w{dir.path() / "t"};
    w.tile(j["root"], j["geometricError"].get<double>());
    EXPECT_EQ(w.leaf_triangles, 69451u);
    EXPECT_EQ(w.tiles, r.tiles);
    EXPECT_EQ(w.outside, 0u);
    EXPECT_EQ(w.bad_errors, 0);
    EXPECT_GT(j["root"]["geometricError"].get<double>(), 0);

    // The root: at most the budget, and at most a quarter of the level below.
    const engine::TilesetSummary sum = engine::summarize_tileset(dir / "t/tileset.json");
    EXPECT_EQ(sum.tiles, r.tiles);
    EXPECT_EQ(sum.version, "1.1");
    EXPECT_EQ(sum.levels[0].triangles, r.levels[0].triangles);
    EXPECT_LE(sum.levels[0].triangles, 5050u);
    EXPECT_LE(sum.levels[0].triangles, sum.levels[1].triangles / 4 + 50);
    EXPECT_GT(sum.levels[0].triangles, 1000u);
}

TEST(Tiles, InASmallMemoryBudgetEveryTriangleIsInTheLeavesAndTilesAboveAreNotRefused) {
    // 4 MiB: the whole bunny would not fit a glTF writer's budget (6.7 MiB), each tile does; the
    // cell counts (a quarter of the budget) go to coarser cells past about 8 000 cells.
    TempDir dir;
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "t", engine::TileCompression::kMeshopt);
    s.read.memory_budget_bytes = uint64_t{4} << 20;
    const engine::TilesResult r = engine::tile_file(s, quiet);
    ASSERT_GE(r.levels.size(), 2u);
    std::ifstream f(dir / "t/tileset.json");
    const Json j = Json::parse(f);
    Walk w{dir.path() / "t"};
    w.tile(j["root"], j["geometricError"].get<double>());
    EXPECT_EQ(w.leaf_triangles, 69451u);
    EXPECT_EQ(w.outside, 0u);
    EXPECT_EQ(w.bad_errors, 0);
    EXPECT_LE(r.levels[0].triangles, 5050u);
}

INSTANTIATE_TEST_SUITE_P(Compressions, Tiles,
                         ::testing::Values(engine::TileCompression::kMeshopt, engine::TileCompression::kNone,
                                           engine::TileCompression::kDraco));

TEST(Tiles, ANonEmptyDirectoryIsRefusedAndKept) {
    TempDir dir;
    fs::create_directories(dir / "t");
    std::ofstream(dir / "t/keep.txt") << "mine";
    engine::QuietProgress quiet;
    try {
        engine::tile_file(bunny_settings(dir / "t", engine::TileCompression::kMeshopt), quiet);
        FAIL() << "a non-empty directory was accepted";
    } catch (const io::OptionError& e) {
        EXPECT_EQ(e.setting(), io::Setting::kOverwrite);
        EXPECT_NE(std::string(e.what()).find("the directory is not empty"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::exists(dir / "t/keep.txt"));
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"t"});

    // --overwrite replaces it, and leaves nothing beside it.
    engine::TilesSettings s = bunny_settings(dir / "t", engine::TileCompression::kMeshopt);
    s.overwrite = true;
    engine::tile_file(s, quiet);
    EXPECT_FALSE(fs::exists(dir / "t/keep.txt"));
    EXPECT_TRUE(fs::exists(dir / "t/tileset.json"));
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"t"});
}

TEST(Tiles, ACancelLeavesNothingBehind) {
    TempDir dir;
    std::atomic<bool> cancel{true};
    engine::QuietProgress cancelled(&cancel);
    EXPECT_THROW(engine::tile_file(bunny_settings(dir / "t", engine::TileCompression::kMeshopt), cancelled),
                 engine::Cancelled);
    EXPECT_TRUE(dir.entries().empty());
}

TEST(Tiles, BadSettingsNameTheSetting) {
    TempDir dir;
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "t", engine::TileCompression::kMeshopt);
    s.tile_triangles = 10;
    try {
        engine::tile_file(s, quiet);
        FAIL();
    } catch (const io::OptionError& e) {
        EXPECT_EQ(e.setting(), io::Setting::kTileTriangles);
        EXPECT_NE(std::string(e.what()).find("at least 256, got 10"), std::string::npos) << e.what();
    }
    s = bunny_settings(dir / "t", engine::TileCompression::kMeshopt);
    s.origin = engine::GeoOrigin{200, 0, 0};
    EXPECT_THROW(engine::tile_file(s, quiet), io::OptionError);
    EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace meshstream
