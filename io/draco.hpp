// Draco `.drc` meshes, read and written with Google's Draco library (Debian libdraco-dev).
// Memory class: whole mesh. The writer indexes the soup in memory (io/mesh_index.hpp: the
// decimator's vertex ids, or exact position welding) and encodes at finish(); the reader holds
// the whole file and the decoded mesh. The writer refuses cleanly as soon as its estimate
// (draco_encode_estimate_bytes) passes the --memory budget; the reader refuses files larger
// than the budget (the decoded mesh, ~50 bytes per triangle, comes on top).
// Writer settings: position quantization --draco-qp (default 14 bits), compression level
// --draco-cl 0–10 (default 7; Draco speed = 10 - level, as draco_encoder does), optional
// area-weighted smooth normals (--normals) quantized with --draco-qn bits.
// Reader: triangles in Draco's decoded order; MeshHeader::notes gets the bitstream version,
// the connectivity method (edgebreaker/sequential), the position quantization bits and the
// attributes present. Draco point clouds (no faces) are refused with a clear io::Error rather
// than read as zero triangles, so a point cloud never turns silently into an empty mesh.
// The encode/decode helpers are shared with the glTF reader and writer (KHR_draco_mesh_compression).
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

// True when `head` starts with the magic "DRACO".
bool probe_draco(std::span<const std::byte> head, std::optional<uint64_t> file_size);

// Bytes the Draco writer is estimated to need at its peak for a mesh of this size with these
// settings (index tables, Draco's copy of the mesh, its corner table, the encoded output, and
// its entropy coder's tables, which double with each quantization bit).
uint64_t draco_encode_estimate_bytes(uint64_t vertex_count, uint64_t triangle_count, const WriteOptions& options);

// Refuses --draco-qp/-qn/-cl out of range, and bit counts whose tables alone pass --memory.
void check_draco_settings(const std::string& file, const WriteOptions& options);

struct DracoEncoded {
    std::vector<char> bytes;       // the Draco bitstream
    uint64_t point_count = 0;      // vertices the decoder will produce (Draco may split some)
    uint64_t face_count = 0;       // triangles the decoder will produce
    int position_id = -1;          // attribute unique ids (for KHR_draco_mesh_compression)
    int normal_id = -1;            // -1 without normals
    Bounds decoded_bounds;         // exact min/max of the dequantized positions
    uint64_t flattened = 0;        // triangles of nonzero area whose dequantized corners have none
};
// The note a writer gives when quantization flattened triangles (empty when none did).
std::string draco_flattened_note(const DracoEncoded& encoded, uint64_t triangles, const WriteOptions& options);

// Encodes `mesh` (and `normals`, 3 floats per vertex, when non-null) with the Draco settings
// of `options`. Throws io::Error naming `file_name` when Draco refuses (e.g. an empty mesh).
DracoEncoded encode_draco(const IndexedMesh& mesh, const std::vector<float>* normals, const WriteOptions& options,
                          const std::string& file_name);

struct DracoDecoded {
    std::vector<float> positions;   // xyz per point, dequantized exactly as Draco does
    std::vector<uint32_t> indices;  // 3 per face
    int version_major = 0, version_minor = 0;
    bool edgebreaker = false;
    int position_bits = 0;          // 0: positions not quantized
    bool normals = false, colors = false, texcoords = false;
};

// Decodes a Draco mesh bitstream. `position_id` selects the position attribute by unique id
// (KHR_draco_mesh_compression's attribute map); -1 takes the named POSITION attribute.
// Throws io::Error naming `file_name` (and `base_offset`, the bitstream's offset in the file)
// for point clouds, corrupt or unsupported data.
DracoDecoded decode_draco(std::span<const std::byte> bytes, const std::string& file_name, uint64_t base_offset = 0,
                          int position_id = -1);

}  // namespace meshstream::io
