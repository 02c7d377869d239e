// Draco `.drc` meshes, read and written with Google's Draco library (Debian libdraco-dev).
// Memory class: whole mesh. The writer indexes the soup in memory (io/mesh_index.hpp: the
// vertex ids readers and the decimator give, or exact position welding, each with its
// attribute record) and encodes at finish(); the reader holds the whole file and the decoded
// mesh. The writer refuses cleanly as soon as its estimate (draco_encode_estimate_bytes) passes
// the --memory budget; the reader refuses files larger than the budget (the decoded mesh,
// ~50 bytes per triangle plus its attributes, comes on top).
// Attributes, read and written: normal, color (uint8, uint16 or float; 3 or 4 components),
// tex_coord (each set one attribute, up to 4) and generic (each vertex scalar channel one
// 1-component attribute named by its "name" metadata entry, as Draco's own tools do).
// Writer settings (DracoSettings, in WriteOptions::format_options): position quantization
// --draco-qp (default 14 bits), normals --draco-qn (10), texture coordinates --draco-qt (12),
// float colours and generic attributes --draco-qc (10; integer ones are stored exactly),
// compression level --draco-cl 0–10 (default 7; Draco speed = 10 - level, as draco_encoder
// does); --normals (WriteOptions::normals) adds area-weighted smooth normals to a mesh
// without them. Draco's encoder drops triangles with a repeated vertex and no quantization
// holds a NaN: both are counted in the writer's notes (errors under --strict).
// Reader: triangles in Draco's decoded order, the point number as vertex id; MeshHeader::notes
// gets the bitstream version, the connectivity method (edgebreaker/sequential), the position
// quantization bits and the attributes present. Draco point clouds (no faces) are refused
// with a clear io::Error rather than read as zero triangles.
// The encode/decode helpers are shared with the glTF reader and writer.
#pragma once

#include "io/format.hpp"
#include "io/mesh_index.hpp"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace meshstream::io {

extern const Format kDracoFormat;  // "draco": .drc

// Draco's own write options, for the .drc writer and glTF's KHR_draco_mesh_compression: set
// them with WriteOptions::format_options.set(DracoSettings{...}); unset, these defaults apply.
// Quantization applies to float attributes only.
struct DracoSettings {
    int position_bits = 14;  // --draco-qp, 1–30
    int normal_bits = 10;    // --draco-qn, 2–30 (Draco's octahedral normal coder fails at 1)
    int texcoord_bits = 12;  // --draco-qt, 1–30
    int color_bits = 10;     // --draco-qc, 1–30: float colours and generic attributes
    int level = 7;           // --draco-cl, 0–10 (Draco speed = 10 - level)
};

// True when `head` starts with the magic "DRACO".
bool probe_draco(std::span<const std::byte> head, std::optional<uint64_t> file_size);

// Bytes the Draco writer is estimated to need at its peak for a mesh of this size with these
// settings (index tables, Draco's copy of the mesh, its corner table, the encoded output, and
// its entropy coder's tables, which double with each quantization bit).
uint64_t draco_encode_estimate_bytes(uint64_t vertex_count, uint64_t triangle_count, const WriteOptions& options);

// The DracoSettings of `options`, checked: throws io::OptionError naming `file` and the setting
// for one out of its range ("x.drc: the Draco position bits must be 1-30, got 31"), and for bit
// counts whose coding tables alone pass the memory budget.
DracoSettings check_draco_settings(const std::string& file, const WriteOptions& options);

// The channels a Draco bitstream written with `options` keeps of `in` (per corner: normal,
// colour, texture coordinates, scalars; `gltf`: no scalars, which glTF names differently).
Channels draco_keep_channels(const Channels& in, const WriteOptions& options, bool gltf);

struct DracoEncoded {
    std::vector<char> bytes;   // the Draco bitstream
    uint64_t point_count = 0;  // vertices the decoder will produce (Draco may split some)
    uint64_t face_count = 0;   // triangles the decoder will produce
    int position_id = -1;      // attribute unique ids (for KHR_draco_mesh_compression)
    int normal_id = -1;        // -1 when absent
    int color_id = -1;
    std::vector<int> texcoord_ids;  // per uv set
    std::vector<int> generic_ids;   // per vertex scalar channel
    Bounds decoded_bounds;          // exact min/max of the dequantized positions
    uint64_t flattened = 0;         // triangles of nonzero area whose dequantized corners have none
    bool on_grid = false;           // quantized on a caller's DracoGrid
    uint64_t dropped = 0;           // triangles the encoder left out (a repeated vertex)
};
// The notes a writer gives for what the encoding lost (flattened or dropped triangles), each
// a sentence; empty when nothing was.
std::vector<std::string> draco_notes(const DracoEncoded& encoded, uint64_t triangles, const DracoSettings& settings);

// Encodes a mesh: `positions` (3 per vertex), `indices` (3 per triangle), the per-vertex
// `values` of the channels `channels` names (normal, colour in its source type, uv sets,
// scalars), with `settings` (as check_draco_settings gives them). `flip_v`: texture
// coordinates are written as v' = 1 - v (glTF's convention; the chunk's v points up).
// Triangles with a repeated vertex are left out (Draco's encoder drops them) and counted in `dropped` (a writer under
// --strict refuses them before, with first_repeated_vertex). Throws io::Error naming `file_name` when Draco refuses
// (e.g. an empty mesh).
// `grid`, when given, quantizes the positions on it instead of on the mesh's own box (Draco's
// explicit quantization: `settings.position_bits` steps over [origin, origin + range] on every
// axis): meshes encoded on one grid decode a position they share to the same float. A position
// beyond the grid is moved onto its nearest side.
struct DracoGrid {
    float origin[3] = {0, 0, 0};
    float range = 1;
};
DracoEncoded encode_draco(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                          const VertexValues& values, const Channels& channels, const DracoSettings& settings,
                          const std::string& file_name, bool flip_v = false, const DracoGrid* grid = nullptr);

// The first triangle of `indices` (3 per triangle) with a repeated vertex, or -1.
int64_t first_repeated_vertex(const std::vector<uint32_t>& indices);

// One decoded non-position attribute, per point (point p's values at p × components).
struct DracoAttribute {
    enum Kind : uint8_t { kNormal, kColor, kTexCoord, kGeneric, kOther } kind = kOther;
    int unique_id = -1;
    int components = 0;
    ScalarType type = ScalarType::kFloat32;  // as stored (float for quantized attributes)
    std::string name;                        // the "name" metadata entry, if any
    std::vector<double> values;              // integer colours normalised to 0..1
};

struct DracoDecoded {
    std::vector<float> positions;            // xyz per point, dequantized exactly as Draco does
    std::vector<uint32_t> indices;           // 3 per face
    std::vector<DracoAttribute> attributes;  // in the bitstream's order
    int version_major = 0, version_minor = 0;
    bool edgebreaker = false;
    int position_bits = 0;  // 0: positions not quantized
};

// Decodes a Draco mesh bitstream. `position_id` selects the position attribute by unique id
// (KHR_draco_mesh_compression's attribute map); -1 takes the named POSITION attribute.
// Throws io::Error naming `file_name` (and `base_offset`, the bitstream's offset in the file)
// for point clouds, corrupt or unsupported data.
DracoDecoded decode_draco(std::span<const std::byte> bytes, const std::string& file_name, uint64_t base_offset = 0,
                          int position_id = -1);

}  // namespace meshstream::io
