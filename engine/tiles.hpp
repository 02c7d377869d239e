// A mesh of any size as OGC 3D Tiles 1.1 (docs/tiles.md): level-of-detail tiles a web viewer
// fetches as the camera needs them, built out of core from the engine's parts.
//
// The tree is an octree over the input's bounding cube: a cell splits while more than
// `tile_triangles` triangles have their centroid in it (counted while the input is read into an
// external sort by cell key, at most 10 levels). Leaves hold the input's triangles at full
// resolution, cut from the sorted stream; the cells above them hold level meshes: level L is a
// streaming decimation of level L + 1 as one mesh (engine::decimate_file, on every core; the
// first from the sorted copy of the input) to about `tile_triangles` per cell of depth L, so the
// tiles of one depth are pieces of one mesh and share their borders vertex for vertex. Triangles
// go to their tiles by an external sort on the cell key (sort::ExternalSorter), so no step holds
// more than a few tiles per thread. A tile's geometricError is measured: the Hausdorff distance
// (compare::compare_meshes) between its content and its children's, plus the largest of theirs,
// 0 at the leaves; so it bounds the distance to full resolution and never grows from parent to
// child.
//
// Content: one GLB a tile (tiles/<depth>/<cell>.glb), written on `threads` threads, positions
// turned y-up as glTF wants them ((x, y, z) as (x, z, -y); 3D Tiles turns them back), with every
// channel the glTF writer keeps and materials with their images embedded in each tile that uses
// them. Compressed, all tiles share one quantization grid over the bounding cube (meshopt: 16
// bits; Draco: 14 bits over the deepest leaves' cells), so a position two tiles share decodes
// to the same float in both. Every three depths a subtree goes to a tileset file of its own
// (tiles/<depth>/<cell>.json, an external tileset), so no JSON file grows with the input.
//
// Memory, within the reader's memory budget: while the input is read, the sort's 3/8, the
// cell counts' 3/16 and the reader's 3/16 (a PLY's vertex table that fits in 3/8 whole, out of
// the sort's share); then up to three tiles per thread in the glTF
// writers (with Draco, their coding tables within an eighth); the decimations'
// (engine/decimate.hpp; their buffers a third of the budget); in the error measure, per
// thread, a tile's children twice (a few times `tile_triangles` triangles, not bounded by the
// budget). Disk: a sorted copy
// of the input and the level meshes in meshstream's triangle stream and the sorts' runs in the
// temporary directory, and the tileset itself, built beside OUTDIR and renamed into place when
// complete; nothing is left of either on an error or a cancel.
#pragma once

#include "engine/progress.hpp"
#include "engine/warnings.hpp"
#include "io/format.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace meshstream::engine {

// A tile's default triangle budget: a GLB of about 1 MB with meshopt (a quick fetch), drawn in
// one call by three.js and CesiumJS; 16-bit indices hold its vertices.
inline constexpr uint64_t kDefaultTileTriangles = 65536;

// Where the model's origin goes on the globe (WGS84): degrees and metres above the ellipsoid.
struct GeoOrigin {
    double longitude = 0, latitude = 0, height = 0;
};

enum class TileCompression : uint8_t { kMeshopt, kDraco, kNone };

struct TilesSettings {
    std::string input;  // a path, or "-" for stdin (spooled)
    std::string input_format;
    std::string outdir;
    uint64_t tile_triangles = kDefaultTileTriangles;
    TileCompression compression = TileCompression::kMeshopt;
    std::optional<GeoOrigin> origin;  // none: the model's own coordinates
    bool overwrite = false;           // replace a non-empty outdir
    unsigned threads = 1;             // the level decimations' ranges
    uint64_t seed = 1;
    io::ReadOptions read;  // memory budget, temporary directory, strict, channels read
};

// One depth of a tileset.
struct TileLevel {
    int depth = 0;
    uint64_t tiles = 0;
    uint64_t leaves = 0;
    uint64_t triangles = 0;
    uint64_t bytes = 0;  // content bytes
    double min_error = 0, max_error = 0;
};

struct TilesResult {
    std::string input_name;
    std::string input_format;
    uint64_t triangles_in = 0;
    std::vector<TileLevel> levels;
    uint64_t tiles = 0, bytes = 0;  // all content, and the tileset's JSON files with it
    uint64_t json_files = 0;        // tileset.json and the external tilesets it references
    uint64_t leaf_bytes = 0;
    double geometric_error = 0;  // the tileset's
    Warnings warnings;
};

// Builds the tileset. Throws io::Error (file and position) for input that cannot be read,
// io::OptionError for settings that cannot work (a non-empty outdir without `overwrite`, a
// tile budget below 256, an origin off the globe), Cancelled once `progress` says so.
TilesResult tile_file(const TilesSettings& settings, ProgressSink& progress);

// What a tileset written by tile_file (or any 3D Tiles 1.x tileset with GLB content) holds:
// tiles, triangles and bytes per depth, geometric errors. Follows external tilesets. Throws
// io::Error naming the file.
struct TilesetSummary {
    std::string version;
    bool placed = false;  // a root transform
    double geometric_error = 0;
    std::vector<TileLevel> levels;
    uint64_t tiles = 0, triangles = 0, bytes = 0, json_files = 0;
};
TilesetSummary summarize_tileset(const std::string& tileset_json);

}  // namespace meshstream::engine
