// engine::tile_file and summarize_tileset: the leaves hold every input triangle, each tile's
// content lies in its bounding volume, geometric errors are 0 at the leaves and never grow from
// parent to child, a non-empty directory is refused and kept, a cancel leaves nothing behind.
#include "engine/tiles.hpp"
#include "compare/metro.hpp"
#include "compare/topology.hpp"
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/read_indexed.hpp"
#include "io/triangle_input.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

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

// Walks the tiles, into external tilesets: content inside the box (positions turned back to
// z-up), errors ordered, the tiles each JSON file holds.
struct Walk {
    fs::path dir;
    uint64_t leaf_triangles = 0, tiles = 0, outside = 0;
    int bad_errors = 0;
    double pad = 0;  // beyond the box: none, the boxes are padded by the writer
    std::map<std::string, uint64_t> tiles_in_file;  // JSON files (relative to `dir`) and their tiles
    std::vector<fs::path> leaves;                   // the leaves' content

    void file(const fs::path& relative, double parent_error) {
        std::ifstream f(dir / relative);
        ASSERT_TRUE(f) << relative;
        const Json j = Json::parse(f);
        EXPECT_EQ(j["asset"]["version"], "1.1") << relative;
        EXPECT_EQ(j["root"]["refine"], "REPLACE") << relative;
        if (j["geometricError"].get<double>() > parent_error) ++bad_errors;
        tile(j["root"], j["geometricError"].get<double>(), relative);
    }
    void tile(const Json& t, double parent_error, const fs::path& in_file) {
        ++tiles_in_file[in_file.generic_string()];
        const double e = t["geometricError"].get<double>();
        if (e > parent_error) ++bad_errors;
        const bool leaf = !t.contains("children");
        const std::vector<double> box = t["boundingVolume"]["box"].get<std::vector<double>>();
        if (t.contains("content")) {
            const fs::path uri = (in_file.parent_path() / t["content"]["uri"].get<std::string>()).lexically_normal();
            if (uri.extension() == ".json") {
                EXPECT_TRUE(leaf) << "a reference to " << uri << " has children";
                file(uri, e);
                return;
            }
            if (leaf && e != 0) ++bad_errors;
            if (leaf) leaves.push_back(dir / uri);
            ++tiles;
            io::TriangleInput in(io::open_input((dir / uri).string()), io::BadTriangles::kKeep);
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
            for (const Json& c : t["children"]) tile(c, e, in_file);
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
    Walk w;
    w.dir = dir.path() / "t";
    w.file("tileset.json", j["geometricError"].get<double>());
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
    Walk w;
    w.dir = dir.path() / "t";
    w.file("tileset.json", j["geometricError"].get<double>());
    EXPECT_EQ(w.leaf_triangles, 69451u);
    EXPECT_EQ(w.outside, 0u);
    EXPECT_EQ(w.bad_errors, 0);
    EXPECT_LE(r.levels[0].triangles, 5050u);
}

// The boundary and non-manifold edges of these meshes' triangles together, their corners
// welded where they are the same floats.
compare::EdgeCounts welded_edges(const std::vector<fs::path>& meshes) {
    compare::EdgeCounter counter;
    for (const fs::path& m : meshes) {
        io::TriangleInput in(io::open_input(m.string()), io::BadTriangles::kKeep);
        io::TriangleChunk chunk;
        while (in.next(chunk))
            for (size_t t = 0; t < chunk.size(); ++t) counter.add_triangle(&chunk.xyz()[9 * t]);
    }
    return counter.finish();
}

TEST_P(Tiles, TheLeavesWeldedHaveTheInputsBoundaryEdgesExactly) {
    // Leaves of three depths meet on one quantization grid: welded, the only boundary edges are
    // the input's own (the bunny's holes), none is non-manifold.
    TempDir dir;
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "t", GetParam());
    s.tile_triangles = 1000;
    const engine::TilesResult r = engine::tile_file(s, quiet);
    Walk w;
    w.dir = dir.path() / "t";
    w.file("tileset.json", HUGE_VAL);
    std::set<int> leaf_depths;
    for (size_t d = 0; d < r.levels.size(); ++d)
        if (r.levels[d].leaves > 0) leaf_depths.insert(int(d));
    EXPECT_GE(leaf_depths.size(), 2u);
    EXPECT_EQ(w.leaf_triangles, 69451u);
    const compare::EdgeCounts input = welded_edges({kBunny}), leaves = welded_edges(w.leaves);
    EXPECT_GT(input.boundary_edges, 100u);
    EXPECT_EQ(leaves.boundary_edges, input.boundary_edges);
    EXPECT_EQ(leaves.non_manifold_edges, input.non_manifold_edges);
    EXPECT_EQ(leaves.edges, input.edges);
}

// The surface of an axis-aligned box, each face a grid of k × k squares of two triangles.
std::vector<float> box_surface(int k) {
    std::vector<float> tris;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side)
            for (int i = 0; i < k; ++i)
                for (int j = 0; j < k; ++j) {
                    // Corners on the face: (u, v) in the other two axes, outward-facing order.
                    auto corner = [&](int u, int v, float* p) {
                        p[axis] = float(side * k);
                        p[(axis + 1) % 3] = float(side ? u : v);
                        p[(axis + 2) % 3] = float(side ? v : u);
                    };
                    float q[4][3];
                    corner(i, j, q[0]), corner(i + 1, j, q[1]), corner(i + 1, j + 1, q[2]), corner(i, j + 1, q[3]);
                    for (int c : {0, 1, 2, 0, 2, 3}) tris.insert(tris.end(), q[c], q[c] + 3);
                }
    return tris;
}

TEST_P(Tiles, TilesOfOneDepthWeldedAreClosedWhereTheInputIs) {
    // A closed box, 64 × 64 squares a face, at 1 600 triangles a tile: every depth-1 octant
    // holds 6 144 triangles and every depth-2 cell at most 1 536, so all 56 leaves are of depth 2
    // and each depth is the whole surface. Welded, each depth's tiles are closed: they meet at
    // the same vertices, also once quantized.
    TempDir dir;
    const std::vector<float> box = box_surface(64);
    {
        std::ofstream f(dir / "box.stl", std::ios::binary);
        const uint32_t n = uint32_t(box.size() / 9);
        f << std::string(80, ' ');
        f.write(reinterpret_cast<const char*>(&n), 4);
        for (uint32_t t = 0; t < n; ++t) {
            f << std::string(12, '\0');
            f.write(reinterpret_cast<const char*>(&box[9 * size_t(t)]), 36);
            f << std::string(2, '\0');
        }
    }
    ASSERT_EQ(welded_edges({dir / "box.stl"}).boundary_edges, 0u);
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "t", GetParam());
    s.input = dir / "box.stl";
    s.tile_triangles = 1600;
    s.threads = 2;
    const engine::TilesResult r = engine::tile_file(s, quiet);
    ASSERT_EQ(r.levels.size(), 3u);
    EXPECT_EQ(r.levels[1].tiles, 8u);
    EXPECT_EQ(r.levels[2].leaves, 56u);
    for (size_t d = 0; d < r.levels.size(); ++d) {
        std::vector<fs::path> tiles;
        for (const fs::directory_entry& e : fs::directory_iterator(dir.path() / "t/tiles" / std::to_string(d)))
            if (e.path().extension() == ".glb") tiles.push_back(e.path());
        EXPECT_EQ(tiles.size(), r.levels[d].tiles) << d;
        const compare::EdgeCounts e = welded_edges(tiles);
        EXPECT_EQ(e.boundary_edges, 0u) << "depth " << d;
        EXPECT_EQ(e.non_manifold_edges, 0u) << "depth " << d;
        EXPECT_GT(e.edges, 0u) << "depth " << d;
    }
}

INSTANTIATE_TEST_SUITE_P(Compressions, Tiles,
                         ::testing::Values(engine::TileCompression::kMeshopt, engine::TileCompression::kNone,
                                           engine::TileCompression::kDraco));

TEST(Tiles, TheRootsErrorBoundsItsDistanceToTheInputAndIsNotMuchMore) {
    // The root's error sums the errors between depths along the worst path (two here): at least
    // the root content's Hausdorff distance to the input, and not many times it. Measuring each
    // tile against its children alone, as if the neighbours drew nothing, made it 4.5 times.
    TempDir dir;
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "t", engine::TileCompression::kNone);
    const engine::TilesResult r = engine::tile_file(s, quiet);
    ASSERT_EQ(r.levels.size(), 3u);
    std::vector<float> root;
    io::TriangleInput in(io::open_input(dir / "t/tiles/0/0.glb"), io::BadTriangles::kKeep);
    io::TriangleChunk chunk;
    while (in.next(chunk))
        for (size_t i = 0; i < 3 * chunk.size(); ++i) {  // back to z-up
            const float* p = &chunk.xyz()[3 * i];
            root.insert(root.end(), {p[0], -p[2], p[1]});
        }
    compare::CompareOptions co;
    co.edges = false;
    const double direct = compare::compare_meshes(compare::file_source(kBunny), compare::memory_source("root", root), co)
                              .hausdorff();
    EXPECT_GE(r.levels[0].max_error, direct * 0.9);
    EXPECT_LE(r.levels[0].max_error, direct * 3);
}

TEST(Tiles, DeepTreesGoToExternalTilesetsOfThreeDepthsEach) {
    // 300 triangles a tile: five depths, so the subtrees from depth 3 are tileset files of their own.
    TempDir dir;
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "t", engine::TileCompression::kMeshopt);
    s.tile_triangles = 300;
    const engine::TilesResult r = engine::tile_file(s, quiet);
    ASSERT_GE(r.levels.size(), 5u);
    Walk w;
    w.dir = dir.path() / "t";
    w.file("tileset.json", HUGE_VAL);
    EXPECT_EQ(w.leaf_triangles, 69451u);
    EXPECT_EQ(w.tiles, r.tiles);
    EXPECT_EQ(w.outside, 0u);
    EXPECT_EQ(w.bad_errors, 0);
    EXPECT_EQ(w.tiles_in_file.size(), r.json_files);
    EXPECT_GT(r.json_files, 8u);
    for (const auto& [file, tiles] : w.tiles_in_file) {
        EXPECT_LE(tiles, 1u + 8 + 64 + 512) << file;
        if (file != "tileset.json") {
            EXPECT_TRUE(file.starts_with("tiles/3/")) << file;
        }
    }
    // tileset.json holds depths 0 to 2 and the references to depth 3.
    EXPECT_LE(w.tiles_in_file["tileset.json"], r.levels[0].tiles + r.levels[1].tiles + r.levels[2].tiles +
                                                    r.levels[3].tiles);
    const engine::TilesetSummary sum = engine::summarize_tileset(dir / "t/tileset.json");
    EXPECT_EQ(sum.tiles, r.tiles);
    EXPECT_EQ(sum.json_files, r.json_files);
    EXPECT_EQ(sum.bytes, r.bytes);
    ASSERT_EQ(sum.levels.size(), r.levels.size());
    for (size_t d = 0; d < r.levels.size(); ++d) {
        EXPECT_EQ(sum.levels[d].tiles, r.levels[d].tiles) << d;
        EXPECT_EQ(sum.levels[d].triangles, r.levels[d].triangles) << d;
    }
}

// Every file of a directory tree, by relative path, with its bytes.
std::map<std::string, std::string> files_under(const fs::path& root) {
    std::map<std::string, std::string> files;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(root))
        if (e.is_regular_file()) {
            std::ifstream f(e.path(), std::ios::binary);
            files[fs::relative(e.path(), root).string()] = std::string(std::istreambuf_iterator<char>(f), {});
        }
    return files;
}

TEST(Tiles, TilesWrittenOnThreadsAreTheSameRunToRunAndTheLeavesAsOnOne) {
    TempDir dir;
    engine::QuietProgress quiet;
    engine::TilesSettings s = bunny_settings(dir / "one", engine::TileCompression::kMeshopt);
    engine::tile_file(s, quiet);
    s.threads = 2;
    s.outdir = dir / "two";
    const engine::TilesResult two = engine::tile_file(s, quiet);
    s.outdir = dir / "again";
    engine::tile_file(s, quiet);
    const auto one_files = files_under(dir / "one"), two_files = files_under(dir / "two");
    EXPECT_EQ(two_files, files_under(dir / "again"));
    // The leaves hold the input, whatever decimated the levels above.
    const std::string deepest = "tiles/" + std::to_string(two.levels.size() - 1) + "/";
    size_t leaves = 0;
    for (const auto& [path, bytes] : two_files)
        if (path.starts_with(deepest)) {
            ++leaves;
            ASSERT_TRUE(one_files.count(path)) << path;
            EXPECT_EQ(bytes, one_files.at(path)) << path;
        }
    EXPECT_EQ(leaves, two.levels.back().leaves);
    EXPECT_GT(leaves, 8u);
}

// The labels of the phases a call reports.
struct PhaseLabels final : engine::ProgressSink {
    std::vector<std::string> labels;
    void phase(std::string label, std::optional<uint64_t>) override { labels.push_back(std::move(label)); }
    void update(uint64_t) override {}
    void update(uint64_t, uint64_t, std::optional<uint64_t>) override {}
    void status(const std::string&) override {}
    size_t count(const std::string& label) const { return size_t(std::count(labels.begin(), labels.end(), label)); }
};

// `mesh` as a binary PLY (float x, y, z; triangles), with the vertices `extra` after its own,
// used by no face.
void write_ply(const fs::path& path, const io::IndexedMesh& mesh, const std::vector<float>& extra) {
    std::ofstream f(path, std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex " << mesh.vertex_count() + extra.size() / 3
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << mesh.triangle_count()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
    f.write(reinterpret_cast<const char*>(mesh.positions.data()), std::streamsize(mesh.positions.size() * 4));
    f.write(reinterpret_cast<const char*>(extra.data()), std::streamsize(extra.size() * 4));
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
        f.put(3);
        f.write(reinterpret_cast<const char*>(&mesh.indices[3 * t]), 12);
    }
}

TEST(Tiles, APlysCubeIsItsTrianglesEvenWithVerticesNoFaceUsesOutsideThem) {
    // The bunny as a PLY is tiled as the STL is, its box found from its vertices alone (one
    // sort); with a vertex no face uses far outside it, the sort is done again on the
    // triangles' cube, and the tileset is the same; one inside the box changes nothing.
    TempDir dir;
    const io::IndexedMesh bunny = io::read_indexed(kBunny).mesh;
    write_ply(dir / "bunny.ply", bunny, {});
    write_ply(dir / "outside.ply", bunny, {1000, -1000, 1000});
    const io::Bounds box = bunny.bounds();
    write_ply(dir / "inside.ply", bunny,
              {(box.min[0] + box.max[0]) / 2, (box.min[1] + box.max[1]) / 2, (box.min[2] + box.max[2]) / 2});
    engine::TilesSettings s = bunny_settings(dir / "stl", engine::TileCompression::kMeshopt);
    engine::QuietProgress quiet;
    engine::tile_file(s, quiet);
    const std::string sorting = "tiles: leaves: sorting by cell";
    for (const char* name : {"bunny", "outside", "inside"}) {
        SCOPED_TRACE(name);
        s.input = dir / (std::string(name) + ".ply");
        s.outdir = dir / name;
        PhaseLabels phases;
        const engine::TilesResult r = engine::tile_file(s, phases);
        EXPECT_EQ(r.triangles_in, bunny.triangle_count());
        EXPECT_EQ(phases.count("tiles: bounds: bounding box of the vertices"), 1u);
        EXPECT_EQ(phases.count(sorting), std::string(name) == "outside" ? 2u : 1u);
        EXPECT_EQ(files_under(dir / name), files_under(dir / "stl"));
    }
    // On two threads the PLY's corners are looked up on both (io::IndexedReadAhead): the same
    // tileset as the STL's on two threads.
    s.threads = 2;
    s.input = kBunny;
    s.outdir = dir / "stl2";
    engine::tile_file(s, quiet);
    s.input = dir / "outside.ply";
    s.outdir = dir / "ply2";
    engine::tile_file(s, quiet);
    EXPECT_EQ(files_under(dir / "ply2"), files_under(dir / "stl2"));
}

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
