// Turns a triangle soup into an indexed mesh in memory, for the whole-mesh writers (Draco and
// glTF). A vertex is a position (or, when the chunks carry the vertex_id channel, a vertex id)
// together with its per-corner attributes (io::CornerLayout's record: normal, colour, texture
// coordinates, scalars): corners that agree on both are one vertex, so a UV or normal seam stays
// two vertices. Positions weld when bit-equal (-0 == +0). An open-addressing hash table of
// 32-bit vertex indices (linear probing, load <= 1/2) finds them.
// Every triangle is kept in input order (degenerate ones too: the writers decide what their
// format can hold), except those with a NaN or infinite coordinate, which no writer here can
// store: they are dropped and counted, or refused under `strict`.
// Memory class: whole mesh: per vertex 12 bytes of position, the record, 8 bytes of id in id
// mode and about 8 bytes of hash table; per triangle 12 bytes of indices (+4 with materials).
#pragma once

#include "io/chunk.hpp"
#include "io/format.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace meshstream::io {

// The triangles of one material, with their own vertices: what one glTF primitive (or one
// Draco bitstream) holds.
struct MeshPart {
    uint32_t material = 0;           // index into the material table (0 without materials)
    std::vector<uint32_t> vertices;  // the mesh vertex of each part vertex, in first-use order
    std::vector<uint32_t> indices;   // 3 per triangle, into `vertices`, in the mesh's order
    size_t vertex_count() const { return vertices.size(); }
    size_t triangle_count() const { return indices.size() / 3; }
};

// A set of vertices' attribute values, unpacked from their records, channel by channel (each
// array empty when its channel is absent).
struct VertexValues {
    std::vector<float> normals;                // 3 per vertex
    std::vector<float> colors;                 // 4 per vertex: RGBA, 0..1 for integer sources
    std::vector<std::vector<float>> uvs;       // per set: 2 per vertex (u, v; v up, as in the chunk)
    std::vector<std::vector<double>> scalars;  // per Channels::vertex_scalars entry: 1 per vertex
};

struct IndexedMesh {
    Channels channels;                  // per vertex: those of `attributes`; per triangle: material
    std::vector<float> positions;       // xyz per vertex
    std::vector<std::byte> attributes;  // CornerLayout(channels).bytes() per vertex
    std::vector<uint32_t> indices;      // 3 per triangle, counter-clockwise as in the soup
    std::vector<uint32_t> materials;    // per triangle, when channels.material

    size_t vertex_count() const { return positions.size() / 3; }
    size_t triangle_count() const { return indices.size() / 3; }
    // Per-axis min/max of the positions (all zero for an empty mesh).
    Bounds bounds() const;
    // Area-weighted smooth vertex normals: for each position, the sum of the cross products of
    // the triangles at it (every vertex there: a UV seam does not split the normal), normalised.
    // A position whose triangles all have zero area gets (0, 0, 1). 3 floats per vertex.
    std::vector<float> smooth_normals() const;
    // The triangles split by material (one part when there is no material channel), in material
    // order, parts without triangles left out. Costs about the indices and vertices again.
    std::vector<MeshPart> parts() const;
    // The attribute values of `vertices` (mesh vertex indices), in that order.
    VertexValues values(std::span<const uint32_t> vertices) const;
};

// Bytes an IndexedMesh of this size holds with these channels (the indexer's tables included),
// for the writers' --memory estimates.
uint64_t indexed_mesh_bytes(uint64_t vertices, uint64_t triangles, const Channels& channels);

// For the whole-mesh writers' --memory check before any triangle: `need(vertices, triangles)` is
// a writer's estimate of the bytes it holds for a mesh of that size; `why` says why it holds the
// whole mesh ("Draco encodes the whole mesh in memory"). Throws io::Error naming `file` when
// even the smallest mesh of `options`' expected (or promised) triangle count, a closed surface
// with half as many vertices, needs more than the budget, with the budget that would do.
void budget_check_up_front(const std::string& file, const WriteOptions& options, const char* why,
                           uint64_t (*need)(uint64_t vertices, uint64_t triangles, const WriteOptions& options));

// A whole-mesh writer's --memory budget while it takes triangles: check() after each chunk with
// the triangles taken so far and the bytes held for them. Past the budget the error says how
// much all the triangles need ("give --memory 1188M or more"), the bytes held scaled to their
// count: at once when that count is known (`options`' promised or expected count, while more
// are to come); otherwise check() returns true, the writer frees its tables and passes only
// counts from then on (count()), and fail() at finish throws with the count then known. Memory
// while counting: none.
class WholeMeshBudget {
public:
    WholeMeshBudget(std::string file, const WriteOptions& options, const char* why);
    // True when `need` bytes for `triangles` pass the budget and their total is not known: the
    // caller stops holding triangles. Throws io::Error when the total is known.
    bool check(uint64_t triangles, uint64_t need);
    bool counting() const { return counting_; }
    void count(uint64_t triangles) { counted_ += triangles; }
    // Throws the error for all the triangles counted (call once the input ended).
    [[noreturn]] void fail() const;

private:
    [[noreturn]] void refuse(uint64_t total) const;
    std::string file_;
    const char* why_;
    uint64_t budget_;
    uint32_t divisor_;               // WriteOptions::memory_budget_divisor
    std::optional<uint64_t> total_;  // the triangles to come, when known
    bool counting_ = false;
    uint64_t triangles_ = 0, need_ = 0;  // when the budget was passed
    uint64_t counted_ = 0;               // all the triangles, while counting
};

// The errors MeshIndexer throws, for others that build an IndexedMesh (io::read_indexed):
// triangle `triangle` (its ordinal in the input) has a NaN or infinite coordinate, refused under
// --strict; the mesh's `triangles` triangles need more than 2^32 - 1 indices.
Error non_finite_triangle_error(const std::string& file, const std::string& format, uint64_t triangle);
Error index_count_error(const std::string& file, const std::string& format, uint64_t triangles);

class MeshIndexer {
public:
    // `file_name` names the file in error messages, `format` what holds the mesh in them
    // ("Draco", "glTF", "an indexed mesh"). `channels`: those of the chunks to come (vertex ids are decided by the first
    // non-empty chunk); the record of each vertex keeps the per-corner ones, `materials()` the
    // per-triangle material. `strict`: a non-finite coordinate is an error instead of a drop.
    MeshIndexer(std::string file_name, std::string format, const Channels& channels, bool strict);

    // Adds a chunk's triangles. Throws io::Error when the index count would pass 2^32 - 1
    // (32-bit glTF/Draco indices), when the vertex_id channel appears or disappears mid-stream,
    // and under `strict` for a triangle with a NaN or infinite coordinate (naming its index in
    // the stream), which is otherwise dropped and counted.
    void add(const TriangleChunk& chunk);
    // Sizes the tables for `triangles` triangles to come whose corners are shared as a closed
    // surface's are (half as many vertices as triangles): the hash slots at once, the arrays'
    // capacity (untouched pages). More vertices grow them as without it. For a writer that
    // knows the count and has checked that such tables fit its budget.
    void reserve(uint64_t triangles);

    uint64_t input_triangle_count() const { return input_triangles_; }
    // Triangles dropped for a NaN or infinite coordinate.
    uint64_t non_finite_count() const { return non_finite_; }
    // Attribute values (normal, colour, uv, scalar) that were NaN or infinite, written as 0.
    uint64_t non_finite_attribute_count() const { return non_finite_attributes_; }
    size_t vertex_count() const { return mesh_.vertex_count(); }
    size_t triangle_count() const { return mesh_.triangle_count(); }
    // What a writer says of the two counts above, a sentence each (none when both are 0), with
    // the settings' mentions kept (Writer::raw_notes).
    std::vector<std::string> notes() const;
    // Bytes held by the tables now (positions, records, ids, hash slots, indices), for budget checks.
    uint64_t memory_bytes() const;

    // Releases the mesh; the indexer is empty afterwards.
    IndexedMesh take();

private:
    uint32_t vertex_for(const float* p, uint64_t id, const std::byte* record);
    uint64_t hash_of(uint32_t v) const;
    void grow();

    std::string file_name_;
    std::string format_;
    bool strict_;
    CornerLayout layout_;
    IndexedMesh mesh_;
    std::vector<uint64_t> ids_;      // per vertex, in id mode
    std::vector<uint32_t> slots_;    // hash table of vertex indices; kEmpty = free
    std::vector<std::byte> record_;  // scratch: one corner's record
    int id_mode_ = -1;               // -1 undecided, 0 positions, 1 vertex ids
    uint64_t input_triangles_ = 0;
    uint64_t non_finite_ = 0, non_finite_attributes_ = 0;
};

}  // namespace meshstream::io
