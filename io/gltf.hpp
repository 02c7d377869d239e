// glTF 2.0: binary `.glb` and JSON `.gltf` (+ `.bin` side file). Reading through tinygltf
// (Debian libtinygltf-dev, the compiled library); KHR_draco_mesh_compression through Draco and
// EXT_meshopt_compression through libmeshoptimizer (Debian libmeshoptimizer-dev), both ways.
// Memory class: whole document. The writer indexes the soup in memory (io/mesh_index.hpp) and
// serialises at finish(); it refuses cleanly once its estimate passes --memory. The reader
// reads the whole document (and its external buffers) into memory, because tinygltf parses
// from memory, and refuses documents larger than --memory.
//
// Writer: one mesh on one node of the default scene, one TRIANGLES primitive per material
// (one in all without materials), each with its own vertices; asset.generator
// "meshstream <version>". Every triangle is kept, degenerate ones too, except with Draco,
// whose encoder drops those with a repeated vertex, and those with a NaN or infinite
// coordinate, which no accessor may hold: both are counted in notes() (errors under --strict).
// --compress (GltfSettings, in WriteOptions::format_options) chooses the encoding:
// - draco (the default): each primitive carries KHR_draco_mesh_compression (in extensionsUsed
//   and extensionsRequired), encoded with io/draco.hpp's DracoSettings; its accessors have no
//   bufferView but the decoded count, min and max (in a build without Draco: none instead);
// - meshopt: as gltfpack -cc: positions quantized to 14-bit unsigned integers
//   (KHR_mesh_quantization) over the mesh's bounding cube, the node's translation and uniform
//   scale undoing it; triangles reordered for the vertex cache (meshopt_optimizeVertexCacheStrip,
//   unless the stream is sorted: WriteOptions::sorted_axis keeps the order) and vertices by first
//   use; every vertex and index stream compressed with meshoptimizer's codecs (index codec
//   version 1) in buffer 0, the views in a data-less fallback buffer (EXT_meshopt_compression
//   and KHR_mesh_quantization required); normals 8-bit octahedral (OCTAHEDRAL filter);
// - none: float POSITION with exact min/max, indices of the smallest type that fits (restart
//   values excluded).
// --normals adds area-weighted smooth normals to a mesh without its own. `.gltf` writes its
// buffer to `<stem>.bin` beside it (committed atomically with it); to stdout the buffer is
// embedded as a base64 data URI. An empty mesh becomes a valid document with an empty scene.
//
// Reader: the default scene's node tree (or, without scenes, every mesh once) with node
// transforms applied, so the soup is in world space; winding is flipped under mirroring
// transforms. Channels: NORMAL (turned by the transform's inverse transpose), COLOR_0,
// TEXCOORD_0-3 (the material's KHR_texture_transform applied, v flipped to point up),
// materials (name, base colour factor, base colour texture with its image bytes), and a
// vertex id per (instance, primitive, vertex); a channel some primitives lack gets its default
// there (normal 0, colour opaque white, uv 0; glTF's default material). Images are kept as bytes,
// never decoded: the whole document is held anyway, external images on top. TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN
// are read (with or without indices, Draco or plain accessors, KHR_mesh_quantization's integer positions,
// EXT_meshopt_compression bufferViews decoded with libmeshoptimizer and its filters); points and lines, sparse
// accessors and other required extensions are refused with an io::Error naming the file and
// the mesh, primitive or extension, as are compressed bufferViews whose parameters the spec
// forbids or whose streams do not decode; JSON nested deeper than 512 arrays and objects, or
// ending inside one, is refused at its byte before any parser sees it. Buffer files are read
// from the document's directory only (the current one for stdin). Decoded meshopt bufferViews
// are held with the document and count against --memory.
#pragma once

#include "io/format.hpp"

#include <cstdint>
#include <optional>
#include <span>

namespace meshstream::io {

extern const Format kGlbFormat;   // "glb": binary glTF
extern const Format kGltfFormat;  // "gltf": JSON glTF with a .bin side file

// glTF's own write options: set them with WriteOptions::format_options.set(GltfSettings{...});
// unset, these defaults apply.
struct GltfSettings {
    // --compress: KHR_draco_mesh_compression, EXT_meshopt_compression with
    // KHR_mesh_quantization, or plain accessors.
    enum class Compression : uint8_t { kDraco, kMeshopt, kNone };
    GltfSettings() = default;
    explicit GltfSettings(Compression c) : compression(c) {}
    Compression compression = Compression::kDraco;
    // meshopt and Draco: the positions' quantization grid, when the caller gives one: `origin`
    // and the cube's `extent`, in 2^bits - 1 steps (bits 1-16 with meshopt, 1-30 with Draco,
    // whose position bits they replace). Meshes written on one grid (the tiles of a tileset) put
    // a position shared by two of them on the same integer (and, with meshopt, the same node
    // transform), so both decode it to the same float; a position beyond the grid is decoded on
    // its nearest side.
    // None: each mesh's own box (meshopt: its bounding cube at 14 bits; Draco: its position
    // bits over the largest extent). Plain (uncompressed) accessors ignore it.
    struct Grid {
        float origin[3] = {0, 0, 0};
        float extent = 1;
        int bits = 16;
    };
    std::optional<Grid> grid;
};

// True for the GLB magic "glTF".
bool probe_glb(std::span<const std::byte> head, std::optional<uint64_t> file_size);
// True when the head is a JSON object that mentions "asset" (a glTF document's required key).
bool probe_gltf_json(std::span<const std::byte> head, std::optional<uint64_t> file_size);

}  // namespace meshstream::io
